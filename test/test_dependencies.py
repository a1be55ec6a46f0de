"""Every third-party module the package imports is declared, and the CI scripts install the
same eclipse-zenoh range as setup.py."""

from __future__ import annotations

import ast
import re
import sys
from importlib.metadata import packages_distributions

from test.setup_info import REPO, requirement_name, setup_kwargs

#: Imported only on a ROS 2 machine (rclpy runtime), where they come from ROS, not pip.
ROS_MODULES = {"rclpy", "rcl_interfaces", "ament_index_python"}


def imported_top_level_modules() -> set[str]:
    names: set[str] = set()
    for path in (REPO / "tdcm_ros").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if isinstance(node, ast.Import):
                names |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    return names - set(sys.stdlib_module_names) - {"tdcm_ros"} - ROS_MODULES


def declared() -> set[str]:
    kwargs = setup_kwargs()
    requirements = list(kwargs["install_requires"])
    for extra in kwargs["extras_require"].values():
        requirements += extra
    return {requirement_name(r) for r in requirements}


def test_every_imported_third_party_module_is_declared_in_setup_py() -> None:
    distributions = packages_distributions()
    missing = {}
    for module in sorted(imported_top_level_modules()):
        names = {d.lower().replace("_", "-") for d in distributions.get(module, [module])}
        if not names & declared():
            missing[module] = sorted(names)
    assert not missing, f"imported but not declared in setup.py: {missing}"


def test_bag_decompressors_are_runtime_requirements() -> None:
    runtime = {requirement_name(r) for r in setup_kwargs()["install_requires"]}
    assert {"lz4", "zstandard"} <= runtime


def _ros_sh_project_packages() -> list[str]:
    text = (REPO / ".ci" / "ros.sh").read_text()
    block = re.search(r"PROJECT_PACKAGES=\((.*?)\)", text, re.DOTALL)
    assert block, "PROJECT_PACKAGES=(...) not found in .ci/ros.sh"
    return [word.strip('"') for word in re.findall(r'"[^"]*"|\S+', block.group(1))]


def test_ci_installs_what_setup_py_requires() -> None:
    packages = _ros_sh_project_packages()
    runtime = setup_kwargs()["install_requires"]
    assert {requirement_name(r) for r in runtime} <= {requirement_name(p) for p in packages}
    zenoh = next(r for r in runtime if requirement_name(r) == "eclipse-zenoh")
    assert zenoh in packages, (zenoh, packages)
    assert f'"{zenoh}"' in (REPO / ".ci" / "test.sh").read_text()


def test_zenoh_is_a_range_not_a_pin() -> None:
    zenoh = next(r for r in setup_kwargs()["install_requires"]
                 if requirement_name(r) == "eclipse-zenoh")
    assert "==" not in zenoh and ">=" in zenoh and "<" in zenoh.replace("<=", ""), zenoh
