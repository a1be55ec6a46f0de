"""``use_sim_time`` on both runtimes (see conftest.py): a node port set so (from its parameter
overrides, as a ``--params`` file gives them) takes ``now_ns`` from ``/clock``; otherwise the
system clock."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.port import CLOCK_QOS, CLOCK_TOPIC, CLOCK_TYPE
from tdcm_ros.runtime.run_node import open_context
from test.support.waiting import eventually

BAG_NS = 1_700_000_123_456_789_012


@pytest.fixture
def own_context(runtime: str) -> Iterator[Any]:
    """The package's context of the test's runtime (its ports are the nodes' ports)."""
    context = open_context(runtime)
    yield context
    context.close()


def clock_message(ns: int) -> Any:
    return from_dict(CLOCK_TYPE, {"clock": {"sec": ns // 10**9, "nanosec": ns % 10**9}})


def sim_time_parameter(port: Any) -> Any:
    """The port's ``use_sim_time``: rclpy's own parameter, or the zenoh port's."""
    return port.node.get_parameter("use_sim_time").value if hasattr(port, "node") else \
        port.get_parameter("use_sim_time")


def test_a_port_on_sim_time_follows_clock(own_context: Any) -> None:
    simulated = own_context.create_port("on_bag_time", overrides={"use_sim_time": True})
    wall = own_context.create_port("on_wall_time")
    assert sim_time_parameter(simulated) is True
    assert sim_time_parameter(wall) is False
    clock = wall.create_publisher(CLOCK_TOPIC, CLOCK_TYPE, CLOCK_QOS)
    for stamp_ns in (BAG_NS, BAG_NS + 5):  # /clock is best effort: sent until taken
        eventually(lambda stamp_ns=stamp_ns: simulated.now_ns() == stamp_ns, 20.0,
                   f"now_ns = {stamp_ns}", spin=own_context,
                   action=lambda stamp_ns=stamp_ns: clock.publish(clock_message(stamp_ns)),
                   every=0.1, detail=lambda: f"now_ns {simulated.now_ns()}")
    before = time.time_ns()
    assert before <= wall.now_ns() <= time.time_ns()   # the other port keeps the system clock
