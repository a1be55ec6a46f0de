"""model_node on /diagnostics the diagnostic_updater way (in-process, MemoryPort): one status per
component with stable names, levels that recover once the problem is gone."""

from __future__ import annotations

from typing import Any

from tdcm_ros.bagio import from_dict
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort

PERIOD_S = 1.0  #: the node's default diagnostics period


def wrench(newtons: float, stamp_ns: int) -> Any:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9}},
        "wrench": {"force": {"z": newtons}}})


def latest(port: MemoryPort) -> dict[str, Any]:
    """The newest status of each component, by name."""
    return {s.name: s for s in port.messages("/diagnostics")[-1].status}


def feed(port: MemoryPort, newtons: float, seconds: float) -> None:
    """Good tensions at 50 Hz for ``seconds``."""
    for _ in range(round(seconds * 50)):
        port.deliver("tension", wrench(newtons, port.clock_ns))
        port.advance(0.02)


def test_one_status_per_component_with_stable_names() -> None:
    port = MemoryPort(name="model_node")
    ModelNode(port)
    feed(port, 10.0, 2.0)
    arrays = port.messages("/diagnostics")
    assert len(arrays) == 2
    for array in arrays:
        assert [(s.name, s.hardware_id) for s in array.status] == [
            ("model_node: input", "tdcm_model"), ("model_node: solver", "tdcm_model")]
    status = latest(port)
    assert [status[n].level for n in status] == [0, 0]
    solver = {kv.key: kv.value for kv in status["model_node: solver"].values}
    assert int(solver["solved"]) > 0 and solver["failed_in_window"] == "0"


def test_a_dropped_input_warns_for_the_window_then_recovers() -> None:
    """One stale tension: WARN naming it, while it lies within the last 5 periods; OK after,
    with the cumulative count kept, while good inputs go on."""
    port = MemoryPort(name="model_node")
    ModelNode(port)
    feed(port, 10.0, 1.5)
    port.deliver("tension", wrench(8.0, port.clock_ns - 10 * 10**9))
    levels = []
    for _ in range(8):
        feed(port, 10.0, PERIOD_S)
        levels.append(latest(port)["model_node: input"].level)
    assert levels[:4] == [1, 1, 1, 1] and levels[-1] == 0, levels
    first_warn = port.messages("/diagnostics")[1].status[0]
    assert "dropped tension 8.0 N: stale" in first_warn.message
    recovered = latest(port)["model_node: input"]
    assert recovered.message == "ok"
    counts = {kv.key: kv.value for kv in recovered.values}
    assert counts["dropped_stale"] == "1" and counts["dropped_in_window"] == "0"


def test_solver_failures_warn_until_solves_succeed_for_a_window() -> None:
    port = MemoryPort({"design.E": 1.0e7}, name="model_node")  # too soft: the tendon path cusps
    ModelNode(port)
    feed(port, 5.0, 1.5)
    failing = latest(port)["model_node: solver"]
    assert failing.level == 1 and "tendon-offset singularity" in failing.message
    assert latest(port)["model_node: input"].level == 0  # the input itself was fine
    assert port.store.set({"design.E": 2.0e9}).successful
    feed(port, 5.0, 6.0 * PERIOD_S)
    solver = latest(port)["model_node: solver"]
    assert (solver.level, solver.message) == (0, "ok")
