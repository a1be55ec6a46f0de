"""Table I at a roll (issue 33): steps are scored in their rolled bending plane, from arrays,
bags and in calibration; at roll 0 nothing changes."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import cast

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.cli.main import main
from tdcm_ros.metrics.api import Topics, calibrate_paths, evaluate_paths
from tdcm_ros.metrics.bagdata import load_bag
from tdcm_ros.metrics.errors import MetricsError
from tdcm_ros.metrics.evaluation import Evaluation, evaluate_series
from tdcm_ros.metrics.options import EvaluateOptions, options_from_sets
from tdcm_ros.metrics.series import RollSeries
from tdcm_ros.metrics.synthetic import Recording, rolled
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import InvalidRollError
from test.metrics.metrics_samples import DESIGN, TRUE_E, rotation_angle, small_recording

OPTS = EvaluateOptions(design=DESIGN)
#: 2 trials of 0, 8, 16 N held 2 s each (0-6 s, 6-12 s), back to 0 N at 12-14 s.
REC = cast(Recording, small_recording())
ROLL = 0.6  #: rad
#: The roll turns from 0 to ROLL at 6 s, as trial 2 starts: between two holds (the zero hold
#: starting there drops its first settle_s).
TURNING = RollSeries.of([0.0, 6.0], [0.0, ROLL])
#: m; the same steps in the bending plane agree to float rounding (measured: < 3e-12).
SAME_M = 1e-9


def assert_same_table(a: Evaluation, b: Evaluation, tol: float = SAME_M) -> None:
    """Table I and every step's deflections and shape error agree within ``tol`` (m; MAPE in
    percent to ``tol`` too)."""
    ta, tb = a.metrics.to_dict(), b.metrics.to_dict()
    assert ta.keys() == tb.keys()
    for key, value in ta.items():
        assert value == pytest.approx(tb[key], abs=tol), key
    assert len(a.records) == len(b.records)
    for ra, rb in zip(a.records, b.records, strict=True):
        for name in ("measured_deflection_m", "predicted_deflection_m", "shape_error_m"):
            assert getattr(ra, name) == pytest.approx(getattr(rb, name), abs=tol), name


def test_a_roll_held_at_0_changes_nothing() -> None:
    plain = evaluate_series(REC.tension, REC.markers, OPTS)
    zero = evaluate_series(REC.tension, REC.markers, OPTS,
                           roll=RollSeries.of(REC.tension.stamps_s[::50],
                                              np.zeros(REC.tension.stamps_s[::50].size)))
    assert zero.to_json() == plain.to_json()
    assert [r.roll_rad for r in zero.records] == [0.0] * len(plain.records)


@pytest.mark.parametrize("roll", [RollSeries.of([0.0], [ROLL]), TURNING],
                         ids=["held", "turning-between-trials"])
def test_steps_at_a_roll_score_as_the_same_steps_at_roll_0(roll: RollSeries) -> None:
    """The body rolled (registration given): Table I is roll 0's; ignoring the roll (the model
    at roll 0) costs millimetres."""
    plain = evaluate_series(REC.tension, REC.markers, OPTS, REC.registration)
    rec = rolled(REC, roll)
    ev = evaluate_series(rec.tension, rec.markers, OPTS, REC.registration, roll=rec.roll)
    assert_same_table(ev, plain)
    assert [r.roll_rad for r in ev.records] == pytest.approx(
        roll.at([r.start_s for r in ev.records]), abs=1e-15)
    ignored = evaluate_series(rec.tension, rec.markers, OPTS, REC.registration)
    assert plain.metrics.rmse_m < 1e-5 and ignored.metrics.rmse_m > 5e-4


@settings(max_examples=15, deadline=None)
@given(roll=st.floats(-math.pi / 2, math.pi / 2, exclude_min=True, exclude_max=True))
def test_any_roll_scores_as_roll_0(roll: float) -> None:
    plain = evaluate_series(REC.tension, REC.markers, OPTS, REC.registration)
    rec = rolled(REC, RollSeries.of([0.0], [roll]))
    assert_same_table(evaluate_series(rec.tension, rec.markers, OPTS, REC.registration,
                                      roll=rec.roll), plain)


def test_a_registration_estimated_at_a_roll_is_turned_into_tdcm_base() -> None:
    rec = rolled(REC, RollSeries.of([0.0], [ROLL]))
    ev = evaluate_series(rec.tension, rec.markers, OPTS, roll=rec.roll)
    assert_same_table(ev, evaluate_series(REC.tension, REC.markers, OPTS))
    assert rotation_angle(ev.registrations[0].rotation, REC.registration.rotation) < 1e-3


def test_the_estimate_pairs_a_zero_hold_with_the_highest_step_at_its_roll() -> None:
    """Rolled only while at 16 N, with no zero hold at that roll: the estimate takes the 8 N
    steps (at roll 0, with the zero holds), and the 16 N steps still score at their roll."""
    roll = RollSeries.of([0.0, 4.0, 6.0, 10.0, 12.0], [0.0, ROLL, 0.0, ROLL, 0.0])
    rec = rolled(REC, roll)
    ev = evaluate_series(rec.tension, rec.markers, OPTS, roll=rec.roll)
    assert rotation_angle(ev.registrations[0].rotation, REC.registration.rotation) < 1e-3
    assert sorted({round(r.roll_rad, 12) for r in ev.records}) == [0.0, ROLL]
    assert ev.metrics.n_flagged == 0 and ev.metrics.rmse_m < 1e-5


#: The roll ramps 0 -> 0.3 rad over trial 1's 8 N hold (2-4 s), then stays.
RAMP = RollSeries.of([0.0, *np.linspace(2.0, 4.0, 101)], [0.0, *np.linspace(0.0, 0.3, 101)])


def test_a_step_whose_roll_moves_is_left_out_with_a_note() -> None:
    rec = rolled(REC, RAMP)
    plain = evaluate_series(REC.tension, REC.markers, OPTS, REC.registration)
    ev = evaluate_series(rec.tension, rec.markers, OPTS, REC.registration, roll=rec.roll)
    moved = [r for r in ev.records if r.note]
    assert len(moved) == 1 and moved[0].tension_n == pytest.approx(8.0, abs=0.1)
    assert moved[0].note.startswith("roll moved") and "roll.tolerance_rad = 0.02 rad" in \
        moved[0].note
    assert moved[0].measured_deflection_m is None and moved[0].shape_error_m is None
    assert any("roll moved" in w for w in ev.warnings)
    assert (ev.metrics.n_steps, ev.metrics.n_flagged) == (plain.metrics.n_steps - 1, 1)
    kept = [k for k, r in enumerate(ev.records) if not r.note]
    assert [ev.records[k].measured_deflection_m for k in kept] == pytest.approx(
        [plain.records[k].measured_deflection_m for k in kept], abs=SAME_M)


def test_a_wider_roll_tolerance_averages_the_moving_step() -> None:
    """``roll.tolerance_rad`` above the ramp: the step's roll is the mean over its frames."""
    rec = rolled(REC, RAMP)
    opts = options_from_sets(["roll.tolerance_rad=0.5"], OPTS)
    ev = evaluate_series(rec.tension, rec.markers, opts, REC.registration, roll=rec.roll)
    step = next(r for r in ev.records if r.tension_n == pytest.approx(8.0, abs=0.1))
    frames = rec.markers.stamps_s
    inside = frames[(frames >= step.start_s) & (frames <= step.end_s)]
    assert step.note == "" and step.roll_rad == pytest.approx(np.mean(RAMP.at(inside)), rel=1e-12)


