"""``NodePort.call_soon`` on both runtimes, as model_node's live path uses it: a callback queued
by a subscription's callback runs on the same thread after it, every input is either taken or
counted as skipped, the newest is taken, and a failing one is logged while the node goes on.
(How many of a burst coalesce depends on when the transport hands them over; the exact order
is the MemoryPort's and the zenoh executor's tests.)"""

from __future__ import annotations

import threading
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.port import NodeLogic, NodePort, QoS
from test.support.graph import private_domain_id, require_rclpy
from test.support.waiting import eventually

COUNT = 20


class Newest(NodeLogic):
    """Keeps the newest ``numbers`` and takes it in a ``call_soon`` callback."""

    default_name = "newest"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        port.create_subscription("numbers", "std_msgs/msg/Int32", self.on_number,
                                 QoS(depth=COUNT))
        self.pending: int | None = None
        self.taken: list[int] = []
        self.skipped = 0
        self.threads: set[int] = set()

    def on_number(self, message: Any) -> None:
        self.threads.add(threading.get_ident())
        if self.pending is None:
            self.port.call_soon(self.take)
        else:
            self.skipped += 1
        self.pending = int(message.data)

    def take(self) -> None:
        self.threads.add(threading.get_ident())
        assert self.pending is not None, "call_soon ran before the callback that queued it"
        self.taken.append(self.pending)
        self.pending = None


def fails() -> None:
    raise RuntimeError("a failing call_soon callback")


def burst(context: Any) -> None:
    node = Newest(context.create_port("newest"))
    publisher = context.create_port("numbers").create_publisher(
        "numbers", "std_msgs/msg/Int32", QoS(depth=COUNT))
    eventually(publisher.matched, 10.0, "the subscription to match", spin=context)
    node.port.call_soon(fails)  # logged and counted: the loop goes on
    for k in range(COUNT):
        publisher.publish(from_dict("std_msgs/msg/Int32", {"data": k}))
    eventually(lambda: node.taken[-1:] == [COUNT - 1], 10.0, "the newest number taken",
               spin=context, detail=lambda: node.taken)
    assert len(node.taken) + node.skipped == COUNT and node.taken == sorted(node.taken)
    assert len(node.threads) == 1  # the subscription's and call_soon's: one callback thread
    assert list(node.port.guard.failures) == ["call_soon fails"]  # type: ignore[attr-defined]


def test_zenoh_call_soon_runs_after_the_callback_and_takes_the_newest(router: Any) -> None:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    context = ZenohContext()
    try:
        burst(context)
    finally:
        context.close()


@pytest.mark.rclpy
def test_rclpy_call_soon_runs_after_the_callback_and_takes_the_newest(
        monkeypatch: pytest.MonkeyPatch) -> None:
    require_rclpy()
    monkeypatch.setenv("ROS_DOMAIN_ID", str(private_domain_id()))
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from tdcm_ros.runtime.rclpy_runtime import RclpyContext

    context = RclpyContext()
    try:
        burst(context)
    finally:
        context.close()
