"""Launch files parse, and every executable they name is a console script of the package."""

import ast
from pathlib import Path

import yaml
from setup_info import console_scripts as installed_scripts

REPO = Path(__file__).resolve().parents[1]


def console_scripts() -> set[str]:
    """What a colcon install puts into lib/tdcm_ros, where ``ros2 launch`` finds executables."""
    return set(installed_scripts("install"))


def test_launch_files_parse_and_name_existing_executables():
    launch_files = sorted((REPO / "launch").glob("*.launch.py"))
    assert launch_files
    scripts = console_scripts()
    for path in launch_files:
        tree = ast.parse(path.read_text(), filename=str(path))
        names = {node.name for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)}
        assert "generate_launch_description" in names, path
        executables = [kw.value.value for node in ast.walk(tree) if isinstance(node, ast.Call)
                       for kw in node.keywords
                       if kw.arg == "executable" and isinstance(kw.value, ast.Constant)]
        assert executables, path
        assert set(executables) <= scripts, (path, set(executables) - scripts)


def test_config_files_are_ros_parameter_yaml_and_load_for_the_embedded_runtime():
    from tdcm_ros.runtime.params import node_parameters

    for path in sorted((REPO / "config").glob("*.yaml")):
        data = yaml.safe_load(path.read_text())
        for node, body in data.items():
            assert "ros__parameters" in body, (path, node)
            values = node_parameters(str(path), f"/{node}")
            assert values, (path, node)
