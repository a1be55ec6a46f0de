"""shape_controller's logic in-process (MemoryPort, manual clock): the driver's limits from its
parameter services, targets through TF, slewed setpoints, refusals, the gain learned from
markers of a world whose E differs, and the fallbacks. The same node in its own process on both
runtimes: test_shape_controller_node.py."""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict, to_dict
from tdcm_ros.control import rotate_z
from tdcm_ros.mocap import Registration
from tdcm_ros.model import MarkerLayout, preset, solve, surface_points
from tdcm_ros.nodes.shape_controller import ShapeControllerNode
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.param_services import to_value

DESIGN = preset("paper-experiment")
LAYOUT = MarkerLayout()
LIMITS = {"tension_max": 20.0, "setpoint_rate": 40.0, "roll_max": 1.2, "roll_rate": 1.0}
#: tdcm_base in mocap: 0.2 m over, 0.5 m up, turned 30 degrees about z
REGISTRATION = Registration((0.2, 0.0, 0.5), (0.0, 0.0, math.sin(math.pi / 12),
                                              math.cos(math.pi / 12)))


def driver_parameters(port: MemoryPort, values: dict[str, float]) -> None:
    """The driver's get_parameters service: the values it has, none for the others."""
    def answer(request: Any) -> Any:
        found = [to_dict(to_value(values[name])) for name in request.names if name in values]
        return from_dict("rcl_interfaces/srv/GetParameters_Response", {"values": found})

    port.add_remote_service("/tension_driver/get_parameters", "rcl_interfaces/srv/GetParameters",
                            answer)


def header(port: MemoryPort, frame: str, stamp_ns: int | None = None) -> dict[str, Any]:
    ns = port.clock_ns if stamp_ns is None else stamp_ns
    return {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": frame}


class Bench:
    """The node on a MemoryPort with the driver's limits served and the registration sent."""

    def __init__(self, overrides: dict[str, Any] | None = None, limits: bool = True) -> None:
        self.port = MemoryPort({"period_s": 0.05, "limits_period_s": 0.2, **(overrides or {})},
                               name="shape_controller")
        if limits:
            driver_parameters(self.port, LIMITS)
        self.node = ShapeControllerNode(self.port, limits_on_timer=True)
        self.taken: list[tuple[int, float, float]] = []  # (stamp ns, tension, roll) followed
        if limits:
            assert self.node.limits.limits is not None  # read at start
        t, q = REGISTRATION.translation, REGISTRATION.quaternion
        self.port.deliver("/tf_static", from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
            "header": header(self.port, "mocap"), "child_frame_id": "tdcm_base",
            "transform": {"translation": dict(zip("xyz", t, strict=True)),
                          "rotation": dict(zip("xyzw", q, strict=True))}}]}))

    def close(self) -> None:
        self.node.close()

    def target(self, point_base: tuple[float, float, float], frame: str = "mocap") -> None:
        point = REGISTRATION.to_mocap(np.asarray(point_base)) if frame == "mocap" else point_base
        self.port.deliver("target_point", from_dict("geometry_msgs/msg/PointStamped", {
            "header": header(self.port, frame), "point": dict(zip("xyz", map(float, point),
                                                                  strict=True))}))

    def tension(self, newtons: float, stamp_ns: int | None = None) -> None:
        self.port.deliver("tension", from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": header(self.port, "tdcm_tendon", stamp_ns),
            "wrench": {"force": {"z": newtons}}}))

    def roll(self, radians: float, stamp_ns: int | None = None) -> None:
        self.port.deliver("joint_states", from_dict("sensor_msgs/msg/JointState", {
            "header": header(self.port, "", stamp_ns), "name": ["roll"], "position": [radians]}))

    def markers(self, world_tension: float, roll: float, modulus_ratio: float,
                rng: np.random.Generator, stamp_ns: int | None = None) -> None:
        world = DESIGN.with_overrides(E=DESIGN.E / modulus_ratio)
        planar = surface_points(solve(world, world_tension), LAYOUT.s,
                                LAYOUT.radius(DESIGN.R_outer), LAYOUT.side_rad)[0]
        base = np.array([rotate_z(tuple(p), roll) for p in planar])
        mocap = REGISTRATION.to_mocap(base) + rng.normal(0.0, 5e-5, base.shape)
        self.port.deliver("markers", from_dict("mocap4r2_msgs/msg/Markers", {
            "header": header(self.port, "mocap", stamp_ns), "frame_number": 0,
            "markers": [{"id_type": 2, "marker_index": i, "marker_name": label,
                         "translation": dict(zip("xyz", row, strict=True))}
                        for i, (label, row) in enumerate(zip(LAYOUT.labels, mocap.tolist(),
                                                             strict=True))]}))

    def last(self, topic: str) -> Any:
        return self.port.messages(topic)[-1]

    def follow(self, seconds: float, modulus_ratio: float, rng: np.random.Generator,
               markers: bool = True, lag_steps: int = 0, tension_lag_steps: int = 0) -> None:
        """The bench closed: the driver holds the last setpoints, the world bends; each marker
        frame reaches the node ``lag_steps`` steps (0.05 s each) after it was taken, each
        tension and roll ``tension_lag_steps`` steps after it was measured."""
        for _ in range(round(seconds / 0.05)):
            self.port.advance(0.05)
            if not self.port.messages("tension_setpoint"):
                continue
            tension = float(self.last("tension_setpoint").data)
            roll = float(self.last("roll_setpoint").data)
            self.taken.append((self.port.clock_ns, tension, roll))
            if len(self.taken) > tension_lag_steps:
                stamp, then_n, then_roll = self.taken[-1 - tension_lag_steps]
                self.tension(then_n, stamp_ns=stamp)
                self.roll(then_roll, stamp_ns=stamp)
            if markers and len(self.taken) > lag_steps:
                stamp, then_n, then_roll = self.taken[-1 - lag_steps]
                self.markers(then_n, then_roll, modulus_ratio, rng, stamp_ns=stamp)


