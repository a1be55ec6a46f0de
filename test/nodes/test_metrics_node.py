"""metrics_node logic on an in-memory port, and the streaming form against the offline one."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.metrics.evaluation import evaluate_series
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.series import RollSeries
from tdcm_ros.metrics.streaming import RunningEvaluation
from tdcm_ros.metrics.synthetic import Recording, rolled, simulate
from tdcm_ros.model import MarkerLayout, preset
from tdcm_ros.nodes.metrics_node import MetricsNode
from tdcm_ros.runtime.memory_port import MemoryPort

DESIGN = preset("paper-experiment").with_overrides(E=0.7e9)


def metrics_port(overrides: dict[str, Any] | None = None) -> MemoryPort:
    """An in-memory port of metrics_node on the simulated robot's modulus, clock at 0."""
    return MemoryPort({"design.E": DESIGN.E, **(overrides or {})}, name="metrics_node",
                      start_ns=0)


def _hdr(stamp_s: float, frame: str) -> dict[str, Any]:
    ns = round(stamp_s * 1e9)
    return {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": frame}


def feed(port: MemoryPort, node: MetricsNode, rec: Recording, every_s: float = 0.5, *,
         before_frame: Callable[[float], None] | None = None) -> None:
    """Deliver the recording in stamp order, running the update timer every ``every_s``;
    ``before_frame(stamp_s)`` runs before each marker frame is delivered."""
    tension, markers = rec.tension, rec.markers
    labels = markers.labels
    fi, next_update = 0, every_s
    for t, x in zip(tension.stamps_s, tension.tension_n, strict=True):
        port.clock_ns = round(t * 1e9)
        port.deliver("tension", from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": _hdr(t, "tdcm_tendon"), "wrench": {"force": {"z": float(x)}}}))
        while fi < markers.stamps_s.size and markers.stamps_s[fi] <= t:
            rows = markers.positions[fi]
            if before_frame is not None:
                before_frame(float(markers.stamps_s[fi]))
            port.deliver("markers", from_dict("mocap4r2_msgs/msg/Markers", {
                "header": _hdr(markers.stamps_s[fi], "mocap"), "frame_number": fi,
                "markers": [{"marker_name": labels[i], "marker_index": i,
                             "translation": {"x": r[0], "y": r[1], "z": r[2]}}
                            for i, r in enumerate(rows.tolist()) if not np.isnan(r[0])]}))
            fi += 1
        if t >= next_update:
            node.update()
            next_update += every_s


@pytest.fixture(scope="module")
def recording() -> Recording:
    return simulate(DESIGN, levels=(0.0, 6.0, 12.0), hold_s=2.5, trials=2, tension_hz=200.0,
                    mocap_hz=50.0, occlusion=0.1, seed=5)


def test_streaming_matches_the_offline_evaluation(recording: Recording) -> None:
    opts = EvaluateOptions(design=DESIGN)
    offline = evaluate_series(recording.tension, recording.markers, opts)
    running = RunningEvaluation(opts)
    frames = iter(range(recording.markers.stamps_s.size))
    fi = next(frames)
    for t, x in zip(recording.tension.stamps_s, recording.tension.tension_n, strict=True):
        running.add_tension(t, x)
        while fi is not None and recording.markers.stamps_s[fi] <= t:
            running.add_markers(recording.markers.stamps_s[fi], recording.markers.positions[fi])
            fi = next(frames, None)
        if round(t * 200) % 100 == 0:
            running.update()
    running.update()
    # the stream ends inside the final zero hold, which never finishes
    assert len(running.records) == len(offline.records) - 1
    for live, off in zip(running.records, offline.records, strict=False):
        assert (live.trial, live.tension_n) == (off.trial, off.tension_n)
        assert live.measured_deflection_m == pytest.approx(off.measured_deflection_m, abs=1e-12)


def test_node_publishes_errors_and_the_running_table(recording: Recording) -> None:
    port = metrics_port()
    node = MetricsNode(port)
    port.deliver("/tf_static", from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
        "header": _hdr(0.0, "mocap"), "child_frame_id": "tdcm_base",
        "transform": {"translation": dict(zip("xyz", recording.registration.translation,
                                              strict=True)),
                      "rotation": dict(zip("xyzw", recording.registration.quaternion,
                                           strict=True))}}]}))
    feed(port, node, recording)
    errors = port.published["metrics/marker_errors"]
    assert len(errors) > 0.9 * recording.markers.stamps_s.size
    sizes = [np.linalg.norm([m.translation.x, m.translation.y, m.translation.z])
             for msg in errors for m in msg.markers]
    # true model + 0.05 mm marker noise; the tension lags the command by 0.1 s, so frames in
    # the ramps see up to one step of model error: the median stays at the noise level
    assert np.median(sizes) < 3e-4
    assert errors[0].header.frame_id == "tdcm_base"
    assert len(port.published["metrics/tip_error"]) > 0
    table = json.loads(port.published["metrics/table"][-1].data)
    assert table["n_steps"] == 6 and table["n_trials"] == 2
    assert table["rmse_m"] < 2e-5
    assert port.published["metrics/rmse_m"][-1].data == pytest.approx(table["rmse_m"])
    node.diagnostics.publish()
    status = port.published["/diagnostics"][-1].status[0]
    assert status.level == 0 and status.message == "ok"
    values = {kv.key: kv.value for kv in status.values}
    assert values["registration"] == "tf_static"


