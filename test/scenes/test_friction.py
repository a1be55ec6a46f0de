"""Friction: the state the world keeps and the tension profile the model calls are separate; the
profile only reads the state, and only a converged solve advances it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.errors import PhysicsError
from tdcm_ros.model.friction import FrictionState, StickSlipTension
from tdcm_ros.scenes import load_scene
from test.scenes.scene_helpers import make_scene

S = np.linspace(0.0, 0.05, 11)


def test_the_model_gets_a_profile_over_the_state_not_the_effect() -> None:
    compiled = make_scene({"tendon_friction": {"mu": 0.2}}).compile()
    (effect,) = compiled.mechanics
    (state,) = compiled.histories
    assert compiled.loading is not None
    profile = compiled.loading.tension_profile
    assert isinstance(profile, StickSlipTension) and isinstance(state, FrictionState)
    assert profile.state is state and profile.mu == 0.2
    assert profile is not effect and state is not effect and profile is not state
    assert repr(profile) == "StickSlipTension(mu=0.2)"


@given(st.lists(st.tuples(st.floats(0.0, 25.0), st.floats(0.0, 3.0)), min_size=1, max_size=6))
def test_calling_the_profile_never_changes_the_state(calls: list[tuple[float, float]]) -> None:
    state = FrictionState()
    profile = StickSlipTension(0.3, state)
    for base, turning in calls:
        wrap = np.linspace(0.0, turning, S.size)
        first = profile(S, wrap, base)
        assert state.tension_along is None
        np.testing.assert_array_equal(profile(S, wrap, base), first)
        assert np.all(first >= base * np.exp(-0.3 * wrap) * (1 - 1e-12))
        assert np.all(first <= base * np.exp(0.3 * wrap) * (1 + 1e-12))


def test_a_converged_solve_advances_the_state_and_a_failed_one_does_not() -> None:
    world = load_scene("near_singular").world()
    (state,) = world.compiled.histories
    assert isinstance(state, FrictionState) and state.tension_along is None
    result = world.solve(18.0)
    along = state.tension_along
    assert along is not None and result.tendon_tension is not None
    np.testing.assert_array_equal(along[0], result.s)
    np.testing.assert_array_equal(along[1], result.tendon_tension)
    with pytest.raises(PhysicsError):
        world.solve(25.0)  # past the tendon-offset singularity
    assert state.tension_along is along


def test_the_state_is_read_on_another_grid_by_interpolation() -> None:
    world = make_scene({"tendon_friction": {"mu": 0.2}}).world()
    (state,) = world.compiled.histories
    assert isinstance(state, FrictionState)
    result = world.solve(12.0)
    assert result.tendon_tension is not None
    np.testing.assert_array_equal(state.at(result.s), result.tendon_tension)
    middle = 0.5 * (result.s[:-1] + result.s[1:])
    np.testing.assert_allclose(state.at(middle), 0.5 * (result.tendon_tension[:-1]
                                                         + result.tendon_tension[1:]))
