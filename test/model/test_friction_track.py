"""FrictionTrack: tensions solved in the order they happened under stick-slip friction, checked
against the stateless capstan profiles (an independent implementation of the same law)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdcm_ros.model import Capstan, FrictionTrack, Loading, check_mu, preset, solve
from tdcm_ros.model.loading import InvalidLoadingError

DESIGN = preset("paper-experiment").with_overrides(E=7.0e8)


def tip(result) -> np.ndarray:
    return np.asarray(result.tip_position)


def test_without_friction_the_track_is_the_papers_solve_bit_for_bit() -> None:
    track = FrictionTrack(0.0)
    for tension in (0.0, 8.0, 20.0, 4.0):
        assert np.array_equal(tip(track.solve(DESIGN, tension)), tip(solve(DESIGN, tension)))
    assert track.state.tension_along is None


def test_loading_from_slack_is_the_capstan_loss_toward_the_tip() -> None:
    track = FrictionTrack(0.3)
    for tension in (0.0, 5.0, 10.0, 15.0, 20.0):
        got = track.solve(DESIGN, tension)
        expected = solve(DESIGN, tension, loading=Loading(tension_profile=Capstan(0.3)))
        assert np.allclose(tip(got), tip(expected), rtol=0.0, atol=1e-9)


def test_a_full_reversal_slips_the_whole_tendon_the_other_way() -> None:
    track = FrictionTrack(0.3)
    for tension in (0.0, 10.0, 20.0):
        track.solve(DESIGN, tension)
    # down to 2 N: below 20 N exp(-2 mu w) everywhere (w < 1 rad here), so every point slips
    got = track.solve(DESIGN, 2.0)
    assert got.tip_angle_rad < 1.0
    expected = solve(DESIGN, 2.0, loading=Loading(tension_profile=Capstan(0.3, unloading=True)))
    assert np.allclose(tip(got), tip(expected), rtol=0.0, atol=1e-9)


def test_the_shape_depends_on_the_direction_of_the_change() -> None:
    up, down = FrictionTrack(0.3), FrictionTrack(0.3)
    loading = [up.solve(DESIGN, t) for t in (0.0, 10.0)][-1]
    unloading = [down.solve(DESIGN, t) for t in (0.0, 20.0, 10.0)][-1]
    frictionless = solve(DESIGN, 10.0)
    # loading loses tension toward the tip, unloading holds it: the loop brackets no friction
    assert loading.tip_deflection_m < frictionless.tip_deflection_m < unloading.tip_deflection_m


def test_solve_at_leaves_the_history_alone() -> None:
    track = FrictionTrack(0.3)
    track.solve(DESIGN, 20.0)
    before = track.state.tension_along
    moved = track.solve_at(DESIGN, 10.0, mu=0.1)
    assert track.state.tension_along is before
    assert moved.loading is not None


@pytest.mark.parametrize("mu", [-0.1, math.nan, math.inf, 10.5])
def test_a_bad_mu_names_the_parameter_and_range(mu: float) -> None:
    with pytest.raises(InvalidLoadingError) as caught:
        FrictionTrack(mu)
    assert caught.value.parameter == "friction.mu" and "[0, 10]" in str(caught.value)
    with pytest.raises(InvalidLoadingError, match="body.yaml: friction.mu"):
        check_mu(mu, "body.yaml: friction.mu")
