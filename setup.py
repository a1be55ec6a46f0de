"""ament_python package setup; also a plain ``pip install`` on machines without ROS."""

import sys
import tomllib
from glob import glob
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = "tdcm_ros"
#: The one declaration of the version, the nodes and the dependencies (see its header).
DECLARED = tomllib.loads((Path(__file__).resolve().parent / "dependencies.toml").read_text("utf-8"))
#: The nodes, as ``ros2 run tdcm_ros <name>`` starts them.
NODES: dict[str, str] = DECLARED["nodes"]
REQUIRED = [e["requirement"] for e in DECLARED["python"] if not e.get("extras")]
EXTRAS: dict[str, list[str]] = {}
for entry in DECLARED["python"]:
    for extra in entry.get("extras", []):
        EXTRAS.setdefault(extra, []).append(entry["requirement"])
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
    version=DECLARED["version"],
    packages=find_packages(exclude=["test", "test.*", "bench"]),
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", glob("launch/*.launch.py")),
        (f"share/{PACKAGE}/config", glob("config/*.yaml")),
        (f"share/{PACKAGE}/config/scenes", glob("config/scenes/*.yaml")),
        (f"share/{PACKAGE}/config/bodies", glob("config/bodies/*.yaml") + glob("config/bodies/*.stl")),
        (f"share/{PACKAGE}/config/design", glob("config/design/*.yaml")),
        (f"share/{PACKAGE}/config/rviz", glob("config/rviz/*.rviz")),
        (f"share/{PACKAGE}/config/foxglove", glob("config/foxglove/*.json")),
        (f"share/{PACKAGE}/config/zenoh", glob("config/zenoh/*")),
        *[(f"share/{PACKAGE}/{folder}", glob(f"{folder}/*.msg"))
          for folder in sorted({str(Path(p).parent) for p in glob("msg_defs/*/msg/*.msg")})],
    ],
    package_data={PACKAGE: ["py.typed"]},
    include_package_data=True,
    python_requires=">=3.11",
    install_requires=REQUIRED,
    extras_require=EXTRAS,
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
