"""``frame_prefix`` on every node that names a frame of the robot: two robots' frames stay apart
on the shared /tf and /tf_static, the mocap frame is the room's, and a bad prefix is refused."""

from __future__ import annotations

import importlib
from typing import Any

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.nodes import (
    device_twin,
    metrics_node,
    mocap_node,
    model_node,
    shape_controller,
    tension_driver,
)
from tdcm_ros.nodes.frames import robot_frame
from tdcm_ros.runtime import FRAMED_NODES, NODES
from tdcm_ros.runtime.memory_port import MemoryPort
from test.nodes.driver_bench import DriverBench
from test.nodes.test_tf_broadcasts import _edges, _root, wrench

ROBOTS = ("robot1/", "robot2/")


def _robot(prefix: str) -> tuple[MemoryPort, MemoryPort]:
    """One robot's model_node (a solve done, 3 stations) and sim mocap_node."""
    model = MemoryPort({"frame_prefix": prefix, "tf.stations": 3}, name="model_node")
    node = model_node.ModelNode(model)
    model.deliver("tension", wrench(12.0, model.now_ns(), robot_frame(prefix, "tdcm_tendon")))
    node.process()
    mocap = MemoryPort({"source": "sim", "frame_prefix": prefix}, name="mocap_node")
    mocap_node.MocapNode(mocap)
    mocap.advance(0.05)
    return model, mocap


def _stamped(port: MemoryPort) -> set[str]:
    return {m.header.frame_id for topic, messages in port.published.items() for m in messages
            if getattr(m, "header", None) is not None and m.header.frame_id}


def test_two_robots_frames_form_one_tree_under_the_shared_mocap_frame() -> None:
    ports = {prefix: _robot(prefix) for prefix in ROBOTS}
    everything = [port for pair in ports.values() for port in pair]
    parents = _edges(*(m for port in everything for topic in ("/tf", "/tf_static")
                       for m in port.messages(topic)))
    for prefix, (model, mocap) in ports.items():
        own = {f"{prefix}{name}" for name in ("tdcm_base", "tdcm_tendon", "tdcm_tip",
                                              "tdcm_station_1", "tdcm_station_3")}
        assert own <= set(parents), (own - set(parents))
        assert parents[f"{prefix}tdcm_base"] == "mocap"  # the registration: the room's frame
        assert parents[f"{prefix}tdcm_tip"] == f"{prefix}tdcm_base"
        assert _stamped(model) == {f"{prefix}tdcm_base"}
        assert _stamped(mocap) == {"mocap"}
    frames = set(parents) | set(parents.values())
    assert {_root(frame, parents) for frame in frames} == {"mocap"}
    assert all(frame == "mocap" or frame.startswith(ROBOTS) for frame in frames), frames


def test_metrics_and_the_controller_work_in_the_prefixed_base() -> None:
    metrics = MemoryPort({"frame_prefix": "robot2/", "registration.source": "tf_static"},
                         name="metrics_node")
    node = metrics_node.MetricsNode(metrics)
    assert node.base_frame == "robot2/tdcm_base" and node.mocap_frame == "mocap"
    controller = MemoryPort({"frame_prefix": "robot2/"}, name="shape_controller")
    assert shape_controller.ShapeControllerNode(controller).base_frame == "robot2/tdcm_base"


def test_the_driver_stamps_its_tension_in_the_prefixed_tendon_frame() -> None:
    bench = DriverBench({"frame_prefix": "robot1/"})
    bench.advance(0.5)
    frames = {m.header.frame_id for m in bench.port.messages("tension")}
    assert frames == {"robot1/tdcm_tendon"}


@pytest.mark.parametrize("node", [model_node.ModelNode, mocap_node.MocapNode,
                                  metrics_node.MetricsNode, shape_controller.ShapeControllerNode,
                                  tension_driver.TensionDriverNode,
                                  device_twin.DeviceTwinNode])
@pytest.mark.parametrize("prefix", ["/robot1/", "robot 1/", "robot1/\n"])
def test_a_bad_prefix_is_refused_naming_the_parameter(node: Any, prefix: str) -> None:
    overrides: dict[str, Any] = {"frame_prefix": prefix}
    if node is mocap_node.MocapNode:
        overrides["source"] = "sim"
    with pytest.raises(InputError) as caught:
        node(MemoryPort(overrides, name=node.default_name))
    assert caught.value.parameter == "frame_prefix" and repr(prefix) in str(caught.value)


def test_the_registry_knows_which_nodes_take_a_frame_prefix() -> None:
    """FRAMED_NODES (what ``tdcm up --frame-prefix`` sets) is the nodes declaring it."""
    declared = {name for name, target in NODES.items()
                if "frame_prefix" in importlib.import_module(target.split(":")[0]).PARAMETERS}
    assert declared == FRAMED_NODES