@pytest.fixture
def bench() -> Any:
    made: list[Bench] = []

    def make(**kwargs: Any) -> Bench:
        made.append(Bench(**kwargs))
        return made[-1]

    yield make
    for b in made:
        b.close()


def model_tip(tension: float, roll: float) -> tuple[float, float, float]:
    x, _, z = solve(DESIGN, tension).tip_position
    return rotate_z((float(x), 0.0, float(z)), roll)


def test_a_point_in_mocap_is_commanded_slewed_within_the_driver_limits(bench) -> None:
    b = bench()
    target = model_tip(10.0, 0.5)
    b.tension(0.0)
    b.target(target)
    tip = b.last("controller/target_tip")
    assert tip.header.frame_id == "tdcm_base"
    assert [tip.point.x, tip.point.y, tip.point.z] == pytest.approx(target, abs=1e-12)
    b.port.advance(0.05)
    assert b.last("tension_setpoint").data == pytest.approx(2.0)   # 40 N/s for 0.05 s
    assert b.last("roll_setpoint").data == pytest.approx(0.05)     # 1 rad/s
    b.port.advance(1.0)
    assert b.last("tension_setpoint").data == pytest.approx(10.0, abs=1e-6)
    assert b.last("roll_setpoint").data == pytest.approx(0.5)
    sent = len(b.port.messages("tension_setpoint"))
    b.port.advance(0.5)   # unchanged: sent again only every keepalive_s (1 s)
    assert len(b.port.messages("tension_setpoint")) <= sent + 1
    assert b.node.check().level == 1   # feedback without a measured tip: says it falls back
    assert "feed-forward with the last gain 1" in b.node.check().message


