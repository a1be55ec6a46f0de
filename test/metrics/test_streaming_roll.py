"""The running evaluation of a rolled body (issue 33): its finished steps take their mean roll
and score in the rolled bending plane, as the offline evaluation of the same samples."""

from __future__ import annotations

from dataclasses import replace
from typing import cast

import numpy as np
import pytest

from tdcm_ros.metrics.evaluation import evaluate_series
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.series import RollSeries
from tdcm_ros.metrics.streaming import RunningEvaluation
from tdcm_ros.metrics.synthetic import Recording, rolled
from test.metrics.metrics_samples import DESIGN, rotation_angle, small_recording, stream

OPTS = EvaluateOptions(design=DESIGN)
REC = cast(Recording, small_recording())
#: The roll: 0 for trial 1 but a ramp 0 -> 0.3 rad over its 8 N hold (2-4 s); 0.6 rad from
#: trial 2 on (6 s).
ROLL = RollSeries.of([0.0, *np.linspace(2.0, 4.0, 101), 6.0],
                     [0.0, *np.linspace(0.0, 0.3, 101), 0.6])


@pytest.mark.parametrize("estimate", [False, True], ids=["registration-given", "estimated"])
def test_running_steps_at_a_roll_are_the_offline_ones(estimate: bool) -> None:
    """Registration given, or estimated live (from the steps finished so far, so offline, with
    the final zero hold too, may pick another zero hold: compared with the live one)."""
    rec = rolled(REC, ROLL)
    running = RunningEvaluation(OPTS, None if estimate else REC.registration)
    stream(rec, running)
    assert running.used_registration is not None
    assert rotation_angle(running.used_registration.rotation, REC.registration.rotation) < 1e-3
    offline = evaluate_series(rec.tension, rec.markers, OPTS, running.used_registration,
                              roll=rec.roll)
    # the stream ends inside the final zero hold, which never finishes
    assert len(running.records) == len(offline.records) - 1
    for live, off in zip(running.records, offline.records, strict=False):
        assert (live.trial, live.phase, live.tensions_n, live.frames, live.note) == \
            (off.trial, off.phase, off.tensions_n, off.frames, off.note)
        assert live.roll_rad == pytest.approx(off.roll_rad, abs=1e-15)
        assert live.measured_deflection_m == pytest.approx(off.measured_deflection_m, abs=1e-12)
        assert live.shape_error_m == pytest.approx(off.shape_error_m, abs=1e-12)
    assert running.metrics == offline.metrics
    assert [r.note.startswith("roll moved") for r in running.records].count(True) == 1
    assert {round(r.roll_rad, 12) for r in running.records if not r.note} == {0.0, 0.3, 0.6}


def test_running_table_at_a_roll_is_the_table_at_roll_0() -> None:
    """A body held at 0.6 rad: the running Table I is roll 0's; without the roll samples it
    is millimetres off."""
    rec = rolled(REC, RollSeries.of([0.0], [0.6]))
    at_zero = RunningEvaluation(OPTS, REC.registration)
    stream(rolled(REC, RollSeries.of([0.0], [0.0])), at_zero)
    at_roll = RunningEvaluation(OPTS, REC.registration)
    stream(rec, at_roll)
    assert at_zero.metrics is not None and at_roll.metrics is not None
    assert at_roll.metrics.rmse_m == pytest.approx(at_zero.metrics.rmse_m, abs=1e-12)
    assert at_roll.metrics.shape_error_m == pytest.approx(at_zero.metrics.shape_error_m,
                                                          abs=1e-12)
    unrolled = RunningEvaluation(OPTS, REC.registration)
    stream(replace(rec, roll=RollSeries.of([0.0], [0.0])), unrolled)  # the roll left out
    assert unrolled.metrics is not None and unrolled.metrics.rmse_m > 5e-4
