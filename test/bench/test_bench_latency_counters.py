"""bench_latency reads model_node's counters from every status of a /diagnostics array (the
input status holds ``coalesced`` and the drops, the solver status ``solved`` and the failures)
and accounts each tension once: here on a real model_node (MemoryPort) after a burst."""

from __future__ import annotations

import sys
from pathlib import Path

from tdcm_ros.bagio import from_dict
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import bench_latency  # a script of bench/ (it imports bench/results.py)


def wrench(newtons: float, stamp_ns: int) -> object:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9}},
        "wrench": {"force": {"z": newtons}}})


def test_counters_of_both_statuses_account_for_every_tension_sent() -> None:
    port = MemoryPort({"design.E": 1.0e7}, name="model_node")  # too soft: solves fail
    ModelNode(port)
    sent = 0
    for burst in range(3):
        with port.burst():
            for k in range(4):
                port.deliver("tension", wrench(5.0 + k, port.clock_ns))
                sent += 1
        port.advance(0.01)
    port.deliver("tension", wrench(-1.0, port.clock_ns))  # dropped: negative
    port.deliver("tension", wrench(5.0, port.clock_ns - 10 * 10**9))  # dropped: stale
    sent += 2
    assert port.store.set({"design.E": 2.0e9}).successful
    for k in range(5):
        port.deliver("tension", wrench(5.0 + k, port.clock_ns))
        port.advance(0.01)
        sent += 1
    port.advance(1.0)
    counters = bench_latency.node_counters(port.messages("/diagnostics")[-1])
    assert counters["coalesced"] == 9 and counters["solved"] == 5
    assert counters["dropped_in_window"] == 2 and sum(
        v for k, v in counters.items() if k.startswith("model_")) == 3
    assert bench_latency.accounted_inputs(counters) == sent
