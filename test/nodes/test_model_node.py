"""model_node in its own process, on the embedded runtime and on rclpy (see conftest.py): what
only a process shows (the wire, parameter services, a peer restarting). Its input gating, to the
ns on simulated time: test_model_node_gating.py."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import preset, solve
from test.support.processes import REPO
from test.support.waiting import eventually

MODEL = "tdcm_ros.nodes.model_node:ModelNode"
Spawn = Callable[..., subprocess.Popen[bytes]]


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
        """Publish ``tension`` (freshly stamped, every 0.15 s) until a midline with the stamp of
        one of them arrives."""
        stamps: set[int] = set()

        def publish() -> None:
            stamps.add(time.time_ns())
            self.tension.publish(wrench(tension, max(stamps)))

        def answered() -> Any:
            return next((path for path in self.paths
                         if path.header.stamp.sec * 10**9 + path.header.stamp.nanosec in stamps),
                        None)

        return eventually(answered, timeout, f"a midline for {tension} N", spin=self.ctx,
                          action=publish, every=0.15)

    def counter(self, key: str) -> int:
        for array in reversed(self.diagnostics):
            for value in array.status[0].values:
                if value.key == key:
                    return int(value.value)
        return 0


def tip(path: Any) -> np.ndarray:
    p = path.poses[-1].pose.position
    return np.array([p.x, p.y, p.z])


def test_midline_equals_library_solve_and_parameters_change_at_runtime(runtime, context, spawn,
                                                                     params):
    spawn("tdcm_ros.runtime.run_node", MODEL)
    probe = Probe(context)
    path = probe.midline_for(20.0)
    expected = solve(preset("paper-experiment"), 20.0)
    assert path.header.frame_id == "tdcm_base" and len(path.poses) == 54
    assert np.allclose(tip(path), expected.tip_position, atol=1e-12)
    positions, _ = expected.pose_at(np.linspace(0, expected.design.length, 54))
    got = np.array([[p.pose.position.x, p.pose.position.y, p.pose.position.z] for p in path.poses])
    assert np.allclose(got, positions, atol=1e-12)

    node = params("/model_node")
    assert {"design.E", "frame_id", "solver.tol", "input.tension_max"} <= set(node.names())
    assert node.set("design.E", 1.2e9) == {"successful": True, "reason": ""}
    assert node.get("design.E") == 1.2e9
    softer = solve(preset("paper-experiment").with_overrides(E=1.2e9), 20.0)
    assert np.allclose(tip(probe.midline_for(20.0)), softer.tip_position, atol=1e-12)
    assert node.set("frame_id", "robot_base")["successful"]
    assert probe.midline_for(20.0).header.frame_id == "robot_base"

    for name, value in (("design.E", -5.0), ("design.r_inner", 0.01)):
        answer = node.set(name, value)
        assert not answer["successful"] and name.split(".")[1] in answer["reason"], answer
    assert node.get("design.E") == 1.2e9
    refused = node.set("design.preset", "ideal")
    assert not refused["successful"] and "read-only" in refused["reason"]
    assert node.get("design.preset") == "paper-experiment"
    assert np.allclose(tip(probe.midline_for(20.0)), softer.tip_position, atol=1e-12)


def test_bad_messages_are_counted_and_the_node_keeps_running(runtime, context, spawn):
    node = spawn("tdcm_ros.runtime.run_node", MODEL)
    probe = Probe(context)
    probe.midline_for(4.0)
    for bad in (float("nan"), -3.0, 1e9):
        probe.tension.publish(wrench(bad))
    probe.tension.publish(wrench(8.0, time.time_ns() - 10 * 10**9))   # 10 s old: stale
    keys = ("dropped_non_finite", "dropped_negative", "dropped_above_max", "dropped_stale")
    eventually(lambda: all(probe.counter(k) >= 1 for k in keys), 15, f"{keys} on /diagnostics",
               spin=context, detail=lambda: {k: probe.counter(k) for k in keys})
    assert {k: probe.counter(k) for k in keys} == dict.fromkeys(keys, 1)
    assert node.poll() is None
    probe.midline_for(12.0)


def test_node_survives_its_peer_restarting(runtime, context, graph_env):
    import sys

    spawn_node = subprocess.Popen([sys.executable, "-m", "tdcm_ros.runtime.run_node", MODEL],
                                  env=graph_env)
    probe = Probe(context)
    try:
        for _ in range(2):
            publisher = subprocess.Popen([sys.executable, "-m", "test.runtime.peer_publisher", "16.0"],
                                         env=graph_env, cwd=REPO)
            probe.paths.clear()
            try:
                eventually(lambda: probe.paths, 20, "a midline from the (re)started publisher",
                           spin=context)
            finally:
                publisher.kill()
                publisher.wait()
            expected = solve(preset("paper-experiment"), 16.0).tip_position
            assert np.allclose(tip(probe.paths[-1]), expected, atol=1e-12)
    finally:
        spawn_node.kill()
        spawn_node.wait()


def test_a_model_files_tip_covariance_and_band_cross_the_wire(runtime, context, spawn,
                                                              tmp_path):
    """The uncertainty outputs (PoseWithCovarianceStamped, a Marker) reach a peer on each
    runtime, equal to what the node builds in-process (test_model_node_uncertainty.py)."""
    import yaml

    from tdcm_ros.model import ModelSpec, ParameterCovariance

    design = preset("paper-experiment").with_overrides(E=7.0e8)
    covariance = ParameterCovariance(("E",), np.array([7.0e8]), np.array([[(7e6) ** 2]]), 1e-4)
    model = tmp_path / "model.yaml"
    model.write_text(ModelSpec(design, 0.0, covariance).text(), encoding="utf-8")
    params = tmp_path / "params.yaml"
    params.write_text(yaml.safe_dump({"model_node": {"ros__parameters": {
        "design": {"file": str(model)}, "output": {"visual_rate_hz": 0.0}}}}))
    spawn("tdcm_ros.runtime.run_node", MODEL, "--params", str(params))
    probe = Probe(context)
    port = context.create_port("band_probe")
    tips: list[Any] = []
    bands: list[Any] = []
    port.create_subscription("tip_pose_with_covariance",
                             "geometry_msgs/msg/PoseWithCovarianceStamped", tips.append)
    port.create_subscription("shape_band", "visualization_msgs/msg/Marker", bands.append)
    path = probe.midline_for(20.0)
    stamp = (path.header.stamp.sec, path.header.stamp.nanosec)
    def stamped(messages: list[Any]) -> Any:
        return next((m for m in messages
                     if (m.header.stamp.sec, m.header.stamp.nanosec) == stamp), None)

    tip_msg = eventually(lambda: stamped(tips), 20.0, "the tip with covariance", spin=context)
    band = eventually(lambda: stamped(bands), 20.0, "the band", spin=context)
    assert band.ns == "tdcm_band" and len(band.points) == 6 * 53
    expected = solve(design, 20.0)
    got = tip_msg.pose.pose.position
    assert np.allclose([got.x, got.y, got.z], expected.tip_position, atol=1e-12)
    cov = np.reshape(tip_msg.pose.covariance, (6, 6))
    # E moves the tip in x and z; y has the residual alone (0.1 mm)
    assert cov[0, 0] > 1e-8 and cov[1, 1] == 1e-4**2
