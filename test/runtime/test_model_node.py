"""model_node in its own process over the embedded runtime (zenoh router on a private port)."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import preset, solve

MODEL = "tdcm_ros.nodes.model_node:ModelNode"
Spawn = Callable[..., subprocess.Popen[bytes]]


@pytest.fixture
def context(router: subprocess.Popen[bytes]) -> Iterator[Any]:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    ctx = ZenohContext()
    yield ctx
    ctx.close()


def wrench(tension: float, stamp_ns: int | None = None) -> Any:
    stamp_ns = time.time_ns() if stamp_ns is None else stamp_ns
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9},
                   "frame_id": "tendon"},
        "wrench": {"force": {"z": tension}}})


class Probe:
    """A test-side port: publishes tensions, collects the model node's outputs."""

    def __init__(self, ctx: Any) -> None:
        self.ctx = ctx
        port = ctx.create_port("probe")
        self.paths: list[Any] = []
        self.markers: list[Any] = []
        self.diagnostics: list[Any] = []
        port.create_subscription("midline", "nav_msgs/msg/Path", self.paths.append)
        port.create_subscription("predicted_markers", "geometry_msgs/msg/PoseArray",
                                 self.markers.append)
        port.create_subscription("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                                 self.diagnostics.append)
        self.tension = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped")

    def midline_for(self, tension: float, timeout: float = 20.0) -> Any:
        """Publish ``tension`` until a midline with that stamp arrives."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            stamp = time.time_ns()
            self.tension.publish(wrench(tension, stamp))
            self.ctx.spin_for(0.15)
            for path in self.paths:
                got = path.header.stamp.sec * 10**9 + path.header.stamp.nanosec
                if got == stamp:
                    return path
        raise AssertionError(f"no midline for {tension} N within {timeout} s")

    def counter(self, key: str) -> int:
        for array in reversed(self.diagnostics):
            for value in array.status[0].values:
                if value.key == key:
                    return int(value.value)
        return 0


def tip(path: Any) -> np.ndarray:
    p = path.poses[-1].pose.position
    return np.array([p.x, p.y, p.z])


def test_midline_equals_library_solve_and_parameters_change_at_runtime(context, spawn):
    from tdcm_ros.runtime.zenoh_runtime import call_parameters

    spawn("tdcm_ros.runtime.run_node", MODEL, "--runtime", "zenoh")
    probe = Probe(context)
    path = probe.midline_for(20.0)
    expected = solve(preset("paper-experiment"), 20.0)
    assert path.header.frame_id == "tdcm_base" and len(path.poses) == 54
    assert np.allclose(tip(path), expected.tip_position, atol=1e-12)
    positions, _ = expected.pose_at(np.linspace(0, expected.design.length, 54))
    got = np.array([[p.pose.position.x, p.pose.position.y, p.pose.position.z] for p in path.poses])
    assert np.allclose(got, positions, atol=1e-12)

    call_parameters(context.session, 0, "/model_node", "set", {"name": "design.E", "value": 1.2e9})
    softer = solve(preset("paper-experiment").with_overrides(E=1.2e9), 20.0)
    assert np.allclose(tip(probe.midline_for(20.0)), softer.tip_position, atol=1e-12)

    for name, value in (("design.E", -5.0), ("design.r_inner", 0.01)):
        answer = call_parameters(context.session, 0, "/model_node", "set",
                                 {"name": name, "value": value})
        assert not answer["successful"] and name.split(".")[1] in answer["reason"]
    assert np.allclose(tip(probe.midline_for(20.0)), softer.tip_position, atol=1e-12)


def test_bad_messages_are_counted_and_the_node_keeps_running(context, spawn):
    node = spawn("tdcm_ros.runtime.run_node", MODEL, "--runtime", "zenoh")
    probe = Probe(context)
    probe.midline_for(4.0)
    for bad in (float("nan"), -3.0, 1e9):
        probe.tension.publish(wrench(bad))
    probe.tension.publish(wrench(8.0, time.time_ns() - 10 * 10**9))   # 10 s old: stale
    deadline = time.monotonic() + 15
    keys = ("dropped_non_finite", "dropped_negative", "dropped_above_max", "dropped_stale")
    while time.monotonic() < deadline and not all(probe.counter(k) >= 1 for k in keys):
        context.spin_for(0.2)
    assert {k: probe.counter(k) for k in keys} == dict.fromkeys(keys, 1)
    assert node.poll() is None
    probe.midline_for(12.0)


def test_node_survives_its_peer_restarting(context, spawn):
    spawn("tdcm_ros.runtime.run_node", MODEL, "--runtime", "zenoh")
    probe = Probe(context)
    values = "{wrench: {force: {z: 16.0}}}"
    for _ in range(2):
        publisher = spawn("tdcm_ros.cli.main", "topic", "pub", "tension",
                          "geometry_msgs/msg/WrenchStamped", values, "--rate", "20")
        probe.paths.clear()
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and not probe.paths:
            context.spin_for(0.1)
        assert probe.paths, "no midline from the restarted publisher"
        expected = solve(preset("paper-experiment"), 16.0).tip_position
        assert np.allclose(tip(probe.paths[-1]), expected, atol=1e-12)
        publisher.kill()
        publisher.wait()