def test_a_late_tick_slews_for_the_time_it_missed_at_most_ten_periods(bench) -> None:
    """A tick 0.15 s after the last (two skipped on a loaded machine) slews 0.15 s worth, so
    the command keeps the driver's rates in time; after a 2 s stall, 10 periods' worth."""
    b = bench()
    b.tension(0.0)
    b.target(model_tip(10.0, 1.1))
    b.port.advance(0.05)
    assert b.last("roll_setpoint").data == pytest.approx(0.05)     # 1 rad/s for 0.05 s
    b.port.clock_ns += 150_000_000   # the next tick runs 0.15 s later
    b.node.step()
    assert b.last("tension_setpoint").data == pytest.approx(2.0 + 40.0 * 0.15)
    assert b.last("roll_setpoint").data == pytest.approx(0.05 + 0.15)
    b.port.clock_ns += 2_000_000_000  # a stall of 2 s
    b.node.step()
    assert b.last("roll_setpoint").data == pytest.approx(0.2 + 10 * 0.05)


def test_an_angle_keeps_the_current_roll(bench) -> None:
    b = bench()
    b.target(model_tip(8.0, -0.3))
    b.port.advance(1.0)
    angle = solve(DESIGN, 12.0).tip_angle_rad
    b.port.deliver("target_angle", from_dict("std_msgs/msg/Float64", {"data": angle}))
    b.port.advance(1.0)
    assert b.last("tension_setpoint").data == pytest.approx(12.0, abs=1e-6)
    assert b.last("roll_setpoint").data == pytest.approx(-0.3)


def test_bad_targets_are_refused_naming_value_and_range_and_the_old_one_stays(bench) -> None:
    b = bench()
    b.target(model_tip(6.0, 0.2))
    refusals = [
        ((math.nan, 0.0, 0.05), "tdcm_base", "target x = nan"),
        ((0.003, 0.0, 0.05), "camera", "frame 'camera' is in no TF edge \\(frames known: mocap, tdcm_base\\)"),
        (model_tip(6.0, 1.4), "mocap", r"target roll = 1.4.* allowed: \[-1.2, 1.2\] rad"),
        (model_tip(40.0, 0.0), "mocap", "reach"),
    ]
    for point, frame, reason in refusals:
        b.target(point, frame)
        assert b.node.counts["targets_refused"] >= 1
        assert pytest.approx(0.2) == b.node.core.target.plane.roll_rad
        assert re.search(reason, b.node.refusal), (reason, b.node.refusal)
        assert re.search(reason, b.node.check().message)
    assert b.node.counts["targets_refused"] == len(refusals)
    b.port.advance(1.0)
    assert b.last("tension_setpoint").data == pytest.approx(6.0, abs=1e-6)


def test_nothing_is_commanded_until_the_driver_limits_are_read(bench) -> None:
    b = bench(limits=False)
    assert "cannot read" in b.node.limits.problem  # the read at start failed
    b.target(model_tip(6.0, 0.0))
    b.port.advance(1.0)
    assert b.port.messages("tension_setpoint") == []
    status = b.node.check()
    assert status.level == 1
    assert "commanding nothing: driver limits unknown (cannot read /tension_driver's limits" \
        in status.message
    driver_parameters(b.port, {k: v for k, v in LIMITS.items() if k != "roll_rate"})
    b.port.advance(0.2)  # the next read, limits_period_s later
    assert "not all declared" in b.node.limits.problem
    assert b.node.limits.limits is None


def test_the_driver_limits_are_read_again_every_limits_period(bench) -> None:
    b = bench(limits=False)
    assert "cannot read" in b.node.limits.problem
    driver_parameters(b.port, LIMITS)
    b.port.advance(0.199)
    assert b.node.limits.limits is None  # no read before the retry is due
    b.port.advance(0.001)
    assert b.node.limits.limits is not None
    assert b.node.limits.limits.tension_max == 20.0 and b.node.limits.problem == ""
    driver_parameters(b.port, {**LIMITS, "tension_max": 12.0})
    b.port.advance(0.199)
    assert b.node.limits.limits.tension_max == 20.0
    b.port.advance(0.001)
    assert b.node.limits.limits.tension_max == 12.0
    b.close()
    driver_parameters(b.port, {**LIMITS, "tension_max": 9.0})
    b.port.advance(1.0)
    assert b.node.limits.limits.tension_max == 12.0  # closed: no more reads


