"""model_node processes a tension when it arrives, keeping the newest only while it is busy
(in-process, MemoryPort: a burst is inputs that arrive during a solve); the skipped ones are
counted as coalesced on /diagnostics, and under friction the history skips them too."""

from __future__ import annotations

from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import FrictionTrack, preset
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort

MS = 1_000_000


def wrench(newtons: float, stamp_ns: int) -> Any:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9}},
        "wrench": {"force": {"z": newtons}}})


def stamp_of(message: Any) -> int:
    return int(message.header.stamp.sec) * 10**9 + int(message.header.stamp.nanosec)


def input_counters(port: MemoryPort) -> dict[str, str]:
    status = {s.name: s for s in port.messages("/diagnostics")[-1].status}
    return {kv.key: kv.value for kv in status["model_node: input"].values}


def test_a_tension_is_solved_when_it_arrives() -> None:
    port = MemoryPort(name="model_node")
    ModelNode(port)
    for k in range(3):
        stamp = port.clock_ns
        port.deliver("tension", wrench(10.0 + k, stamp))  # no clock step: no timer to wait for
        (sent_ns, tip), = port.sent("tip_pose")[k:]
        assert (sent_ns, stamp_of(tip)) == (stamp, stamp)
        port.advance(0.0005)


def test_inputs_arriving_during_a_solve_leave_the_newest_counted_as_coalesced() -> None:
    port = MemoryPort({"output.visual_rate_hz": 0.0}, name="model_node")
    node = ModelNode(port)
    stamps = [port.clock_ns - k * MS for k in (5, 4, 3, 2)]
    with port.burst():
        for newtons, stamp in zip((5.0, 20.0, 8.0, 12.0), stamps, strict=True):
            port.deliver("tension", wrench(newtons, stamp))
        assert port.messages("midline") == []
    assert [stamp_of(m) for m in port.messages("midline")] == [stamps[-1]]
    assert (node.counts["solved"], node.counts["coalesced"]) == (1, 3)
    port.deliver("tension", wrench(9.0, port.clock_ns))  # idle again: solved at once
    assert (node.counts["solved"], node.counts["coalesced"]) == (2, 3)
    port.advance(1.0)
    counters = input_counters(port)
    assert counters["coalesced"] == "3"
    node.process()  # nothing pending: nothing solved
    assert node.counts["solved"] == 2


def test_under_friction_the_history_holds_only_the_solved_tensions() -> None:
    """A burst 0 -> 20 -> 10 N solves 10 N after the slack start, loading: the 20 N it skipped
    would have made it unloading."""
    design = preset("paper-experiment")
    port = MemoryPort({"output.visual_rate_hz": 0.0, "friction.mu": 0.3}, name="model_node")
    ModelNode(port)
    port.deliver("tension", wrench(0.0, port.clock_ns))
    with port.burst():
        for newtons in (20.0, 10.0):
            port.deliver("tension", wrench(newtons, port.clock_ns))
    loading = FrictionTrack(0.3)
    loading.solve(design, 0.0)
    p = port.messages("tip_pose")[-1].pose.position
    assert np.allclose([p.x, p.y, p.z], loading.solve(design, 10.0).tip_position, rtol=0.0,
                       atol=1e-9)
