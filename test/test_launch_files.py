"""Launch files parse, and every executable they name is a console script of the package."""

import ast
import re
import xml.etree.ElementTree as ET
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
    """The package's executables are its console scripts; another package's (robot_state_publisher,
    rviz2) is an exec_depend of package.xml."""
    launch_files = sorted((REPO / "launch").glob("*.launch.py"))
    assert launch_files
    scripts = console_scripts()
    depends = set(re.findall(r"<exec_depend>([^<]+)</exec_depend>",
                             (REPO / "package.xml").read_text()))
    for path in launch_files:
        tree = ast.parse(path.read_text(), filename=str(path))
        names = {node.name for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)}
        assert "generate_launch_description" in names, path
        started = [{kw.arg: kw.value.value for kw in node.keywords
                    if kw.arg in ("package", "executable") and isinstance(kw.value, ast.Constant)}
                   for node in ast.walk(tree)
                   if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "Node"]
        assert started, path
        for node in started:
            if node["package"] == "tdcm_ros":
                assert node["executable"] in scripts, (path, node)
            else:
                assert node["package"] in depends, (path, node)


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
    for node, arguments in launch_fakes.launched(path, {"rviz": "true"} if _takes_rviz(path)
                                                 else {}):
        if node.package != "tdcm_ros":
            continue  # robot_state_publisher and rviz2: test_view_launch_*
        values = _effective_parameters(node, arguments)
        assert values, node.name
        for name, value in values.items():
            assert name in specs[node.executable], (path.name, node.name, name)
            specs[node.executable][name].check(value, name)


def _takes_rviz(path: Path) -> bool:
    declared = launch_fakes.load(path).entities
    return any(getattr(e, "name", None) == "rviz" for e in declared
               if isinstance(e, launch_fakes.DeclareLaunchArgument))


@pytest.mark.parametrize("path", sorted((REPO / "launch").glob("*.launch.py")), ids=lambda p: p.name)
def test_every_launch_file_takes_namespace_and_use_sim_time_for_every_node(path: Path) -> None:
    """namespace:=/robot1 moves every node there, and the shipped parameter files still apply
    (their keys are /**/NODE); use_sim_time:=true reaches every node as a bool, and
    frame_prefix:=robot1/ as text ('' by default, not YAML's null)."""
    view = {"rviz": "true"} if _takes_rviz(path) else {}
    plain = {node.name: _effective_parameters(node, arguments)
             for node, arguments in launch_fakes.launched(path, view)}
    moved = launch_fakes.launched(path, {**view, "namespace": "/robot1", "use_sim_time": "true",
                                         "frame_prefix": "robot1/"})
    assert {node.name for node, _ in moved} == set(plain)
    for node, arguments in moved:
        values = _effective_parameters(node, arguments)
        assert values.pop("use_sim_time") is True and plain[node.name].pop("use_sim_time") is False
        if node.executable == "rviz2":  # a viewer of the graph, in no namespace
            assert launch_fakes.resolve(node.namespace, arguments) is None
            continue
        assert launch_fakes.resolve(node.namespace, arguments) == "/robot1", node.name
        assert values.pop("frame_prefix") == "robot1/" and plain[node.name].pop("frame_prefix") == ""
        assert values == plain[node.name], node.name


# -- view.launch.py: robot_state_publisher draws the body model_node models, RViz opens ----------

VIEW = REPO / "launch" / "view.launch.py"


def _by_executable(path: Path, given: dict[str, str]) -> dict[str, tuple[Any, dict[str, str]]]:
    return {node.executable: (node, arguments)
            for node, arguments in launch_fakes.launched(path, given)}


@pytest.mark.parametrize("namespace", ["", "/robot1"])
def test_view_launch_describes_the_body_model_node_publishes_joints_for(
        tmp_path: Path, namespace: str) -> None:
    """robot_state_publisher's robot_description is the URDF of model_node's design under the
    same parameter file (a wrist here, in the node's namespace), and model_node's joint_states
    set every moving joint of it but the driver's roll, putting its tip on the solve."""
    from tdcm_ros.bagio import from_dict
    from tdcm_ros.model import named_design, solve
    from tdcm_ros.nodes.model_node import ModelNode
    from tdcm_ros.runtime.memory_port import MemoryPort
    from tdcm_ros.runtime.params import node_parameters
    from test.model.test_urdf import WRIST, forward

    params = tmp_path / "model_node.yaml"
    params.write_text(f"{namespace or '/**'}/model_node:\n  ros__parameters:\n    design:\n"
                      f"      file: {WRIST}\n"
                      "    markers:\n      arc_lengths: [0.005, 0.01]\n")
    nodes = _by_executable(VIEW, {"params_file": str(params), "namespace": namespace})
    publisher, arguments = nodes["robot_state_publisher"]
    description = str(_effective_parameters(publisher, arguments)["robot_description"])
    assert launch_fakes.resolve(publisher.namespace, arguments) == namespace

    port = MemoryPort(node_parameters([params], f"{namespace}/model_node"), name="model_node")
    ModelNode(port)
    port.deliver("tension", from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": port.clock_ns // 10**9, "nanosec": port.clock_ns % 10**9}},
        "wrench": {"force": {"z": 2.0}}}))
    port.advance(0.01)
    states = port.messages("joint_states")[-1]
    moving = [j.get("name") for j in ET.fromstring(description.split("\n", 1)[1]).iter("joint")
              if j.get("type") != "fixed"]
    assert sorted(moving) == sorted(["roll", *states.name])
    pose = forward(description.split("\n", 1)[1],
                   dict(zip(states.name, states.position, strict=True)) | {"roll": 0.0},
                   "tdcm_body_tip")
    assert pose[:3, 3] == pytest.approx(solve(named_design(WRIST), 2.0).tip_position, abs=1e-9)


def test_view_launch_opens_rviz_with_the_shipped_config_unless_told_not_to() -> None:
    nodes = _by_executable(VIEW, {})
    rviz, arguments = nodes["rviz2"]
    flag, config = launch_fakes.resolve(rviz.arguments, arguments)
    assert flag == "-d" and Path(config) == REPO / "config" / "rviz" / "tdcm.rviz"
    assert set(_by_executable(VIEW, {"rviz": "false"})) == {"robot_state_publisher"}
    with pytest.raises(ValueError, match="rviz"):
        _by_executable(VIEW, {"rviz": "yes"})


def test_the_bench_opens_the_view_only_when_asked() -> None:
    bench = REPO / "launch" / "bench.launch.py"
    assert not {"robot_state_publisher", "rviz2"} & set(_by_executable(bench, {}))
    nodes = _by_executable(bench, {"rviz": "true", "namespace": "/robot1",
                                   "frame_prefix": "robot1/"})
    publisher, arguments = nodes["robot_state_publisher"]
    values = _effective_parameters(publisher, arguments)
    assert launch_fakes.resolve(publisher.namespace, arguments) == "/robot1"
    assert values["frame_prefix"] == "robot1/"
    model, model_arguments = nodes["model_node"]
    assert launch_fakes.resolve(model.namespace, model_arguments) == "/robot1"
    assert "rviz2" in nodes