@pytest.mark.parametrize("modulus_ratio", [1.3, 0.8])
def test_feedback_learns_the_gain_and_tracks_where_feedforward_does_not(bench, modulus_ratio
                                                                         ) -> None:
    rng = np.random.default_rng(3)
    errors = {}
    for mode in ("feedforward", "feedback"):
        b = bench(overrides={"mode": mode})
        target = model_tip(10.0, 0.4)
        b.target(target)
        b.follow(6.0, modulus_ratio, rng)
        measured = b.last("controller/measured_tip")
        error = b.last("controller/tracking_error").vector
        assert [error.x, error.y, error.z] == pytest.approx(
            np.subtract([measured.point.x, measured.point.y, measured.point.z], target))
        errors[mode] = math.dist([measured.point.x, measured.point.y, measured.point.z], target)
        gain, std = b.last("controller/gain").data, b.last("controller/gain_std").data
        if mode == "feedforward":
            assert (gain, std) == (1.0, 0.3)
        else:
            assert gain == pytest.approx(modulus_ratio, abs=4 * std + 1e-3)
            assert std < 0.03   # from the prior 0.3
            assert b.node.check().level == 0, b.node.check().message
    assert errors["feedforward"] > 0.3e-3 > errors["feedback"]


def test_back_in_feedforward_the_learned_gain_is_kept_frozen_and_commands(bench) -> None:
    rng = np.random.default_rng(6)
    b = bench(overrides={"mode": "feedback"})
    b.target(model_tip(10.0, 0.4))
    b.follow(4.0, 1.3, rng)
    estimator = b.node.core.estimator
    learned, std = estimator.gain, estimator.std
    assert learned == pytest.approx(1.3, abs=4 * std + 1e-3) and std < 0.03
    assert b.port.store.set({"mode": "feedforward"}).successful
    adapted = b.node.counts["adapted"]
    target = model_tip(7.0, -0.3)        # a new target, reached with the learned gain only
    b.target(target)
    b.follow(4.0, 1.3, rng)
    assert b.node.counts["adapted"] == adapted
    assert (estimator.gain, estimator.std) == (learned, std)
    assert b.last("controller/gain").data == learned
    measured = b.last("controller/measured_tip").point
    # feed-forward at the prior (g = 1) misses by more than 0.3 mm in this world (above)
    assert math.dist([measured.x, measured.y, measured.z], target) < 0.3e-3


def test_feedback_falls_back_without_markers_and_stops_adapting_when_released(bench) -> None:
    rng = np.random.default_rng(4)
    b = bench(overrides={"measurement_timeout_s": 0.3})
    b.target(model_tip(10.0, 0.0))
    b.follow(3.0, 1.3, rng)
    learned = b.node.core.estimator.gain
    b.follow(1.0, 1.3, rng, markers=False)
    status = b.node.check()
    assert status.level == 1 and "no measured tip for more than 0.3 s" in status.message
    assert b.last("tension_setpoint").data == pytest.approx(10.0 / learned, rel=1e-9)
    # a driver fault releases the tendon: markers of the straight body keep coming
    adapted = b.node.counts["adapted"]
    for _ in range(30):
        b.port.advance(0.05)
        b.tension(0.0)
        b.markers(0.0, 0.0, 1.3, rng)
    assert b.node.counts["adapted"] == adapted
    assert b.node.core.estimator.gain == learned
    assert "tendon released (0 N measured" in b.node.check().message
    assert b.last("tension_setpoint").data == pytest.approx(10.0 / learned, rel=1e-9)


def test_mode_is_writable_at_run_time_and_checked(bench) -> None:
    b = bench()
    assert b.port.store.set({"mode": "feedforward"}).successful
    assert b.port.get_parameter("mode") == "feedforward"
    refused = b.port.store.set({"mode": "open-loop"})
    assert not refused.successful and "mode" in refused.reason
    assert not b.port.store.set({"design.E": 1e9}).successful  # read-only


