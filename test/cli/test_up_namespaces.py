"""Two robots on one graph: ``tdcm up --namespace`` twice, each model_node answering only its
own namespace's tension, on both runtimes."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from tdcm_ros.model import preset, solve
from test.nodes.test_model_node import wrench
from test.support.waiting import eventually

Spawn = Callable[..., subprocess.Popen[bytes]]


def tip_in(context: Any, namespace: str, tension: float) -> np.ndarray:
    """Publish ``tension`` on ``namespace/tension`` until a midline stamped like it arrives on
    ``namespace/midline``; its tip (m)."""
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
    return np.array([position.x, position.y, position.z])


def test_two_robots_each_in_its_namespace_share_one_graph(runtime: str, context: Any,
                                                         spawn: Spawn) -> None:
    for namespace in ("/robot1", "/robot2"):
        spawn("tdcm_ros", "up", "--runtime", runtime, "--nodes", "model_node",
              "--namespace", namespace, "-p", "model_node:design.E:=" + (
                  "1.85e9" if namespace == "/robot1" else "1.2e9"))
    design = preset("paper-experiment")
    stiff = solve(design.with_overrides(E=1.85e9), 12.0).tip_position
    soft = solve(design.with_overrides(E=1.2e9), 12.0).tip_position
    assert np.allclose(tip_in(context, "/robot1", 12.0), stiff, atol=1e-12)
    assert np.allclose(tip_in(context, "/robot2", 12.0), soft, atol=1e-12)
