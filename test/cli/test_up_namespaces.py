"""Two robots on one graph: ``tdcm up --namespace --frame-prefix`` twice, each model_node
answering only its own namespace's tension in its own frames on the shared /tf, on both
runtimes."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from tdcm_ros.model import preset, solve
from tdcm_ros.runtime import QoS
from test.nodes.test_model_node import wrench
from test.support.waiting import eventually

Spawn = Callable[..., subprocess.Popen[bytes]]


def tip_in(context: Any, namespace: str, tension: float) -> tuple[np.ndarray, str]:
    """Publish ``tension`` on ``namespace/tension`` until a midline stamped like it arrives on
    ``namespace/midline``; its tip (m) and frame."""
    port = context.create_port("probe", namespace)
    paths: list[Any] = []
    port.create_subscription("midline", "nav_msgs/msg/Path", paths.append)
    publisher = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped")
    stamps: set[int] = set()

    def publish() -> None:
        stamps.add(time.time_ns())
        publisher.publish(wrench(tension, max(stamps)))

    def answered() -> Any:
        return next((p for p in paths
                     if p.header.stamp.sec * 10**9 + p.header.stamp.nanosec in stamps), None)

    path = eventually(answered, 60.0, f"a midline on {namespace} for {tension} N",
                      spin=context, action=publish, every=0.15)
    position = path.poses[-1].pose.position
    return np.array([position.x, position.y, position.z]), path.header.frame_id


def test_two_robots_each_in_its_namespace_share_one_graph(runtime: str, context: Any,
                                                         spawn: Spawn) -> None:
    tf: list[Any] = []
    context.create_port("tf_probe").create_subscription("/tf", "tf2_msgs/msg/TFMessage",
                                                        tf.append, QoS(depth=100))
    for namespace in ("/robot1", "/robot2"):
        spawn("tdcm_ros", "up", "--runtime", runtime, "--nodes", "model_node",
              "--namespace", namespace, "--frame-prefix", namespace[1:] + "/",
              "-p", "model_node:design.E:=" + ("1.85e9" if namespace == "/robot1" else "1.2e9"))
    design = preset("paper-experiment")
    stiff = solve(design.with_overrides(E=1.85e9), 12.0).tip_position
    soft = solve(design.with_overrides(E=1.2e9), 12.0).tip_position
    for namespace, expected in (("/robot1", stiff), ("/robot2", soft)):
        tip, frame = tip_in(context, namespace, 12.0)
        assert np.allclose(tip, expected, atol=1e-12)
        assert frame == f"{namespace[1:]}/tdcm_base"

    def tip_frames() -> set[tuple[str, str]]:
        return {(t.header.frame_id, t.child_frame_id) for m in tf for t in m.transforms}

    both = {("robot1/tdcm_base", "robot1/tdcm_tip"), ("robot2/tdcm_base", "robot2/tdcm_tip")}
    tensions = [context.create_port("again", ns).create_publisher(
        "tension", "geometry_msgs/msg/WrenchStamped") for ns in ("/robot1", "/robot2")]
    eventually(lambda: both <= tip_frames(), 30.0, "both robots' tips on /tf", spin=context,
               action=lambda: [p.publish(wrench(12.0, time.time_ns())) for p in tensions],
               every=0.2)
    assert tip_frames() == both
