"""metrics_node does not lose what it scores while it is busy: a burst of marker frames and
tensions arriving while its executor does not run (a slow update, a loaded machine) is all
counted once it runs again. In-process on the zenoh runtime (one session, no router, so the
samples go no further than the subscription's queue, whose depth is what is tested)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.nodes.metrics_node import SCORED_DEPTH, MetricsNode
from tdcm_ros.runtime.port import DEFAULT_QOS, QoS
from test.support.waiting import eventually

zenoh_runtime = pytest.importorskip("tdcm_ros.runtime.zenoh_runtime")

#: The sample bag's 6,758 marker frames arrived at metrics_node as 6,244 on a loaded machine
#: (rclpy, depth 100): a burst well past the old depth, within the new one.
BURST = 3000


@pytest.fixture
def context() -> Iterator[Any]:
    import zenoh

    config = zenoh.Config()
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    ctx = zenoh_runtime.ZenohContext(zenoh.open(config))
    yield ctx
    ctx.close()


def _header(n: int, frame: str) -> dict[str, Any]:
    return {"stamp": {"sec": n // 100, "nanosec": (n % 100) * 10_000_000}, "frame_id": frame}


def test_a_burst_while_metrics_node_is_busy_is_counted_in_full(context: Any) -> None:
    node = MetricsNode(context.create_port("metrics_node"))
    source = context.create_port("player")
    markers = source.create_publisher("/markers", "mocap4r2_msgs/msg/Markers", QoS(depth=10))
    tension = source.create_publisher("/tension", "geometry_msgs/msg/WrenchStamped",
                                      QoS(depth=100))
    eventually(lambda: markers.matched() and tension.matched(), 10.0,
               "the publishers to match metrics_node's subscriptions")
    tasks = context.executor._tasks
    queued = tasks.qsize()
    for n in range(BURST):  # the node's executor does not run meanwhile: it is busy
        markers.publish(from_dict("mocap4r2_msgs/msg/Markers", {
            "header": _header(n, "mocap"), "frame_number": n, "markers": []}))
        tension.publish(from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": _header(n, "tdcm_tendon"), "wrench": {"force": {"z": 1.0}}}))
    # every sample has reached its subscription (one delivery task each) before the node runs
    eventually(lambda: tasks.qsize() >= queued + 2 * BURST, 30.0, "the burst to arrive",
               detail=lambda: f"{tasks.qsize() - queued} of {2 * BURST} arrived")
    eventually(lambda: tasks.qsize() == 0, 60.0, "the node to take the burst", spin=context)
    assert (node.counts["marker_frames"], node.counts["tension"]) == (BURST, BURST)
    assert BURST < SCORED_DEPTH


def test_every_scored_input_is_reliable_and_deep_enough_for_the_sample_bag() -> None:
    from tdcm_ros.runtime.memory_port import MemoryPort

    port = MemoryPort(name="metrics_node")
    seen: dict[str, QoS] = {}
    create = port.create_subscription

    def record(topic: str, type_name: str, callback: Any, qos: QoS = DEFAULT_QOS) -> Any:
        seen[topic] = qos
        return create(topic, type_name, callback, qos)

    port.create_subscription = record  # type: ignore[method-assign]
    MetricsNode(port)
    for topic in ("tension", "markers", "joint_states"):
        assert seen[topic].reliability == "reliable", topic
        assert seen[topic].depth == SCORED_DEPTH >= 6758, topic  # the sample bag's frames
