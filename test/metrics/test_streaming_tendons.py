"""The streaming evaluation of a body with several tendons (the antagonistic pair): the
multilinear marker lattice against a direct solve, and the running step records against the
offline evaluation of the same samples."""

from __future__ import annotations

import numpy as np
import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.metrics.evaluation import Evaluation, evaluate_series, predict
from tdcm_ros.metrics.lookup import MarkerLattice
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.streaming import RunningEvaluation
from tdcm_ros.metrics.synthetic import Recording
from test.metrics.metrics_samples import PAIR_BODY, PAIR_LEVELS, pair_recording, stream

OPTIONS = options_from_sets([f"design.preset={PAIR_BODY}"])
#: m. Measured: over 50 random tension vectors in [0, 16]**2 N the lattice (0.1 N per tendon,
#: multilinear) is within 7.5e-9 m of a direct solve (the nearest lattice point alone: 3.0e-5
#: m); at a lattice point it is the point's own solve (0 m).
LATTICE_M = 2e-8


def stream_pair(rec: Recording) -> RunningEvaluation:
    """A running evaluation of the pair fed ``rec`` (:func:`stream`)."""
    running = RunningEvaluation(OPTIONS, rec.registration)
    stream(rec, running)
    return running


def assert_same_steps(running: RunningEvaluation, offline: Evaluation) -> None:
    """The running records are the offline ones but the last (the stream ends inside the final
    zero hold, which never finishes): trial, phase and tensions by tendon exactly, deflections
    to float rounding."""
    assert len(running.records) == len(offline.records) - 1
    for live, off in zip(running.records, offline.records, strict=False):
        assert (live.trial, live.phase, live.tensions_n, live.frames) == \
            (off.trial, off.phase, off.tensions_n, off.frames)
        assert live.measured_deflection_m == pytest.approx(off.measured_deflection_m, abs=1e-12)
        assert live.predicted_deflection_m == pytest.approx(off.predicted_deflection_m,
                                                            abs=1e-12)


def test_the_lattice_is_a_direct_solve_to_nanometres() -> None:
    lattice = MarkerLattice(OPTIONS.design, OPTIONS.layout, settings=OPTIONS.solver)
    vectors = np.random.default_rng(0).uniform(0.0, 16.0, (50, 2))
    direct = np.array([predict(OPTIONS.design, v.tolist(), OPTIONS).markers for v in vectors])
    assert np.linalg.norm(lattice.markers(vectors) - direct, axis=-1).max() < LATTICE_M
    for level in PAIR_LEVELS:  # on the lattice: that point's own solve alone
        solves = lattice.solves
        exact = predict(OPTIONS.design, list(level), OPTIONS).markers
        assert np.array_equal(lattice.markers(level), exact)
        assert lattice.solves - solves <= 1


def test_the_lattice_keeps_at_most_max_points() -> None:
    lattice = MarkerLattice(OPTIONS.design, OPTIONS.layout, max_points=8)
    lattice.markers([[0.05, 0.05], [1.05, 1.05], [2.05, 2.05]])
    assert lattice.solves == 12 and len(lattice._points) == 8
    with pytest.raises(InputError, match="tension"):
        lattice.markers([1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="tension"):
        lattice.markers([1.0, -2.0])


@pytest.mark.parametrize("noise", [False, True], ids=["noise-free", "noisy"])
def test_the_running_steps_of_a_pair_are_the_offline_ones(noise: bool) -> None:
    rec = pair_recording(**({"tension_noise_n": 0.03, "marker_noise_m": 5e-5, "lag_s": 0.1,
                             "occlusion": 0.1} if noise else {}))
    offline = evaluate_series(rec.tension, rec.markers, OPTIONS, registration=rec.registration)
    running = stream_pair(rec)
    assert_same_steps(running, offline)
    assert running.metrics == offline.metrics


def test_a_tension_sample_needs_one_value_per_tendon() -> None:
    running = RunningEvaluation(OPTIONS)
    with pytest.raises(InputError, match="flexor, extensor"):
        running.add_tension(0.0, 8.0)
    running.add_tension(0.0, (8.0, 1.0))
    assert running.tension_at(0.01) == (8.0, 1.0)