def _tf_static(parent: str, child: str, rec: Recording) -> Any:
    return from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
        "header": _hdr(0.0, parent), "child_frame_id": child,
        "transform": {"translation": dict(zip("xyz", rec.registration.translation, strict=True)),
                      "rotation": dict(zip("xyzw", rec.registration.quaternion, strict=True))}}]})


def _tf(stamp_s: float, parent: str, child: str, translation: Any, quaternion: Any) -> Any:
    return from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
        "header": _hdr(stamp_s, parent), "child_frame_id": child,
        "transform": {"translation": dict(zip("xyz", map(float, translation), strict=True)),
                      "rotation": dict(zip("xyzw", map(float, quaternion), strict=True))}}]})


def _pose(translation: Any, axis: Any, angle: float) -> np.ndarray:
    """4x4 pose: a rotation by ``angle`` about the unit ``axis`` (Rodrigues), then a shift."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + math.sin(angle) * cross + (1 - math.cos(angle)) * cross @ cross
    m[:3, 3] = translation
    return m


def _quaternion(axis: Any, angle: float) -> tuple[float, ...]:
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return (*(math.sin(angle / 2) * k), math.cos(angle / 2))


#: A bench mounted on a robot: mocap -> world and tool0 -> r1_base static, world -> tool0 a
#: rotation about ARM_AXIS by ARM_ANGLE(t) plus ARM_SHIFT(t), sampled on /tf every TF_PERIOD_S.
WORLD = ((0.3, -1.0, 0.2), (0.2, 0.1, 1.0), 0.7)
MOUNT = ((0.0, 0.05, 0.12), (1.0, 0.0, 0.0), math.pi)
ARM_AXIS = (0.3, 1.0, -0.2)
TF_PERIOD_S = 0.01


def _arm(t: float) -> tuple[np.ndarray, float]:
    return np.array([0.4 + 0.1 * math.sin(t), 0.2 * math.cos(0.7 * t), 0.5]), 0.6 * math.sin(0.4 * t)


def _moved(rows: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Points (k, 3) m moved by a 4x4 pose."""
    return rows @ pose[:3, :3].T + pose[:3, 3]


def _mounted(rec: Recording) -> Recording:
    """The recording's markers as a bench on the moving arm sees them in ``mocap``: each frame
    moved from the base by mocap<-world<-tool0(t)<-base, tool0(t) interpolated between the /tf
    samples as the angle and the shift, linearly (a rotation about one axis: its slerp)."""
    reg = rec.registration
    base_rows = [reg.to_base(rows) for rows in rec.markers.positions]
    world, mount = _pose(*WORLD), _pose(*MOUNT)
    moved = []
    for t, rows in zip(rec.markers.stamps_s, base_rows, strict=True):
        k = math.floor(t / TF_PERIOD_S + 1e-9)
        (s0, a0), (s1, a1) = _arm(k * TF_PERIOD_S), _arm((k + 1) * TF_PERIOD_S)
        f = t / TF_PERIOD_S - k
        arm = _pose(s0 + f * (s1 - s0), ARM_AXIS, a0 + f * (a1 - a0))
        moved.append(_moved(rows, world @ arm @ mount))
    return replace(rec, markers=replace(rec.markers, positions=np.asarray(moved)))


