"""Point covariances from a parameter covariance: linearised through the solver, checked against
Monte Carlo on the same inputs, closed forms and scipy's quantiles."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.model import (
    Design,
    FrictionTrack,
    InvalidUncertaintyError,
    ParameterCovariance,
    inside_band,
    linearised_covariances,
    preset,
    surface_points,
)
from tdcm_ros.model.uncertainty import (
    band_half_widths,
    chi2_3,
    monte_carlo_covariances,
    normal_quantile,
    point_covariances,
)

DESIGN = preset("paper-experiment").with_overrides(E=7.0e8)
#: A calibration's size of spread: E to 1 %, mu to 0.03, correlated as a fit makes them.
COVARIANCE = np.array([[(7e6) ** 2, -0.4 * 7e6 * 0.03], [-0.4 * 7e6 * 0.03, 0.03**2]])


def fitted(names=("E", "mu"), values=(7.0e8, 0.3), covariance=COVARIANCE, residual=1e-4):
    return ParameterCovariance(tuple(names), np.array(values), np.array(covariance), residual)


def markers_after_loading(design: Design, mu: float) -> np.ndarray:
    """The three markers at 20 N reached from slack (a fresh friction track)."""
    track = FrictionTrack(mu)
    track.solve(design, 10.0)
    result = track.solve(design, 20.0)
    return surface_points(result, np.array([0.015, 0.033, 0.053]), 0.00492, math.pi)[0]


def test_linearised_agrees_with_monte_carlo_through_the_solver() -> None:
    uncertainty = fitted()
    linear = linearised_covariances(markers_after_loading, DESIGN, 0.3, uncertainty)
    sampled = monte_carlo_covariances(markers_after_loading, DESIGN, 0.3, uncertainty, 1000,
                                      np.random.default_rng(1))
    # a sample variance of 1000 draws is within sqrt(2 / 1000) = 4.5 % (1 SE) of the truth
    for k in range(3):  # each marker's in-plane block (y is exact in the planar model)
        block = np.ix_([0, 2], [0, 2])
        a, b = linear[k][block], sampled[k][block]
        assert np.linalg.norm(a - b) <= 0.12 * np.linalg.norm(b), (k, a, b)
    assert np.all(linear[:, 1, :] == 0.0)
    # the tip's spread is what a 1 % E and 0.03 mu give: tens of micrometres, not nothing
    assert 1e-5 < math.sqrt(linear[-1, 0, 0]) < 1e-3


def test_an_affine_model_is_propagated_exactly() -> None:
    """x = A p + b: the linearised covariance is A C A^T whatever the step."""
    a = np.array([[[1e-12, 0.0, 2e-12], [0.0, 0.0, -3e-12]], [[0.5, 0.0, 0.1], [2.0, 1.0, 0.0]]])

    def affine(design: Design, mu: float) -> np.ndarray:
        return a[0] * design.E + a[1] * mu + 1.0

    uncertainty = fitted()
    got = linearised_covariances(affine, DESIGN, 0.3, uncertainty)
    expected = np.einsum("aki,ab,bkj->kij", a, uncertainty.covariance, a)
    assert np.allclose(got, expected, rtol=1e-6, atol=1e-20)
    assert np.allclose(point_covariances(a, uncertainty.covariance), expected, rtol=1e-12)


@pytest.mark.parametrize("confidence", [0.5, 0.9, 0.95, 0.99, 0.999])
def test_quantiles_match_scipy(confidence: float) -> None:
    from scipy.stats import chi2, norm

    assert chi2_3(confidence) == pytest.approx(chi2.ppf(confidence, 3), rel=1e-12)
    assert normal_quantile(confidence) == pytest.approx(norm.ppf(0.5 + confidence / 2),
                                                        rel=1e-12)


@pytest.mark.parametrize("confidence", [0.0, 1.0, math.nan, -0.5])
def test_a_confidence_outside_0_1_is_refused(confidence: float) -> None:
    with pytest.raises(InvalidUncertaintyError, match="confidence"):
        chi2_3(confidence)


@settings(max_examples=25, deadline=None)
@given(st.floats(0.5, 0.99), st.integers(0, 2**31))
def test_the_band_holds_its_confidence_of_normal_draws(confidence: float, seed: int) -> None:
    rng = np.random.default_rng(seed)
    root = rng.normal(size=(3, 3))
    covariance = root @ root.T + 0.1 * np.eye(3)
    draws = rng.multivariate_normal(np.zeros(3), covariance, 20_000)
    inside = inside_band(draws, np.broadcast_to(covariance, (len(draws), 3, 3)), confidence)
    assert abs(inside.mean() - confidence) < 0.015
    normal = np.array([1.0, 0.0, 0.0])
    half = band_half_widths(covariance[None], normal[None], confidence)[0]
    assert abs(np.mean(np.abs(draws[:, 0]) <= half) - confidence) < 0.015


@pytest.mark.parametrize(("kwargs", "parameter"), [
    ({"names": ("E", "Young")}, "uncertainty.parameters"),
    ({"names": ("E", "E")}, "uncertainty.parameters"),
    ({"values": (7e8,)}, "uncertainty.values"),
    ({"values": (7e8, math.nan)}, "uncertainty.values"),
    ({"covariance": [[1.0, 2.0], [0.0, 1.0]]}, "uncertainty.covariance"),
    ({"covariance": [[1.0, 0.0], [0.0, -1.0]]}, "uncertainty.covariance"),
    ({"covariance": [[0.0, 0.0], [0.0, 0.0]]}, "uncertainty.covariance"),
    ({"covariance": [[1.0, 0.0], [0.0, math.inf]]}, "uncertainty.covariance"),
    ({"residual": -1e-4}, "uncertainty.residual_m"),
    ({"residual": math.nan}, "uncertainty.residual_m"),
])
def test_a_bad_covariance_names_its_key(kwargs: dict, parameter: str) -> None:
    with pytest.raises(InvalidUncertaintyError) as caught:
        fitted(**kwargs)
    assert caught.value.parameter == parameter and "allowed" in str(caught.value)


def test_monte_carlo_of_draws_that_are_never_designs_stops_with_an_error() -> None:
    """mu drawn around -1 (the band taken there) is never valid: a typed error after a bounded
    number of draws, not a loop without end."""
    hopeless = fitted(names=("mu",), values=(0.3,), covariance=[[1e-6]])
    with pytest.raises(InvalidUncertaintyError, match="parameter draws were valid designs"):
        monte_carlo_covariances(markers_after_loading, DESIGN, -1.0, hopeless, 5,
                                np.random.default_rng(0))
