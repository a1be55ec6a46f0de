"""model_node publishes the body's URDF joints on ``joint_states`` for every solve: the values
that put ``tdcm urdf``'s chain on the solved midline; it leaves the roll joint to the driver
and ignores its own messages."""

from __future__ import annotations

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import body_urdf, joint_names, joint_positions, named_design, solve
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort
from test.model.test_urdf import WRIST, forward


def test_joint_states_put_the_urdf_chain_on_the_solved_tip() -> None:
    port = MemoryPort({"design.file": WRIST, "markers.arc_lengths": [0.005, 0.01]},
                      name="model_node")
    node = ModelNode(port)
    port.deliver("tension", from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": port.clock_ns // 10**9, "nanosec": port.clock_ns % 10**9}},
        "wrench": {"force": {"z": 2.0}}}))
    port.advance(0.01)
    design = named_design(WRIST)
    expected = solve(design, 2.0)
    states = port.messages("joint_states")[-1]
    assert list(states.name) == joint_names(design)[1:]  # no roll: the driver's joint
    assert list(states.position) == pytest.approx(joint_positions(expected)[1:].tolist(),
                                                  abs=1e-12)
    values = dict(zip(states.name, states.position, strict=True)) | {"roll": 0.0}
    pose = forward(body_urdf(design), values, "tdcm_body_tip")
    assert pose[:3, 3] == pytest.approx(expected.tip_position, abs=1e-9)
    before = dict(node.counts)
    port.deliver("joint_states", states)  # its own message comes back on the shared topic
    port.advance(0.01)
    assert dict(node.counts) == before