def _deliver_arm(port: MemoryPort, sent: list[float], until_s: float) -> None:
    """The arm's /tf samples up to one past ``until_s`` (s)."""
    while not sent or sent[-1] < until_s:
        t = len(sent) * TF_PERIOD_S
        shift, angle = _arm(t)
        port.deliver("/tf", _tf(t, "world", "tool0", shift, _quaternion(ARM_AXIS, angle)))
        sent.append(t)


def _mount_statics(port: MemoryPort) -> None:
    port.deliver("/tf_static", _tf(0.0, "vicon", "world", WORLD[0],
                                   _quaternion(WORLD[1], WORLD[2])))
    port.deliver("/tf_static", _tf(0.0, "tool0", "r1_base", MOUNT[0],
                                   _quaternion(MOUNT[1], MOUNT[2])))


def _between(rec: Recording, start_s: float, stop_s: float) -> Recording:
    """The part of a recording stamped in [start_s, stop_s) s."""
    t, m = rec.tension.stamps_s, rec.markers.stamps_s
    keep, frames = (t >= start_s) & (t < stop_s), (m >= start_s) & (m < stop_s)
    return replace(rec, tension=replace(rec.tension, stamps_s=t[keep],
                                        tension_n=rec.tension.tension_n[keep]),
                   markers=replace(rec.markers, stamps_s=m[frames],
                                   positions=rec.markers.positions[frames]))


def _run_fixed_and_mounted(recording: Recording, overrides: dict[str, Any]
                           ) -> tuple[MemoryPort, MemoryPort, MetricsNode]:
    frames = {"base_frame_id": "r1_base", "mocap_frame_id": "vicon", **overrides}
    fixed = metrics_port(frames)
    fixed_node = MetricsNode(fixed)
    fixed.deliver("/tf_static", _tf(0.0, "vicon", "r1_base", recording.registration.translation,
                                    recording.registration.quaternion))
    feed(fixed, fixed_node, recording)
    mounted = metrics_port(frames)
    node = MetricsNode(mounted)
    _mount_statics(mounted)
    sent: list[float] = []
    feed(mounted, node, _mounted(recording),
         before_frame=lambda stamp: _deliver_arm(mounted, sent, stamp))
    return fixed, mounted, node


@pytest.mark.parametrize("source", ["tf", "auto"])
def test_a_bench_on_a_moving_robot_scores_as_a_fixed_one(recording: Recording,
                                                         source: str) -> None:
    """Issue 29: mounted under a moving tool frame (vicon -> world -> tool0(t) -> r1_base), each
    marker frame is placed by TF at its stamp, and every error and Table I figure equals the
    fixed bench's (which the steps average in mocap, the mounted one in the base)."""
    fixed, mounted, node = _run_fixed_and_mounted(recording, {"registration.source": source})
    assert node.moving and node.counts["frames_without_transform"] == 0
    got, want = (port.published["metrics/marker_errors"] for port in (mounted, fixed))
    assert len(got) == len(want) > 0.9 * recording.markers.stamps_s.size
    for a, b in zip(got, want, strict=True):
        assert [m.marker_name for m in a.markers] == [m.marker_name for m in b.markers]
        assert a.header.frame_id == "r1_base"
        np.testing.assert_allclose([[m.translation.x, m.translation.y, m.translation.z]
                                    for m in a.markers],
                                   [[m.translation.x, m.translation.y, m.translation.z]
                                    for m in b.markers], atol=1e-12)
    moving, still = (json.loads(port.published["metrics/table"][-1].data)
                     for port in (mounted, fixed))
    assert moving["n_steps"] == still["n_steps"] == 6
    for key in ("rmse_m", "mae_m", "mape_pct", "shape_error_m"):
        assert moving[key] == pytest.approx(still[key], rel=1e-9, abs=1e-15), key
    assert moving["details"]["sources"][0]["registration"]["method"] == "tf"
    assert still["details"]["sources"][0]["registration"]["method"] == "tf_static"


