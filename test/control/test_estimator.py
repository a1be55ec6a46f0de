"""The effective-stiffness estimate against simulated worlds of a known g."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.control import GainEstimator, GainSettings, ModelTip
from tdcm_ros.errors import InputError
from tdcm_ros.model import preset, solve

DESIGN = preset("paper-experiment")


def test_the_model_depends_on_the_tension_through_t_over_e_only() -> None:
    stiffer = DESIGN.with_overrides(E=DESIGN.E * 1.3)
    assert np.allclose(solve(stiffer, 13.0).tip_position, solve(DESIGN, 10.0).tip_position,
                       atol=1e-12)


@settings(max_examples=15)
@given(st.floats(0.6, 1.6), st.integers(0, 2**32 - 1), st.floats(2e-5, 2e-4))
def test_the_estimate_converges_to_the_true_gain_and_its_std_shrinks(
        true_gain: float, seed: int, noise_m: float) -> None:
    rng = np.random.default_rng(seed)
    world = DESIGN.with_overrides(E=DESIGN.E / true_gain)
    estimator, model = GainEstimator(GainSettings(noise_m=noise_m)), ModelTip(DESIGN)
    stds = [estimator.std]
    for tension in rng.uniform(2.0, 18.0, 60):
        x, _, z = solve(world, tension).tip_position + rng.normal(0.0, noise_m, 3)
        _, tip, slope = model.tip_and_jacobian(estimator.gain, tension)
        estimator.predict(0.02)
        assert estimator.update((x, z), tip, slope)
        stds.append(estimator.std)
    assert abs(estimator.gain - true_gain) < max(4.0 * estimator.std, 1e-3)
    assert stds[-1] < 0.05 * stds[0]


def test_a_zero_tension_teaches_nothing_and_the_random_walk_widens_the_std() -> None:
    estimator, model = GainEstimator(), ModelTip(DESIGN)
    _, tip, slope = model.tip_and_jacobian(1.0, 0.0)
    assert slope == (0.0, 0.0)
    before = estimator.std
    estimator.update((tip[0] + 1e-3, tip[1]), tip, slope)
    assert (estimator.gain, estimator.std) == (1.0, before)
    estimator.predict(100.0)
    assert estimator.std == pytest.approx(math.hypot(before, 0.01 * 10.0))


@given(st.tuples(*[st.sampled_from([math.nan, math.inf, -math.inf, 0.01])] * 6))
def test_non_finite_input_is_refused_and_leaves_no_nan(values: tuple[float, ...]) -> None:
    estimator = GainEstimator()
    used = estimator.update(values[:2], values[2:4], values[4:])
    assert used == all(math.isfinite(v) for v in values)
    assert math.isfinite(estimator.gain) and math.isfinite(estimator.std)
    estimator.predict(math.nan)
    assert math.isfinite(estimator.std)


def test_the_estimate_stays_within_its_bounds() -> None:
    estimator = GainEstimator(GainSettings(bounds=(0.5, 2.0)))
    estimator.update((1.0, 0.0), (0.0, 0.0), (1e-3, 0.0))  # a wild measurement
    assert estimator.gain == 2.0


@pytest.mark.parametrize(("field", "value"), [("initial_std", 0.0), ("noise_m", math.nan),
                                              ("process_std", -1.0), ("bounds", (2.0, 1.0)),
                                              ("initial", 9.0)])
def test_bad_settings_name_the_field(field: str, value: object) -> None:
    with pytest.raises(InputError, match=f"gain.{field}"):
        GainSettings(**{field: value})
