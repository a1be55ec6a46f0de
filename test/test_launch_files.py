"""Launch files parse, and every executable they name is a console script of the package."""

import ast
from pathlib import Path
from typing import Any

import pytest
import yaml

from test import launch_fakes
from test.setup_info import console_scripts as installed_scripts

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
            assert node.startswith("/**/"), (path, node)  # applies in any namespace
            name = node.split("/")[-1]
            values = node_parameters([path], f"/{name}")
            assert values, (path, node)
            assert node_parameters([path], f"/robot1/{name}") == values


# -- the launch files run on stand-ins of launch/launch_ros (test/launch_fakes.py) -------------

def _launch_value(value: Any) -> Any:
    """An inline parameter as launch_ros passes it: a ``ParameterValue`` of ``value_type=str``
    as its text, other text read as YAML."""
    if isinstance(value, launch_fakes.ParameterValue):
        assert value.value_type is str, value.value_type
        return str(value.value)
    return yaml.safe_load(value) if isinstance(value, str) else value


def _effective_parameters(node: launch_fakes.Node, arguments: dict[str, str]) -> dict[str, Any]:
    """What the node starts with: its parameter files (``ros__parameters`` of ``/<name>``), then
    the inline dicts, later entries winning, as launch_ros passes them."""
    from tdcm_ros.runtime.params import node_parameters

    values: dict[str, Any] = {}
    namespace = str(launch_fakes.resolve(node.namespace, arguments) or "").strip("/")
    fqn = f"/{namespace}/{node.name}" if namespace else f"/{node.name}"
    for entry in launch_fakes.resolve(node.parameters, arguments):
        if isinstance(entry, dict):  # launch_ros reads a substituted value as YAML
            values.update({k: _launch_value(v) for k, v in entry.items()})
        else:
            assert Path(entry).is_file(), entry
            values.update(node_parameters([entry], fqn))
    return values


def _node(path: Path, executable: str) -> launch_fakes.Node:
    (node,) = [n for n in launch_fakes.nodes(launch_fakes.load(path)) if n.executable == executable]
    return node


def _mocap_source(path: Path, **given: str) -> str:
    description = launch_fakes.load(path)
    arguments = launch_fakes.launch_arguments(description, given)
    (node,) = [n for n in launch_fakes.nodes(description) if n.executable == "mocap_node"]
    return str(_effective_parameters(node, arguments)["source"])


@pytest.mark.parametrize("name", ["mocap.launch.py", "bench.launch.py"])
def test_real_bench_launch_files_default_to_the_live_mocap_driver(name: str) -> None:
    assert _mocap_source(REPO / "launch" / name) == "relabel"


def test_simulated_markers_are_an_explicit_launch_argument() -> None:
    path = REPO / "launch" / "mocap.launch.py"
    assert _mocap_source(path, source="sim") == "sim"
    assert _mocap_source(path, source="csv") == "csv"
    with pytest.raises(ValueError, match="source"):
        _mocap_source(path, source="simulated")


def test_the_driver_topic_is_remapped_onto_the_relabel_input() -> None:
    path = REPO / "launch" / "mocap.launch.py"
    description = launch_fakes.load(path)
    node = _node(path, "mocap_node")
    arguments = launch_fakes.launch_arguments(description, {"driver_markers": "/markers"})
    remaps = dict(launch_fakes.resolve(node.remappings, arguments))
    input_topic = _effective_parameters(node, arguments)["relabel.input_topic"]
    assert remaps[input_topic] == "/markers"


@pytest.mark.parametrize("path", sorted((REPO / "launch").glob("*.launch.py")), ids=lambda p: p.name)
def test_launch_files_find_configs_with_find_package_share_and_pass_valid_parameters(
        path: Path) -> None:
    from tdcm_ros.nodes import (
        device_twin,
        metrics_node,
        mocap_node,
        model_node,
        shape_controller,
        tension_driver,
    )
    from tdcm_ros.runtime import NODE_COMMON

    specs = {"model_node": model_node.PARAMETERS, "metrics_node": metrics_node.PARAMETERS,
             "mocap_node": mocap_node.PARAMETERS, "tension_driver": tension_driver.PARAMETERS,
             "device_twin": device_twin.PARAMETERS,
             "shape_controller": shape_controller.PARAMETERS}
    specs = {node: {**table, **NODE_COMMON} for node, table in specs.items()}
    tree = ast.parse(path.read_text())
    imported = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    assert "ament_index_python.packages" not in imported, "use FindPackageShare"
    description = launch_fakes.load(path)
    arguments = launch_fakes.launch_arguments(description, {})
    for node in launch_fakes.nodes(description):
        values = _effective_parameters(node, arguments)
        assert values, node.name
        for name, value in values.items():
            assert name in specs[node.executable], (path.name, node.name, name)
            specs[node.executable][name].check(value, name)


@pytest.mark.parametrize("path", sorted((REPO / "launch").glob("*.launch.py")), ids=lambda p: p.name)
def test_every_launch_file_takes_namespace_and_use_sim_time_for_every_node(path: Path) -> None:
    """namespace:=/robot1 moves every node there, and the shipped parameter files still apply
    (their keys are /**/NODE); use_sim_time:=true reaches every node as a bool, and
    frame_prefix:=robot1/ as text ('' by default, not YAML's null)."""
    description = launch_fakes.load(path)
    plain = {node.name: _effective_parameters(node, launch_fakes.launch_arguments(description, {}))
             for node in launch_fakes.nodes(description)}
    arguments = launch_fakes.launch_arguments(description, {"namespace": "/robot1",
                                                            "use_sim_time": "true",
                                                            "frame_prefix": "robot1/"})
    for node in launch_fakes.nodes(description):
        assert launch_fakes.resolve(node.namespace, arguments) == "/robot1", node.name
        values = _effective_parameters(node, arguments)
        assert values.pop("use_sim_time") is True and plain[node.name].pop("use_sim_time") is False
        assert values.pop("frame_prefix") == "robot1/" and plain[node.name].pop("frame_prefix") == ""
        assert values == plain[node.name], node.name
