"""metrics_node logic on an in-memory port, and the streaming form against the offline one."""

from __future__ import annotations

import json
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.metrics.evaluation import evaluate_series
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.streaming import RunningEvaluation
from tdcm_ros.metrics.synthetic import Recording, simulate
from tdcm_ros.model import MarkerLayout, preset, roll_points
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


def feed(port: MemoryPort, node: MetricsNode, rec: Recording, every_s: float = 0.5) -> None:
    """Deliver the recording in stamp order, running the update timer every ``every_s``."""
    tension, markers = rec.tension, rec.markers
    labels = markers.labels
    fi, next_update = 0, every_s
    for t, x in zip(tension.stamps_s, tension.tension_n, strict=True):
        port.clock_ns = round(t * 1e9)
        port.deliver("tension", from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": _hdr(t, "tdcm_tendon"), "wrench": {"force": {"z": float(x)}}}))
        while fi < markers.stamps_s.size and markers.stamps_s[fi] <= t:
            rows = markers.positions[fi]
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


def test_only_the_mocap_edge_into_the_base_is_the_registration(recording: Recording) -> None:
    """Mounted on a robot, /tf_static also holds tool0 -> tdcm_base: not a mocap registration,
    so it is counted and ignored (before, it was taken and the metrics were silently wrong);
    the frames are parameters."""
    port = metrics_port({"registration.source": "tf_static", "base_frame_id": "r1_base",
                         "mocap_frame_id": "vicon"})
    node = MetricsNode(port)
    for parent in ("tool0", "mocap"):
        port.deliver("/tf_static", _tf_static(parent, "r1_base", recording))
        assert (f"{parent!r} -> 'r1_base' is not the registration (parent 'vicon'"
                in node.running.problem)
    assert node.counts["tf_other_parent"] == 2 and node.counts["tf_static"] == 0
    port.deliver("/tf_static", _tf_static("vicon", "r1_base", recording))
    assert node.counts["tf_static"] == 1
    feed(port, node, recording)
    assert port.published["metrics/marker_errors"][0].header.frame_id == "r1_base"
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


def _rolled(rec: Recording, roll: float) -> Recording:
    """``rec`` with the body rolled by ``roll`` (rad) about tdcm_base z: markers turned in base."""
    base = rec.registration.to_base(rec.markers.positions.reshape(-1, 3))
    turned = rec.registration.to_mocap(roll_points(base, roll))
    markers = replace(rec.markers, positions=turned.reshape(rec.markers.positions.shape))
    return replace(rec, markers=markers)


@pytest.mark.parametrize("roll_sent", [True, False])
def test_marker_errors_compare_at_the_measured_roll(recording: Recording, roll_sent: bool
                                                    ) -> None:
    """The body rolled by 0.8 rad: with the roll on joint_states the per-frame errors stay at
    the noise level; without it (the model at roll 0) they are millimetres."""
    roll = 0.8
    rec = _rolled(recording, roll)
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
    if roll_sent:
        assert np.median(sizes) < 3e-4
        assert node.counts["roll"] == 1 and node.counts["roll_non_finite"] == 1
    else:
        assert np.median(sizes) > 2e-3
