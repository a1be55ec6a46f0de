"""What each node declares is exactly its ``PARAMETERS`` table: the same names, each with the
spec's finite range as its ROS range (so parameter files checked against the table are checked
against what the node reads)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.registry import NODES
from test.support.nodes import START, built_node

#: the sensor inputs whose QoS a parameter file may override (``qos_overrides.<topic>...``)
SENSOR_INPUTS = {"metrics_node": ("/tension", "/markers", "/joint_states"),
                 "model_node": ("/tension", "/joint_states"),
                 "shape_controller": ("/markers", "/tension", "/joint_states"),
                 "mocap_node": ("/vicon/markers",)}


@pytest.mark.parametrize("node", sorted(NODES))
def test_declared_parameters_are_the_table(node: str, tmp_path: Path) -> None:
    module, port, logic = built_node(node, tmp_path)
    try:
        declared = port.store.specs
        qos = {name for name in declared if name.startswith("qos_overrides.")}
        assert list(declared) and set(declared) - qos == set(module.PARAMETERS)
        assert qos == {f"qos_overrides.{topic}.subscription.{policy}"
                       for topic in SENSOR_INPUTS.get(node, ())
                       for policy in ("reliability", "durability", "depth")}
        for name, spec in module.PARAMETERS.items():
            assert declared[name].range == spec.bounds, name
            assert declared[name].description.startswith(spec.description), name
    finally:
        logic.close()


@pytest.mark.parametrize(("node", "old", "new", "value"), [
    ("model_node", "markers.radius", "markers.ball_radius", 0.002),
    ("metrics_node", "markers.radius", "markers.ball_radius", 0.002),
    ("shape_controller", "markers.radius", "markers.ball_radius", 0.002),
    ("mocap_node", "markers.radius", "markers.radial_offset", 0.006),
])
def test_a_former_parameter_name_sets_the_new_one_and_warns(
        node: str, old: str, new: str, value: float, tmp_path: Path,
        caplog: pytest.LogCaptureFixture) -> None:
    """One name per concept: the ball radius is ``markers.ball_radius`` in every node, the
    mocap node's marker-centre distance ``markers.radial_offset``; a parameter file's former
    ``markers.radius`` still sets them, with a WARN on the node's log."""
    module_name, _, class_name = NODES[node].partition(":")
    module = importlib.import_module(module_name)
    assert old not in module.PARAMETERS and new in module.PARAMETERS
    port = MemoryPort({old: value, **START.get(node, {})}, name=node)
    with caplog.at_level("WARNING"):
        logic = getattr(module, class_name)(port)
    try:
        assert port.get_parameter(new) == value != module.PARAMETERS[new].default
        assert f"parameter {old} is deprecated; use {new} (same meaning)" in caplog.text
    finally:
        logic.close()