def test_a_tension_past_the_model_limits_is_counted_not_fatal(bench) -> None:
    rng = np.random.default_rng(5)
    b = bench()
    b.target(model_tip(8.0, 0.0))
    b.port.advance(0.1)
    b.tension(1e4)                       # a glitch past the tendon singularity
    b.markers(8.0, 0.0, 1.0, rng)
    assert b.node.counts["model_tendon_singularity"] == 1
    assert b.port.messages("controller/measured_tip") == []
    b.tension(8.0)
    b.markers(8.0, 0.0, 1.0, rng)
    assert len(b.port.messages("controller/measured_tip")) == 1


def test_a_marker_frame_late_from_the_mocap_meets_the_tension_of_its_own_stamp(bench) -> None:
    """Marker frames reach the controller 0.2 s after they were taken (a mocap pipeline on a
    loaded machine), while the tendon ramps between targets: paired with the newest tension,
    each frame showed the world's bend at an older, lower tension and the gain learned a world
    stiffer than it is (seen live: 1.20 for 1.11, and feedback tracked worse than feed-forward).
    Paired by stamp, the gain is the world's."""
    rng = np.random.default_rng(11)
    b = bench(overrides={"mode": "feedback"})
    for target_n in (6.0, 14.0, 8.0, 16.0, 7.0, 15.0) * 4:  # the tendon always on the move
        b.target(model_tip(target_n, 0.3))
        b.follow(0.3, 1.1, rng, lag_steps=4)  # frames 0.2 s late
    gain, std = b.last("controller/gain").data, b.last("controller/gain_std").data
    assert gain == pytest.approx(1.1, abs=4 * std + 2e-3), (gain, std)  # newest: 0.945


def test_a_marker_frame_waits_for_the_late_tension_of_its_own_stamp(bench) -> None:
    """The driver's tension and roll reach the controller 0.4 s after they were measured (a
    driver not scheduled on a loaded machine) while the marker frames come on time: paired with
    the newest tension the node had, each frame showed the world's bend at another tension
    (seen live: tensions 1.9 s old, the gain swinging 0.80-1.42 and ending at 1.27 for 1.106).
    Each frame waits for the tension of its stamp, so the gain is the world's."""
    rng = np.random.default_rng(12)
    b = bench(overrides={"mode": "feedback", "measurement_timeout_s": 1.0})
    b.tension(0.0)
    for target_n in (6.0, 14.0, 8.0, 16.0, 7.0, 15.0) * 4:  # the tendon always on the move
        b.target(model_tip(target_n, 0.3))
        b.follow(0.3, 1.1, rng, tension_lag_steps=8)  # tension and roll 0.4 s late
    gain, std = b.last("controller/gain").data, b.last("controller/gain_std").data
    assert gain == pytest.approx(1.1, abs=4 * std + 2e-3), (gain, std)
    assert b.node.counts["markers_tension_late"] == 0
    assert len(b.node.waiting) == 8  # the last 0.4 s of frames, their tension on its way


def test_a_marker_frame_whose_tension_never_comes_is_dropped_and_said(bench) -> None:
    rng = np.random.default_rng(13)
    b = bench(overrides={"mode": "feedback", "measurement_timeout_s": 0.5})
    b.target(model_tip(8.0, 0.0))
    b.tension(8.0)
    b.port.advance(0.1)
    b.markers(8.0, 0.0, 1.0, rng)  # newer than the only tension
    assert b.port.messages("controller/measured_tip") == []
    b.port.advance(0.3)
    b.tension(8.0, stamp_ns=b.port.clock_ns - 10**8)  # stamped at the frame: it is paired
    assert len(b.port.messages("controller/measured_tip")) == 1
    b.markers(8.0, 0.0, 1.0, rng)  # its tension never comes
    b.port.advance(0.45)
    assert b.node.counts["markers_tension_late"] == 0  # still within measurement_timeout_s
    b.port.advance(0.1)
    assert b.node.counts["markers_tension_late"] == 1 and not b.node.waiting
    assert len(b.port.messages("controller/measured_tip")) == 1
    status = b.node.check()
    assert "marker frames dropped: no tension stamped at or after them within 0.5 s" in (
        status.message), status.message
