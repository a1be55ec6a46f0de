"""Bags of a body with several tendons (the antagonistic pair): tension layouts, steps that hold
every tendon, evaluation and calibration at each step's tension vector, all from bags the model
itself simulates."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.metrics.align import on_first_stamps
from tdcm_ros.metrics.api import calibrate_paths, evaluate_paths
from tdcm_ros.metrics.errors import MetricsError, TensionTopicError
from tdcm_ros.metrics.evaluation import evaluate_series
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.report import format_evaluation
from tdcm_ros.metrics.series import TensionSeries
from tdcm_ros.metrics.steps import LOADING, UNLOADING, assign_phases, detect_steps
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.metrics.tension_topics import TensionTopics, tension_topics
from test.metrics.metrics_samples import (
    PAIR,
    PAIR_BODY,
    PAIR_LEVELS,
    pair_recording,
    small_recording,
)

OPTIONS = options_from_sets([f"design.preset={PAIR_BODY}"])
TENDONS = ("flexor", "extensor")
#: m. The noise-free bag's markers are the model's own at the holds' exact tensions, taken to
#: the mocap frame and back (two rotations of ~50 mm coordinates: rounding ~1e-17 m) and
#: averaged over the frames of a hold: what is left of the error is float64 rounding, so 1 nm
#: bounds it with room while any model or tension difference (um and up) would exceed it.
ROUNDING_M = 1e-9
#: m. The shape error compares the model's midline with a spline through three markers: a
#: reconstruction error of the measured midline, not of the model (the single-tendon tests
#: bound it at 0.1 mm); here at most 0.016 mm, at the 16 N bend.
SPLINE_M = 5e-5


@pytest.fixture(scope="module")
def pair_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The noise-free pair on one JointState topic ``tension``."""
    return write_recording(pair_recording(), tmp_path_factory.mktemp("pair") / "joint_state")


def test_a_noise_free_pair_bag_evaluates_to_zero_error(pair_bag: Path) -> None:
    ev = evaluate_paths([pair_bag], OPTIONS)
    # each hold is a step at its exact tension vector, named by tendon
    assert [tuple(r.tensions_n) for r in ev.records] == [TENDONS] * 11
    assert [tuple(r.tensions_n.values()) for r in ev.records] == [*PAIR_LEVELS * 2, (0.0, 0.0)]
    assert [r.trial for r in ev.records] == [1] * 5 + [2] * 6
    # (16, 0) -> (8, 8) and (8, 8) -> (0, 12) pull a tendon further: loading; the end unloads
    assert [r.phase for r in ev.records] == [LOADING] * 10 + [UNLOADING]
    errors = [abs((r.predicted_deflection_m or 0.0) - (r.measured_deflection_m or 1.0))
              for r in ev.records]
    assert max(errors) < ROUNDING_M
    m = ev.metrics
    assert (m.n_trials, m.n_steps, m.n_flagged) == (2, 10, 0)
    assert m.rmse_m is not None and m.rmse_m < ROUNDING_M
    assert m.mae_m is not None and m.mae_m < ROUNDING_M
    assert m.mape_pct is not None and m.mape_pct < 1e-5  # over the 4 bent steps
    assert m.shape_error_m is not None and m.shape_error_m < SPLINE_M
    # the trial's highest step is (16, 0): its tip deflection, as the model gives it
    bent = [r for r in ev.records if tuple(r.tensions_n.values()) == (16.0, 0.0)]
    assert m.deflection_mean_m == pytest.approx(bent[0].predicted_deflection_m, abs=ROUNDING_M)
    assert ev.warnings == ()


def test_reports_show_each_tendons_tension_by_name(pair_bag: Path) -> None:
    ev = evaluate_paths([pair_bag], OPTIONS)
    steps = ev.to_json()["steps"]
    assert steps[3]["tensions_n"] == {"flexor": 8.0, "extensor": 8.0}
    assert all("tension_n" not in step for step in steps)
    text = format_evaluation(ev).splitlines()
    head = next(line for line in text if line.lstrip().startswith("trial"))
    assert head.split()[:6] == ["trial", "phase", "flexor", "N", "extensor", "N"]
    row = text[text.index(head) + 5].split()
    assert row[:4] == ["1", "loading", "0.000", "12.000"]


def test_calibrate_recovers_the_modulus_of_a_pair_world(tmp_path: Path) -> None:
    """A world of E = 1.2 GPa with load-cell and marker noise, lag and occlusions; the fit
    starts from the body file's 1.85 GPa."""
    true_e = 1.2e9
    rec = pair_recording(PAIR.with_overrides(E=true_e), tension_noise_n=0.03,
                         marker_noise_m=5e-5, lag_s=0.1, occlusion=0.05, seed=4)
    cal = calibrate_paths([write_recording(rec, tmp_path / "pair")], ["E"], OPTIONS)
    (e,) = cal.parameters
    assert e.initial == pytest.approx(1.85e9)
    assert e.ci_low < true_e < e.ci_high
    assert e.value == pytest.approx(true_e, rel=5e-3)
    assert e.ci_high - e.ci_low < 0.02 * true_e
    assert cal.identifiable and cal.warnings == ()
    assert cal.after.metrics.rmse_m is not None and cal.before.metrics.rmse_m is not None
    assert cal.after.metrics.rmse_m < 0.01 * cal.before.metrics.rmse_m