def test_a_roll_series_refuses_non_finite_rolls_by_name() -> None:
    with pytest.raises(InvalidRollError, match=r"servo = nan rad is out of range"):
        RollSeries.of([0.0, 1.0], [0.0, np.nan], "servo")
    with pytest.raises(MetricsError, match="one per stamp"):
        RollSeries.of([0.0, 1.0], [0.0])
    series = RollSeries.of([2.0, 1.0], [0.2, 0.1])
    assert series.at([0.0, 1.0, 1.5, 2.0, 9.0]).tolist() == [0.1, 0.1, 0.1, 0.2, 0.2]


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The same recording at roll 0 (no roll topic), held at 0 on joint_states, turning to ROLL
    between the trials, and turning with the roll as joint ``servo``."""
    folder = tmp_path_factory.mktemp("roll")
    zero = RollSeries.of(REC.tension.stamps_s[::50], np.zeros(REC.tension.stamps_s[::50].size))
    return {"plain": write_recording(REC, folder / "plain"),
            "zero": write_recording(replace(REC, roll=zero), folder / "zero"),
            "turning": write_recording(rolled(REC, TURNING), folder / "turning"),
            "servo": write_recording(rolled(REC, TURNING), folder / "servo", roll_joint="servo")}


def test_a_bag_with_a_roll_topic_held_at_0_evaluates_as_without(bags: dict[str, Path]) -> None:
    def doc(name: str) -> dict:
        out = evaluate_paths([bags[name]], OPTS).to_json()
        del out["details"]["sources"]  # their paths
        return out

    assert doc("zero") == doc("plain")


def test_a_bag_at_a_roll_evaluates_in_its_bending_plane(bags: dict[str, Path]) -> None:
    plain = evaluate_paths([bags["plain"]], OPTS)
    assert load_bag(bags["turning"], labels=OPTS.layout.labels).roll is not None
    assert_same_table(evaluate_paths([bags["turning"]], OPTS), plain)
    ignored = evaluate_paths([bags["turning"]], OPTS, topics=Topics(joint_states="none"))
    assert ignored.metrics.rmse_m > 50 * plain.metrics.rmse_m


def test_tdcm_evaluate_reads_the_roll_joint_it_is_told(bags: dict[str, Path],
                                                      capsys: pytest.CaptureFixture[str]
                                                      ) -> None:
    def run(*args: str) -> dict:
        assert main(["evaluate", str(bags["servo"]), "--json", *args]) == 0
        return json.loads(capsys.readouterr().out)

    plain = evaluate_paths([bags["plain"]], OPTS)
    told = run("--roll-joint", "servo", "--set", f"E={TRUE_E}")
    assert told["rmse_m"] == pytest.approx(plain.metrics.rmse_m, abs=SAME_M)
    untold = run("--set", f"E={TRUE_E}")
    assert any("no finite position of joint roll" in w for w in untold["details"]["warnings"])
    assert untold["rmse_m"] > 50 * plain.metrics.rmse_m


def test_non_finite_roll_messages_are_left_out_and_counted(tmp_path: Path) -> None:
    stamps = np.array([0.0, 3.0, 6.0])
    holes = RollSeries(stamps, np.array([0.0, np.nan, ROLL]))  # unchecked: as a bag may hold
    bag = write_recording(replace(rolled(REC, TURNING), roll=holes), tmp_path / "holes")
    read = load_bag(bag, labels=OPTS.layout.labels)
    assert read.roll is not None and read.roll.roll_rad.tolist() == [0.0, ROLL]
    assert any("1 messages without a finite position of joint roll" in w for w in read.warnings)


def test_calibration_fits_the_same_modulus_at_a_roll(bags: dict[str, Path]) -> None:
    start = options_from_sets(["E=1.0e9"])
    plain = calibrate_paths([bags["plain"]], ["E"], start)
    turning = calibrate_paths([bags["turning"]], ["E"], start)
    assert turning.parameters[0].value == pytest.approx(plain.parameters[0].value, rel=1e-6)
    assert plain.parameters[0].value == pytest.approx(TRUE_E, rel=0.02)