def test_a_frame_waits_for_late_tf_and_one_tf_never_covers_is_counted(
        recording: Recording) -> None:
    """/tf lagging 0.3 s behind the markers: each frame waits (tf.wait_s 1 s) and is scored;
    after /tf stops, frames wait 1 s of node time, then are counted and not scored."""
    port = metrics_port({"base_frame_id": "r1_base", "mocap_frame_id": "vicon",
                         "registration.source": "tf"})
    node = MetricsNode(port)
    _mount_statics(port)
    sent: list[float] = []
    stop_s = 10.0
    mounted = _mounted(recording)
    feed(port, node, mounted, before_frame=lambda stamp: _deliver_arm(
        port, sent, min(stamp - 0.3, stop_s)) if stamp > 0.3 else None)
    after = mounted.markers.stamps_s > stop_s
    last_s = float(recording.tension.stamps_s[-1])
    # frames stamped in (stop_s, last_s - wait] waited their second and were dropped; the rest
    # still wait at the end of the stream
    dropped = int(np.count_nonzero(after & (mounted.markers.stamps_s < last_s - 1.0)))
    assert node.counts["frames_without_transform"] == pytest.approx(dropped, abs=1)
    assert "after the last sample" in node.tf_problem
    errors = port.published["metrics/marker_errors"]
    assert max(m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in errors) <= stop_s
    assert len(errors) > 0.9 * np.count_nonzero(~after)


def test_a_static_path_that_starts_moving_restarts_the_markers_and_keeps_the_tension(
        recording: Recording) -> None:
    """Steps scored by one static registration, then the arm starts moving on /tf: the frames
    change frame, so the finished steps go (counted, ``restarts``) and the evaluation goes on
    in the base; the tension samples stay."""
    port = metrics_port({"base_frame_id": "r1_base", "mocap_frame_id": "vicon",
                         "registration.source": "tf"})
    node = MetricsNode(port)
    _mount_statics(port)
    shift, angle = _arm(0.0)
    port.deliver("/tf_static", _tf(0.0, "world", "tool0", shift, _quaternion(ARM_AXIS, angle)))
    held = _pose(*WORLD) @ _pose(shift, ARM_AXIS, angle) @ _pose(*MOUNT)
    still = _between(recording, 0.0, 8.0)
    still = replace(still, markers=replace(still.markers, positions=np.asarray(
        [_moved(recording.registration.to_base(rows), held)
         for rows in still.markers.positions])))
    feed(port, node, still)
    before = json.loads(port.published["metrics/table"][-1].data)
    assert not node.moving and before["n_steps"] >= 2
    assert before["details"]["sources"][0]["registration"]["method"] == "tf_static"
    sent: list[float] = [t * TF_PERIOD_S for t in range(round(8.0 / TF_PERIOD_S))]
    feed(port, node, _between(_mounted(recording), 8.0, np.inf),
         before_frame=lambda stamp: _deliver_arm(port, sent, stamp))
    assert node.moving and node.counts["restarts"] == 1
    after = json.loads(port.published["metrics/table"][-1].data)
    assert after["details"]["sources"][0]["registration"]["method"] == "tf"
    assert 1 <= after["n_steps"] < 6 and after["rmse_m"] < 2e-5


def test_a_base_under_a_tool_frame_waits_for_the_path_to_mocap(recording: Recording) -> None:
    """Mounted on a robot, /tf_static holds tool0 -> r1_base: with no path from tool0 to the
    mocap frame the frames cannot be placed; the problem says so, the frames are counted and
    not scored, until the path arrives."""
    port = metrics_port({"registration.source": "tf_static", "base_frame_id": "r1_base",
                         "mocap_frame_id": "vicon"})
    node = MetricsNode(port)
    assert "/tf" not in port.subscriptions
    port.deliver("/tf_static", _tf(0.0, "tool0", "r1_base", MOUNT[0],
                                   _quaternion(MOUNT[1], MOUNT[2])))
    feed(port, node, _between(recording, 0.0, 2.0))
    assert node.counts["frames_without_transform"] > 0
    assert "metrics/marker_errors" not in port.published
    node.diagnostics.publish()
    status = port.published["/diagnostics"][-1].status[0]
    assert "no registration yet (waiting for TF vicon -> r1_base" in status.message
    assert "not placed by TF: frame 'vicon' is in no TF edge" in status.message
    # the direct registration replaces tool0 as r1_base's parent: frames are placed again
    port.deliver("/tf_static", _tf(0.0, "vicon", "r1_base", recording.registration.translation,
                                   recording.registration.quaternion))
    feed(port, node, _between(recording, 2.0, np.inf))
    assert node.tf_problem == ""
    # the first 2 s are the first zero hold: its frames were lost, its tension was not
    assert json.loads(port.published["metrics/table"][-1].data)["n_steps"] == 6


