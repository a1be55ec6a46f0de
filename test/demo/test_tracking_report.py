"""The tracking report on a synthetic bag written with the package's bag writer: errors whose
RMSE and maximum are known by construction, per phase, with the settle spans left out."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from tdcm_ros.bagio import BagError, from_dict, serialize
from tdcm_ros.bagio.writer import BagWriter
from tdcm_ros.demo import tracking_report
from tdcm_ros.demo.tracking_report import (
    GAIN_TOPIC,
    LAP_TOPIC,
    MEASURED_TOPIC,
    PREDICTED_TOPIC,
    TARGET_TOPIC,
    phase_errors,
    read_tracking,
)
from tdcm_ros.scenes.trajectory import (
    FEEDBACK,
    FEEDFORWARD,
    FEEDFORWARD_LEARNED,
    CircleTrajectory,
    parse_trajectory,
)

CIRCLE = parse_trajectory({"centre_m": [0.009, 0.0], "radius_m": 0.003, "period_s": 4.0,
                           "approach_s": 1.0, "feedforward_laps": 1, "feedback_laps": 2,
                           "settle_s": 2.0, "rate_hz": 20.0})
#: The same circle ending with a lap of feed-forward with the learned gain (13-17 s).
LEARNED = parse_trajectory({**CIRCLE.to_dict(), "learned_feedforward_laps": 1})
EPOCH_NS = 1_700_000_000 * 10**9
Z = 0.05
#: error of the measured tip (m) by lap inside its phase's settle span, and by phase after it
#: (alternating)
SETTLING = {0: 0.010, 1: 0.005, 2: 0.003, 3: 0.003, 4: 0.004}
FF_AFTER = (0.001, 0.002)   # RMSE sqrt((1 + 4) / 2) mm, max 2 mm
FB_AFTER = (0.0001, 0.0001)
LEARNED_AFTER = (0.0003, 0.0004)   # RMSE sqrt((0.09 + 0.16) / 2) mm, max 0.4 mm
AFTER = {FEEDFORWARD: FF_AFTER, FEEDBACK: FB_AFTER, FEEDFORWARD_LEARNED: LEARNED_AFTER}
PREDICTED_OFFSET = 0.0005


def _point(stamp_ns: int, xyz: tuple[float, float, float], frame: str = "tdcm_base") -> bytes:
    return serialize(from_dict("geometry_msgs/msg/PointStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9},
                   "frame_id": frame},
        "point": {"x": xyz[0], "y": xyz[1], "z": xyz[2]}}))


def _target(t: float) -> tuple[float, float, float]:
    x, y = CIRCLE.xy(t)
    return x, y, Z


def _published_target(ms: int) -> tuple[float, float, float]:
    """The target at ``ms`` as the report sees it: linear between the 20 Hz targets."""
    before = ms - ms % 50
    share = (ms - before) / 50
    a, b = np.array(_target(before / 1000)), np.array(_target((before + 50) / 1000))
    x, y, z = (1 - share) * a + share * b
    return float(x), float(y), float(z)


def _measured_error(circle: CircleTrajectory, t: float, index: int) -> float:
    lap = circle.lap_at(t)
    phase = circle.phase_of_lap(lap)
    phase_start = circle.approach + (circle.lap_phases.index(phase) * circle.period if lap else 0)
    if lap == 0 or t < phase_start + circle.settle:
        return SETTLING[lap]
    return AFTER[phase][index % 2]


def write_bag(path: Path, *, frame: str = "tdcm_base", skip: str = "",
              circle: CircleTrajectory = CIRCLE) -> None:
    """Targets at 20 Hz with their laps, measured tips at 100 Hz (error along the radial
    direction, sizes above), predicted tips 0.5 mm off the target along z."""
    end_ms = int(circle.duration * 1000)
    with BagWriter(path) as bag:
        for topic, kind in ((TARGET_TOPIC, "geometry_msgs/msg/PointStamped"),
                            (LAP_TOPIC, "std_msgs/msg/Int32"),
                            (MEASURED_TOPIC, "geometry_msgs/msg/PointStamped"),
                            (PREDICTED_TOPIC, "geometry_msgs/msg/PointStamped"),
                            (GAIN_TOPIC, "std_msgs/msg/Float64")):
            if topic != skip:
                bag.add_topic("/" + topic, kind)
        for ms in range(0, end_ms + 1, 10):
            t = ms / 1000
            stamp = EPOCH_NS + ms * 10**6
            if ms % 50 == 0 and ms < end_ms:
                bag.write("/" + TARGET_TOPIC, stamp + 10**6, _point(stamp, _target(t), frame))
                bag.write("/" + LAP_TOPIC, stamp + 10**6, serialize(from_dict(
                    "std_msgs/msg/Int32", {"data": circle.lap_at(t)})))
                bag.write("/" + GAIN_TOPIC, stamp + 10**6, serialize(from_dict(
                    "std_msgs/msg/Float64", {"data": 1.0 + t / 100})))
            x, y, z = _published_target(ms)
            radial = math.atan2(y, x)
            size = _measured_error(circle, t, ms // 10)
            measured = (x + size * math.cos(radial), y + size * math.sin(radial), z)
            bag.write("/" + MEASURED_TOPIC, stamp + 5 * 10**6, _point(stamp, measured))
            if skip != PREDICTED_TOPIC:
                bag.write("/" + PREDICTED_TOPIC, stamp + 5 * 10**6,
                          _point(stamp, (x, y, z + PREDICTED_OFFSET)))


def test_each_phase_error_is_the_one_built_into_the_bag(tmp_path: Path) -> None:
    write_bag(tmp_path / "bag")
    errors = {e.mode: e for e in phase_errors(read_tracking(tmp_path / "bag"), CIRCLE)}
    assert list(errors) == [FEEDFORWARD, FEEDBACK]
    ff, fb = errors[FEEDFORWARD], errors[FEEDBACK]
    assert ff.laps == (1,) and fb.laps == (2, 3)
    assert ff.rmse_m == pytest.approx(math.sqrt((1 + 4) / 2) * 1e-3, rel=1e-6)
    assert ff.max_m == pytest.approx(2e-3, rel=1e-6)
    assert fb.rmse_m == pytest.approx(1e-4, rel=1e-6) and fb.max_m == pytest.approx(1e-4, rel=1e-6)
    # the settle spans (5 mm and 3 mm errors) and the approach (10 mm) are left out
    assert ff.start_s == pytest.approx(1.0, abs=2e-3) and fb.start_s == pytest.approx(5.0, abs=2e-3)
    assert ff.window_s[0] >= 3.0 - 1e-9 and fb.window_s[0] >= 7.0 - 1e-9
    # 100 Hz: ff 3.00-4.99 s; fb 7.00 s to the last target, 12.95 s (none is extrapolated)
    assert (ff.samples, fb.samples) == (200, 596)
    assert fb.window_s == pytest.approx((7.0, 12.95))
    assert ff.predicted_rmse_m == pytest.approx(PREDICTED_OFFSET, rel=1e-6)
    # the measured tips sit radially off, the predicted ones along z: perpendicular errors
    assert ff.model_rmse_m == pytest.approx(math.hypot(PREDICTED_OFFSET, ff.rmse_m), rel=1e-6)


def test_the_learned_feed_forward_laps_are_a_phase_of_their_own(tmp_path: Path) -> None:
    write_bag(tmp_path / "bag", circle=LEARNED)
    errors = {e.phase: e for e in phase_errors(read_tracking(tmp_path / "bag"), LEARNED)}
    assert list(errors) == [FEEDFORWARD, FEEDBACK, FEEDFORWARD_LEARNED]
    ff, fb, learned = errors[FEEDFORWARD], errors[FEEDBACK], errors[FEEDFORWARD_LEARNED]
    assert [e.mode for e in errors.values()] == [FEEDFORWARD, FEEDBACK, FEEDFORWARD]
    assert (ff.laps, fb.laps, learned.laps) == ((1,), (2, 3), (4,))
    # the first two phases are as without the learned lap: the feedback phase now ends at 13 s
    assert ff.rmse_m == pytest.approx(math.sqrt((1 + 4) / 2) * 1e-3, rel=1e-6)
    assert ff.samples == 200
    assert fb.rmse_m == pytest.approx(1e-4, rel=1e-6) and fb.max_m == pytest.approx(1e-4, rel=1e-6)
    assert fb.window_s == pytest.approx((7.0, 12.99)) and fb.samples == 600
    # the learned lap: its settle span (4 mm) left out, 15.00 s to the last target, 16.95 s
    assert learned.rmse_m == pytest.approx(math.sqrt((0.09 + 0.16) / 2) * 1e-3, rel=1e-6)
    assert learned.max_m == pytest.approx(0.4e-3, rel=1e-6)
    assert learned.start_s == pytest.approx(13.0, abs=2e-3)
    assert learned.window_s == pytest.approx((15.0, 16.95)) and learned.samples == 196
    assert learned.mean_m[2] == pytest.approx(0.0, abs=1e-12)   # radial errors: none along z
    assert learned.predicted_rmse_m == pytest.approx(PREDICTED_OFFSET, rel=1e-6)
    assert learned.to_json()["phase"] == FEEDFORWARD_LEARNED
    assert learned.to_json()["mode"] == FEEDFORWARD


def test_the_report_writes_the_learned_phase_beside_the_others(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("matplotlib")
    write_bag(tmp_path / "bag", circle=LEARNED)
    results = tracking_report(tmp_path / "bag", LEARNED, tmp_path, "synthetic", world_gain=1.1)
    written = json.loads((tmp_path / "metrics.json").read_text())
    assert written == json.loads(json.dumps(results))
    assert list(written["tracking"]) == [FEEDFORWARD, FEEDBACK, FEEDFORWARD_LEARNED]
    assert written["tracking"][FEEDFORWARD_LEARNED]["rmse_m"] == pytest.approx(0.35355e-3,
                                                                               rel=1e-4)
    assert written["trajectory"]["learned_feedforward_laps"] == 1
    out = capsys.readouterr().out
    assert "feedforward_learned" in out and "0.354 mm" in out and "0.400 mm" in out
    for name in ("tracking_paths.png", "tracking_error.png"):
        assert (tmp_path / "plots" / name).stat().st_size > 0


def test_the_report_writes_what_it_computed_from_the_bag(tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    pytest.importorskip("matplotlib")
    write_bag(tmp_path / "bag")
    results = tracking_report(tmp_path / "bag", CIRCLE, tmp_path, "synthetic", world_gain=1.1)
    written = json.loads((tmp_path / "metrics.json").read_text())
    assert written == json.loads(json.dumps(results))
    assert written["tracking"][FEEDFORWARD]["rmse_m"] == pytest.approx(1.5811e-3, rel=1e-4)
    assert written["final_gain"] == pytest.approx(1.0 + 12.95 / 100)
    assert written["world_gain"] == 1.1
    out = capsys.readouterr().out
    assert "feedforward" in out and "1.581 mm" in out and "0.100 mm" in out
    assert "controller gain at the end: 1.1295 (the scene's E_model / E_world: 1.1000)" in out
    for name in ("tracking_paths.png", "tracking_error.png"):
        assert (tmp_path / "plots" / name).stat().st_size > 0


def test_a_missing_topic_or_a_foreign_frame_is_named(tmp_path: Path) -> None:
    write_bag(tmp_path / "no_predicted", skip=PREDICTED_TOPIC)
    with pytest.raises(BagError, match="controller/predicted_tip"):
        read_tracking(tmp_path / "no_predicted")
    write_bag(tmp_path / "mocap", frame="mocap")
    with pytest.raises(BagError, match="'mocap'.*tdcm_base"):
        read_tracking(tmp_path / "mocap")


def test_a_phase_without_samples_after_its_settle_time_is_an_error(tmp_path: Path) -> None:
    write_bag(tmp_path / "bag")
    record = read_tracking(tmp_path / "bag")
    # read as 2 feed-forward laps then 2 feedback: feedback starts with lap 3 (9 s), and the
    # bag ends before its 7.5 s settle time is over
    late = parse_trajectory({**CIRCLE.to_dict(), "feedforward_laps": 2, "settle_s": 7.5})
    with pytest.raises(BagError, match="feedback phase has no measured tip after its first 7.5 s"):
        phase_errors(record, late)
    # a bag that ends before any feedback lap (a run stopped early) reports feed-forward only
    short = parse_trajectory({**CIRCLE.to_dict(), "feedforward_laps": 3, "settle_s": 2.0})
    assert [e.mode for e in phase_errors(record, short)] == [FEEDFORWARD]
    assert np.all(record.lap_index >= 0)
