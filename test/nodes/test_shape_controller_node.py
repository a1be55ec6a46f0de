"""shape_controller in its own process, on the embedded runtime and on rclpy (see conftest.py).

The test peer plays the driver (its limits as parameters of a node named ``tension_driver``;
``tension`` and ``joint_states`` echo the setpoints, as a driver holding them would) and
mocap_node (``markers`` in ``mocap`` of a world whose E is the model's / 1.3, the registration
on transient-local ``/tf_static``). The logic in detail: test_shape_controller_logic.py.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tdcm_ros.bagio import from_dict
from tdcm_ros.control import rotate_z
from tdcm_ros.mocap import Registration
from tdcm_ros.model import MarkerLayout, preset, solve, surface_points
from tdcm_ros.nodes.shape_controller import LATE_STEPS_COUNTED
from tdcm_ros.runtime.port import QoS
from test.support.waiting import eventually

NODE = "tdcm_ros.nodes.shape_controller:ShapeControllerNode"
DESIGN = preset("paper-experiment")
WORLD = DESIGN.with_overrides(E=DESIGN.E / 1.3)
LAYOUT = MarkerLayout()
LIMITS = {"tension_max": 20.0, "setpoint_rate": 40.0, "roll_max": 1.2, "roll_rate": 1.0}
REGISTRATION = Registration((0.2, 0.0, 0.5), (0.0, 0.0, math.sin(math.pi / 12),
                                              math.cos(math.pi / 12)))


def header(frame: str) -> dict[str, Any]:
    ns = time.time_ns()
    return {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": frame}


def xyz(point: Any) -> list[float]:
    return [point.x, point.y, point.z]


class Peer:
    """The driver's limits and echo, the world's markers; collects the node's outputs."""

    def __init__(self, ctx: Any, driver_limits: dict[str, float] | None) -> None:
        self.ctx = ctx
        port = ctx.create_port("controller_peer")
        if driver_limits is not None:
            driver = ctx.create_port("tension_driver")
            declare = getattr(driver, "declare_parameter", None) or driver.node.declare_parameter
            for name, value in driver_limits.items():
                declare(name, value)
        self.outputs: dict[str, list[Any]] = {}
        point, flt = "geometry_msgs/msg/PointStamped", "std_msgs/msg/Float64"
        for topic, kind in (("tension_setpoint", flt), ("roll_setpoint", flt),
                            ("controller/measured_tip", point), ("controller/predicted_tip", point),
                            ("controller/tracking_error", "geometry_msgs/msg/Vector3Stamped"),
                            ("controller/gain", flt), ("controller/gain_std", flt),
                            ("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray")):
            sink = self.outputs.setdefault(topic, [])
            port.create_subscription(topic, kind, sink.append, QoS(depth=100))
        sink = self.outputs.setdefault("controller/target_tip", [])
        port.create_subscription("controller/target_tip", point, sink.append,
                                 QoS(depth=1, durability="transient_local"))
        self.tf = port.create_publisher("/tf_static", "tf2_msgs/msg/TFMessage",
                                        QoS(depth=1, durability="transient_local"))
        self.target = port.create_publisher("target_point", point)
        self.tension = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped",
                                             QoS(depth=100))
        self.joints = port.create_publisher("joint_states", "sensor_msgs/msg/JointState")
        self.markers = port.create_publisher("markers", "mocap4r2_msgs/msg/Markers")

    def send_registration(self) -> None:
        self.tf.publish(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
            "header": header("mocap"), "child_frame_id": "tdcm_base",
            "transform": {"translation": dict(zip("xyz", REGISTRATION.translation, strict=True)),
                          "rotation": dict(zip("xyzw", REGISTRATION.quaternion, strict=True))}}]}))

    def send_target(self, point_base: tuple[float, float, float]) -> None:
        point = REGISTRATION.to_mocap(np.asarray(point_base))
        self.target.publish(from_dict("geometry_msgs/msg/PointStamped", {
            "header": header("mocap"), "point": dict(zip("xyz", map(float, point), strict=True))}))

    def echo(self, tension: float, roll: float) -> None:
        """The driver holding the setpoints and the world bending under them, in mocap."""
        self.tension.publish(from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": header("tdcm_tendon"), "wrench": {"force": {"z": tension}}}))
        self.joints.publish(from_dict("sensor_msgs/msg/JointState", {
            "header": header(""), "name": ["roll"], "position": [roll]}))
        planar = surface_points(solve(WORLD, tension), LAYOUT.s, LAYOUT.radius(DESIGN.R_outer),
                                LAYOUT.side_rad)[0]
        mocap = REGISTRATION.to_mocap(np.array([rotate_z(tuple(p), roll) for p in planar]))
        self.markers.publish(from_dict("mocap4r2_msgs/msg/Markers", {
            "header": header("mocap"), "frame_number": 0,
            "markers": [{"id_type": 2, "marker_index": i, "marker_name": label,
                         "translation": dict(zip("xyz", row, strict=True))}
                        for i, (label, row) in enumerate(zip(LAYOUT.labels, mocap.tolist(),
                                                             strict=True))]}))

    def last(self, topic: str) -> Any:
        return self.outputs[topic][-1] if self.outputs[topic] else None

    def status(self) -> Any:
        array = self.last("/diagnostics")
        return array.status[0] if array is not None else None

    def diagnostic(self, key: str) -> str | None:
        status = self.status()
        return {kv.key: kv.value for kv in status.values}.get(key) if status else None

    def spin_until(self, predicate: Callable[[], bool], timeout: float, what: str,
                   step: Callable[[], None] | None = None) -> None:
        """:func:`eventually`, spinning the peer's context and running ``step`` between checks;
        a timeout shows the node's latest diagnostics."""
        eventually(predicate, timeout, what, spin=self.ctx, action=step, every=0.0,
                   detail=lambda: f"diagnostics: {(s := self.status()) and s.message}")


def params_file(tmp_path: Path, values: dict[str, Any]) -> str:
    path = tmp_path / "shape_controller.yaml"
    path.write_text(yaml.safe_dump({"shape_controller": {"ros__parameters": values}}))
    return str(path)


def model_tip(tension: float, roll: float) -> tuple[float, float, float]:
    x, _, z = solve(DESIGN, tension).tip_position
    return rotate_z((float(x), 0.0, float(z)), roll)


def test_a_target_in_mocap_is_tracked_with_feedback_from_markers(runtime, context, spawn, params,
                                                                  tmp_path) -> None:
    peer = Peer(context, LIMITS)
    peer.send_registration()
    node = spawn("tdcm_ros.runtime.run_node", NODE, "--params", params_file(tmp_path, {
        "limits_period_s": 0.5, "diagnostics_period_s": 0.2}))
    peer.spin_until(lambda: peer.diagnostic("roll_max") == "1.2", 30.0, "the driver's limits")
    assert peer.outputs["tension_setpoint"] == []   # no target yet: nothing commanded

    target = model_tip(10.0, 0.4)
    # re-sent until resolved: on rclpy the node's target subscription may match after its
    # diagnostics publisher did (discovery is per endpoint); the same target is idempotent
    eventually(lambda: peer.outputs["controller/target_tip"], 10.0, "the resolved target",
               spin=peer.ctx, action=lambda: peer.send_target(target), every=0.5)
    assert xyz(peer.last("controller/target_tip").point) == pytest.approx(target, abs=1e-12)
    peer.spin_until(lambda: peer.last("tension_setpoint") is not None
                    and peer.last("tension_setpoint").data == pytest.approx(10.0, abs=1e-6)
                    and peer.last("roll_setpoint").data == pytest.approx(0.4), 10.0,
                    "the feed-forward setpoints (model: 10 N, 0.4 rad)")
    # Slewed at the driver's setpoint_rate (40 N/s): the first tick by one period (0.05 s) from
    # 0 N, each later one by the time since the last, at most LATE_STEPS_COUNTED periods (the
    # law on simulated time: test_shape_controller_logic.py); a ramp, never down.
    setpoints = [m.data for m in peer.outputs["tension_setpoint"]]
    assert setpoints[0] <= 40.0 * 0.05 + 1e-9
    steps = np.diff(setpoints)
    assert np.all(steps >= 0.0) and np.all(steps <= 40.0 * 0.05 * LATE_STEPS_COUNTED + 1e-9)

    def close_loop() -> None:
        peer.echo(peer.last("tension_setpoint").data, peer.last("roll_setpoint").data)

    peer.spin_until(lambda: peer.last("controller/gain") is not None
                    and abs(peer.last("controller/gain").data - 1.3) < 0.01, 30.0,
                    "the gain to learn the world's 1.3", step=close_loop)
    peer.spin_until(lambda: peer.last("tension_setpoint").data < 10.0 / 1.29, 10.0,
                    "the feed-forward corrected", step=close_loop)
    # the settled error to the µm is checked on simulated time (test_shape_controller_logic)
    peer.spin_until(lambda: np.linalg.norm(xyz(peer.last("controller/tracking_error").vector))
                    < 0.3e-3, 10.0, "the tracking error under 0.3 mm", step=close_loop)
    assert xyz(peer.last("controller/measured_tip").point) == pytest.approx(
        np.add(target, xyz(peer.last("controller/tracking_error").vector)), abs=1e-12)
    assert peer.last("controller/gain_std").data < 0.3

    controller = params("/shape_controller")
    assert controller.set("mode", "feedforward") == {"successful": True, "reason": ""}
    assert controller.get("mode") == "feedforward"
    refused = controller.set("mode", "closed")
    assert not refused["successful"] and "mode" in refused["reason"]

    peer.target.publish(from_dict("geometry_msgs/msg/PointStamped", {
        "header": header("nowhere"), "point": {"x": 0.003, "y": 0.0, "z": 0.05}}))
    peer.spin_until(lambda: "frame 'nowhere' is in no TF edge" in (peer.status().message or ""),
                    10.0, "the refusal on /diagnostics")
    assert node.poll() is None


def test_without_the_driver_nothing_is_commanded_and_diagnostics_say_why(runtime, context, spawn,
                                                                         tmp_path) -> None:
    peer = Peer(context, None)
    spawn("tdcm_ros.runtime.run_node", NODE, "--params", params_file(tmp_path, {
        "limits_period_s": 0.5, "diagnostics_period_s": 0.2}))
    peer.spin_until(lambda: peer.status() is not None and "cannot read" in peer.status().message,
                    30.0, "the failed read of the driver's limits")
    assert "commanding nothing: driver limits unknown" in peer.status().message
    eventually(lambda: int(peer.diagnostic("targets_refused") or 0) >= 1, 10.0,
               "the target refused on /diagnostics", spin=peer.ctx,
               action=lambda: peer.send_target(model_tip(5.0, 0.0)), every=0.5)
    arrays = len(peer.outputs["/diagnostics"])  # the control step runs 4 times a period
    eventually(lambda: len(peer.outputs["/diagnostics"]) >= arrays + 2, 10.0,
               "two more diagnostics periods", spin=peer.ctx)
    assert peer.outputs["tension_setpoint"] == []
