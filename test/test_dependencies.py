"""Every third-party module the package imports is declared, and the CI scripts install the
same eclipse-zenoh range as setup.py."""

from __future__ import annotations

import importlib.util
import re
from importlib.metadata import packages_distributions
from typing import Any

from tdcm_ros.runtime import NODES
from test.setup_info import REPO, requirement_name, setup_kwargs

#: Imported only on a ROS 2 machine (rclpy runtime), where they come from ROS, not pip.
ROS_MODULES = {"rclpy", "rcl_interfaces", "ament_index_python"}


def declared() -> set[str]:
    kwargs = setup_kwargs()
    requirements = list(kwargs["install_requires"])
    for extra in kwargs["extras_require"].values():
        requirements += extra
    return {requirement_name(r) for r in requirements}


def test_every_imported_third_party_module_is_declared_in_setup_py() -> None:
    distributions = packages_distributions()
    missing = {}
    for module in sorted(set(_deps_script().imported_modules()) - ROS_MODULES):
        names = {d.lower().replace("_", "-") for d in distributions.get(module, [module])}
        if not names & declared():
            missing[module] = sorted(names)
    assert not missing, f"imported but not declared in setup.py: {missing}"


def test_bag_decompressors_are_runtime_requirements() -> None:
    runtime = {requirement_name(r) for r in setup_kwargs()["install_requires"]}
    assert {"lz4", "zstandard"} <= runtime


def _deps_script() -> Any:
    """``.ci/deps.py`` as a module (it is a script, run by CI before any install)."""
    spec = importlib.util.spec_from_file_location("ci_deps", REPO / ".ci" / "deps.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_package_xml_the_route_page_and_the_version_are_generated_from_the_declaration() -> None:
    deps = _deps_script()
    decl = deps.declaration()
    for name, expected in deps.FILES.items():
        text = (REPO / name).read_text(encoding="utf-8")
        assert expected(text, decl) == text, f"{name}: run python3 .ci/deps.py write"


def test_the_route_page_s_executables_table_follows_the_node_table() -> None:
    """A node added to dependencies.toml gets its row; a row of no node goes."""
    deps = _deps_script()
    decl = deps.declaration()
    text = (REPO / deps.ROUTE_PAGE).read_text(encoding="utf-8")
    grown = {**decl, "nodes": {**decl["nodes"], "gripper_node": "tdcm_ros.nodes.gripper_node:main"}}
    row = "| gripper | `ros2 run tdcm_ros gripper_node` | `tdcm_gripper_node` |\n"
    assert row not in text and row in deps.expected_route_page(text, grown)
    shrunk = {**decl, "nodes": {k: v for k, v in decl["nodes"].items() if k != "device_twin"}}
    assert "`tdcm_device_twin`" not in deps.expected_route_page(text, shrunk)
    assert "`tdcm_node`, `tdcm`" in deps.expected_route_page(text, shrunk)  # the last row stays


def test_the_ros_route_installs_every_module_the_package_imports() -> None:
    """What package.xml's keys and the route page's pip line give covers every import (the CI
    step imports them all in a venv built from that route alone)."""
    deps = _deps_script()
    route = {requirement_name(r) for r in deps.ros_route(deps.declaration())}
    distributions = packages_distributions()
    missing = {}
    for module in sorted(set(deps.imported_modules()) - ROS_MODULES):
        names = {d.lower().replace("_", "-") for d in distributions.get(module, [module])}
        if not names & route:
            missing[module] = sorted(names)
    assert not missing, f"imported but not installed by the ROS route: {missing}"


def test_the_ros_venv_installs_package_xml_s_ros_packages_or_names_the_gap() -> None:
    """.ci/ros.sh's wheels come from [ros] exec: each one is a wheel or a gap with a reason."""
    deps = _deps_script()
    decl = deps.declaration()
    gaps = decl["ros"]["registry_gaps"]
    wheels = {re.sub(r"\[.*\]$", "", w).removeprefix("ros-jazzy-").replace("-", "_")
              for w in deps.ros_wheels(decl)}
    assert wheels | set(gaps) == set(decl["ros"]["exec"]) and not wheels & set(gaps)
    assert all(reason.startswith("no wheel: ") for reason in gaps.values())
    assert "ros-jazzy-rclpy[fastrtps]" in deps.ros_wheels(decl)
    assert '"$REPO/.ci/deps.py" ros-wheels' in (REPO / ".ci" / "ros.sh").read_text()


def test_the_node_table_is_declared_once() -> None:
    declared_nodes = _deps_script().declaration()["nodes"]
    assert set(NODES) - {"talker"} == set(declared_nodes)
    assert {name: f"tdcm_ros.nodes.{name}:main" for name in declared_nodes} == declared_nodes


def test_numba_is_an_extra() -> None:
    kwargs = setup_kwargs()
    assert "numba" not in {requirement_name(r) for r in kwargs["install_requires"]}
    assert "numba" in {requirement_name(r) for r in kwargs["extras_require"]["fast"]}
    assert "numba" in {requirement_name(r) for r in kwargs["extras_require"]["test"]}


def test_ci_installs_the_zenoh_range_of_setup_py() -> None:
    zenoh = next(r for r in setup_kwargs()["install_requires"]
                 if requirement_name(r) == "eclipse-zenoh")
    assert zenoh in _deps_script().ros_route(_deps_script().declaration())
    assert f'"{zenoh}"' in (REPO / ".ci" / "test.sh").read_text()


def test_zenoh_is_a_range_not_a_pin() -> None:
    zenoh = next(r for r in setup_kwargs()["install_requires"]
                 if requirement_name(r) == "eclipse-zenoh")
    assert "==" not in zenoh and ">=" in zenoh and "<" in zenoh.replace("<=", ""), zenoh
