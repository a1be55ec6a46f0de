"""ament_python package setup; also a plain ``pip install`` on machines without ROS."""

from glob import glob
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = "tdcm_ros"

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(exclude=["test", "test.*", "bench"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", glob("launch/*.launch.py")),
        (f"share/{PACKAGE}/config", glob("config/*.yaml")),
        (f"share/{PACKAGE}/config/scenes", glob("config/scenes/*.yaml")),
        (f"share/{PACKAGE}/config/zenoh", glob("config/zenoh/*")),
        *[(f"share/{PACKAGE}/{folder}", glob(f"{folder}/*.msg"))
          for folder in sorted({str(Path(p).parent) for p in glob("msg_defs/*/msg/*.msg")})],
    ],
    package_data={PACKAGE: ["py.typed"]},
    include_package_data=True,
    python_requires=">=3.11",
    install_requires=[
        "numpy>=1.24",
        "scipy>=1.10",
        "numba>=0.60",
        "rosbags>=0.10.4",
        "mcap>=1.1",
        "PyYAML>=6",
        "pyserial>=3.5",
        "tqdm>=4.60",
        "eclipse-zenoh==1.6.2",
        "xxhash>=3.0",
    ],
    extras_require={
        "plot": ["matplotlib>=3.7"],
        # The type checker and the stubs it reads are pinned: a newer one may report new errors.
        "test": ["pytest>=7", "hypothesis>=6.80", "ruff>=0.5", "matplotlib>=3.7", "mypy==2.4.1",
                 "scipy-stubs==1.17.1.5", "types-PyYAML==6.0.12.20261113",
                 "types-pyserial==3.5.0.20260712"],
    },
    zip_safe=True,
    maintainer="tdcm_ros developers",
    maintainer_email="dev@tdcm.invalid",
    description="Shape estimation of notched tendon-driven continuum manipulators, with ROS 2 nodes.",
    license="Apache-2.0",
    tests_require=["pytest"],
    entry_points={
        "console_scripts": [
            "tdcm = tdcm_ros.cli.main:main",
            "tdcm_node = tdcm_ros.runtime.run_node:main",
            "tdcm_talker = tdcm_ros.nodes.talker:main",
            "model_node = tdcm_ros.nodes.model_node:main",
            "metrics_node = tdcm_ros.nodes.metrics_node:main",
            "mocap_node = tdcm_ros.nodes.mocap_node:main",
            "tension_driver = tdcm_ros.nodes.tension_driver:main",
            "device_twin = tdcm_ros.nodes.device_twin:main",
        ],
    },
)