def test_a_one_tendon_joint_state_bag_gives_the_wrench_table(tmp_path: Path) -> None:
    """model_node takes a JointState for any body: so does the evaluation, the paper's one
    tendon by its default name ``tendon_1``."""
    rec = small_recording()
    column = rec.tension.tension_n[:, None]
    joint = replace(rec, tension=TensionSeries(rec.tension.stamps_s, column, ("tendon_1",)))
    options = options_from_sets(["E=0.7e9"])
    wrench = evaluate_paths([write_recording(rec, tmp_path / "wrench")], options)
    efforts = evaluate_paths([write_recording(joint, tmp_path / "joint")], options)
    assert format_evaluation(efforts) == format_evaluation(wrench).replace(
        str(tmp_path / "wrench"), str(tmp_path / "joint"))


def test_a_step_holds_every_tendon() -> None:
    """The flexor holds 8 N for 6 s; the extensor ramps 0 -> 4 N over the first 3 s, then
    holds: one step, where both hold, with each tendon's median and mean."""
    t = np.arange(0.0, 6.0, 0.002)
    flexor = np.full(t.size, 8.0)
    extensor = np.clip(4.0 * t / 3.0, 0.0, 4.0)
    (step,) = detect_steps(t, np.column_stack([flexor, extensor]))
    assert step.start_s >= 3.0 and step.end_s == pytest.approx(t[-1])
    assert step.medians_n == step.means_n == (8.0, 4.0)
    assert step.median_n == 8.0  # the level: the largest
    assert detect_steps(t, flexor)[0].start_s < 1.0  # the flexor alone holds from the start


def test_a_step_loads_when_any_tendon_rises() -> None:
    medians = [(0.0, 0.0), (8.0, 0.0), (8.0, 8.0), (0.0, 8.0), (0.0, 8.1), (0.0, 0.0)]
    assert assign_phases(medians, [0] * 6, 0.3) == [
        LOADING, LOADING, LOADING, UNLOADING, UNLOADING, UNLOADING]
    assert assign_phases([(0.0, 0.0), (4.0, 0.0), (0.0, 4.0)], [0] * 3, 0.3) == [LOADING] * 3


def test_samples_of_several_topics_meet_on_the_first_ones_stamps() -> None:
    first = np.array([0.0, 0.1, 0.2, 0.3])
    other = np.array([0.004, 0.099, 0.26, 0.305])
    stamps, values = on_first_stamps([first, other], [first * 10, other * 100], 0.01)
    np.testing.assert_array_equal(stamps, [0.0, 0.1, 0.3])  # 0.2 has no sample within 10 ms
    np.testing.assert_allclose(values, [[0.0, 0.4], [1.0, 9.9], [3.0, 30.5]])


def test_tension_topic_layouts() -> None:
    assert tension_topics("tension", TENDONS) == TensionTopics(TENDONS, "tension")
    assert tension_topics(["extensor=/e", "flexor=/f"], TENDONS) == TensionTopics(
        TENDONS, None, ("/f", "/e"))  # in the body file's order


@pytest.mark.parametrize(("given", "message"), [
    (["flexor=/f", "thumb=/e"],
     "'thumb' is not a tendon of the body; allowed: its tendon names flexor, extensor"),
    (["flexor=/f"],
     "no topic for tendon(s) extensor of the body; allowed: NAME=TOPIC for every tendon"),
    (["flexor=/f", "flexor=/g", "extensor=/e"], "tendon flexor is given a topic twice"),
    (["flexor=/f", "extensor=/f"], "one topic for several tendons"),
    (["/f", "extensor=/e"], "'/f' is a plain TOPIC among NAME=TOPIC"),
    (["flexor=", "extensor=/e"], "'flexor=' has an empty NAME or TOPIC"),
    (["/f", "/e"], "several topics or none without NAME="),
])
def test_tension_topics_that_do_not_fit_the_body(given: list[str], message: str) -> None:
    with pytest.raises(TensionTopicError, match="--tension-topic") as caught:
        tension_topics(given, TENDONS)
    assert message in str(caught.value) and caught.value.parameter == "--tension-topic"
    assert isinstance(caught.value, InputError) and caught.value.exit_code == 2


def test_a_series_must_have_a_column_per_tendon() -> None:
    rec = pair_recording(trials=1)
    one = TensionSeries.of(rec.tension.stamps_s, rec.tension.tension_n[:, 0])
    with pytest.raises(MetricsError, match="do not match the design's tendons flexor, extensor"):
        evaluate_series(one, rec.markers, OPTIONS)
    assert evaluate_series(rec.tension, rec.markers, OPTIONS,
                           rec.registration).metrics.n_steps == 5