def test_node_estimates_the_registration_without_tf(recording: Recording) -> None:
    port = metrics_port({"registration.source": "estimate"})
    node = MetricsNode(port)
    assert "/tf_static" not in port.subscriptions
    feed(port, node, recording)
    table = json.loads(port.published["metrics/table"][-1].data)
    assert table["details"]["sources"][0]["registration"]["method"] == "estimated"
    assert table["rmse_m"] < 5e-5


def test_stale_inputs_and_no_registration_warn() -> None:
    port = metrics_port({"registration.source": "tf_static", "stale_s": 0.5})
    node = MetricsNode(port)
    port.clock_ns = 10**10
    node.diagnostics.publish()
    status = port.published["/diagnostics"][-1].status[0]
    assert status.level == 1
    assert "no tension for more than 0.5 s" in status.message
    assert "no markers" in status.message and "no registration" in status.message


@pytest.mark.parametrize(("name", "value", "match"), [
    ("steps.tolerance_n", -1.0, "steps.tolerance_n"),
    ("align.tolerance_s", 20.0, "align.tolerance_s"),
    ("registration.source", "guess", "registration.source"),
    ("markers.arc_lengths", [0.01, 0.2, 0.5], "markers.arc_lengths"),
    ("deflection_axis", "tip", "deflection_axis"),
    ("registration.rotation", [0.0, 0.0, 0.0, 0.0], "quaternion"),
])
def test_bad_parameters_are_rejected(name: str, value: Any, match: str) -> None:
    overrides = {name: value}
    if name == "registration.rotation":
        overrides["registration.source"] = "parameter"
    with pytest.raises(InputError, match=match):
        MetricsNode(metrics_port(overrides))


def test_node_maps_other_labels_and_midline_markers() -> None:
    """A lab's Vicon names and virtual midline markers: ``markers.labels`` and
    ``markers.radial_offset`` (default: on the surface, R_outer + ball radius)."""
    assert MetricsNode(metrics_port()).options.layout.radius(DESIGN.R_outer) == pytest.approx(
        DESIGN.R_outer + 0.001)
    labels = ("tdcm:M15", "tdcm:M33", "tdcm:M53")
    rec = simulate(DESIGN, layout=MarkerLayout(labels=labels, radial_offset=0.0),
                   levels=(0.0, 6.0, 12.0), hold_s=2.5, trials=1, tension_hz=200.0,
                   mocap_hz=50.0, seed=6)
    port = metrics_port({"markers.labels": list(labels), "markers.radial_offset": 0.0,
                         "registration.source": "parameter",
                         "registration.translation": list(rec.registration.translation),
                         "registration.rotation": list(rec.registration.quaternion)})
    node = MetricsNode(port)
    feed(port, node, rec)
    table = json.loads(port.published["metrics/table"][-1].data)
    assert table["n_steps"] == 3 and table["rmse_m"] < 2e-5


@pytest.mark.parametrize("roll_sent", [True, False])
def test_marker_errors_compare_at_the_measured_roll(recording: Recording, roll_sent: bool
                                                    ) -> None:
    """The body rolled by 0.8 rad: with the roll on joint_states the per-frame errors and the
    running Table I (steps scored in the rolled bending plane) stay at the noise level;
    without it (the model at roll 0) they are millimetres."""
    roll = 0.8
    rec = rolled(recording, RollSeries.of([0.0], [roll]))
    port = metrics_port({"registration.source": "parameter",
                         "registration.translation": list(rec.registration.translation),
                         "registration.rotation": list(rec.registration.quaternion)})
    node = MetricsNode(port)
    if roll_sent:
        port.deliver("joint_states", from_dict("sensor_msgs/msg/JointState", {
            "header": _hdr(0.0, ""), "name": ["roll"], "position": [roll]}))
        port.deliver("joint_states", from_dict("sensor_msgs/msg/JointState", {
            "header": _hdr(0.5, ""), "name": ["roll"], "position": [float("nan")]}))
    feed(port, node, rec)
    sizes = [np.linalg.norm([m.translation.x, m.translation.y, m.translation.z])
             for msg in port.published["metrics/marker_errors"] for m in msg.markers]
    assert len(sizes) > 0.9 * rec.markers.stamps_s.size
    table = json.loads(port.published["metrics/table"][-1].data)
    if roll_sent:
        assert np.median(sizes) < 3e-4 and table["rmse_m"] < 2e-5
        assert node.counts["roll"] == 1 and node.counts["roll_non_finite"] == 1
    else:
        assert np.median(sizes) > 2e-3 and table["rmse_m"] > 5e-4
