"""ament_python package setup; also a plain ``pip install`` on machines without ROS."""

import sys
from glob import glob
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = "tdcm_ros"
#: The embedded runtime's Zenoh: from 1.5.0, the first Python release with the advanced publisher and
#: subscriber (transient local, as rmw_zenoh does it), to 1.8.x, what Jazzy's rmw_zenoh 0.2.6-0.2.10
#: vendor (1.5.0-1.8.0). 1.9.0 and 1.10.x fail the TLS/authentication test; 1.8.0 has no wheel on the
#: registry (its source build needs Rust). CI runs the highest allowed and, in a throwaway venv, the
#: lowest (.ci/zenoh_lowest.sh). Keep .ci/ros.sh and .ci/test.sh in step (test/test_dependencies.py).
ZENOH_REQUIREMENT = "eclipse-zenoh>=1.5.0,!=1.8.0,<1.9"

#: The nodes, as ``ros2 run tdcm_ros <name>`` starts them.
NODES = {
    "model_node": "tdcm_ros.nodes.model_node:main",
    "metrics_node": "tdcm_ros.nodes.metrics_node:main",
    "mocap_node": "tdcm_ros.nodes.mocap_node:main",
    "tension_driver": "tdcm_ros.nodes.tension_driver:main",
    "device_twin": "tdcm_ros.nodes.device_twin:main",
    "shape_controller": "tdcm_ros.nodes.shape_controller:main",
}
#: Console scripts every install gets: prefixed, so a pip install puts no generic name on PATH.
SCRIPTS = {
    "tdcm": "tdcm_ros.cli.main:main",
    "tdcm_node": "tdcm_ros.runtime.run_node:main",
    "tdcm_talker": "tdcm_ros.nodes.talker:main",
    **{f"tdcm_{name}": target for name, target in NODES.items()},
}
#: colcon (ament_python) installs with ``setup.py install`` or ``develop``, which setup.cfg points at
#: lib/tdcm_ros, where ``ros2 run`` looks and which is not on PATH: only there the nodes also get
#: their ROS names. pip builds a wheel (bdist_wheel, editable_wheel), whose scripts land on PATH.
ROS_INSTALL = bool({"install", "develop"} & set(sys.argv[1:]))

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
        (f"share/{PACKAGE}/config/bodies", glob("config/bodies/*.yaml")),
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
        "xxhash>=3.0",
        # the bag reader decompresses MCAP chunks itself (tdcm_ros/bagio/reader.py)
        "lz4>=4",
        "zstandard>=0.19",
        # a notch section given as a polygon is checked by shapely (simple rings, holes inside)
        "shapely>=2.0",
        # a body given as a mesh in a format other than STL (OBJ, PLY, ...) is loaded by trimesh
        # (model/mesh_file.py; an STL is read by NumPy, without trimesh's ~1.5 s import)
        "trimesh>=4",
        ZENOH_REQUIREMENT,
    ],
    extras_require={
        "plot": ["matplotlib>=3.7"],
        # The type checker and the stubs it reads are pinned: a newer one may report new errors.
        # pytest-xdist runs the suite in parallel (.ci/test.sh): most tests wait on timers and
        # sockets, so workers overlap their waits on the 2-core CI machine.
        "test": ["pytest>=7", "pytest-xdist>=3.5", "hypothesis>=6.80", "ruff>=0.5",
                 "matplotlib>=3.7", "mypy==2.4.1", "scipy-stubs==1.17.1.5",
                 "types-PyYAML==6.0.12.20261113", "types-pyserial==3.5.0.20260712",
                 "types-shapely==2.1.0.20261030",
                 # builds the meshes of the mesh-body tests and bench (test/support/meshes.py)
                 "manifold3d>=3"],
    },
    zip_safe=True,
    maintainer="tdcm_ros developers",
    maintainer_email="dev@tdcm.invalid",
    description="Shape estimation of notched tendon-driven continuum manipulators, with ROS 2 nodes.",
    license="Apache-2.0",
    tests_require=["pytest"],
    entry_points={
        "console_scripts": [f"{name} = {target}" for name, target in
                            {**SCRIPTS, **(NODES if ROS_INSTALL else {})}.items()],
    },
)
