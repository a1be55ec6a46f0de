"""Hard cases over the design space: every solve converges to a finite, reproducible shape or
raises the right typed error, never NaN."""

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from tdcm_ros.model import (
    ConvergenceError,
    InvalidDesignError,
    NotchClosureError,
    SolverSettings,
    TendonSingularityError,
    preset,
    solve,
)
from tdcm_ros.model.grid import build_grid

LIMITS = (TendonSingularityError, NotchClosureError, ConvergenceError)


@st.composite
def hard_designs(draw):
    r_outer = draw(st.floats(1e-3, 6e-3))
    return preset("paper-experiment").with_overrides(
        N=draw(st.integers(1, 60)),
        w_n=draw(st.floats(1e-5, 4e-3)),             # down to far narrower than a default cell
        w_t=draw(st.sampled_from([0.0, 1e-6, 1e-4, 4e-3])),  # including w_t at its 1 um floor
        w_d=draw(st.floats(0.05, 1.99)) * r_outer,    # stiffness ratio ~1 to > 1000
        R_outer=r_outer,
        r_inner=draw(st.floats(0.0, 0.9)) * r_outer,
        R_c=draw(st.floats(0.1, 0.99)) * r_outer,
        E=draw(st.floats(1e8, 3e9)),
        profile=draw(st.sampled_from(["circular", "rectangular"])),
    )


@settings(max_examples=150, suppress_health_check=[HealthCheck.too_slow])
@given(design=hard_designs(), tension=st.floats(0.0, 5e3),
       routing=st.sampled_from(["paper", "free"]))
def test_converges_or_raises_a_typed_limit(design, tension, routing):
    config = SolverSettings(routing=routing)
    try:
        first = solve(design, tension, settings=config)
    except LIMITS as error:
        assert str(error)
        with pytest.raises(type(error)):
            solve(design, tension, settings=config)
        return
    assert first.converged
    assert np.all(np.isfinite(first.positions)) and np.all(np.isfinite(first.theta))
    again = solve(design, tension, settings=config)
    assert np.array_equal(first.positions, again.positions)
    # The shape honours Algorithm 1's tolerance: one more iteration moves no node beyond it.
    assert first.residual_history[-1] <= config.tol


def test_stiffness_ratio_spans_one_to_over_a_thousand():
    base = preset("paper-experiment")
    for w_d, low, high in ((1.999 * base.R_outer, 0.99, 1.01), (0.1e-3, 1000.0, np.inf)):
        grid = build_grid(base.with_overrides(w_d=w_d), SolverSettings())
        ratio = grid.peak_c.max() * base.E * base.tube_second_moment
        assert low <= ratio <= high
        assert solve(base.with_overrides(w_d=w_d), 0.05).converged


def test_bends_past_180_and_360_degrees():
    soft = preset("paper-experiment").with_overrides(N=60, w_n=1e-3, w_t=0.2e-3, w_d=0.6e-3,
                                                   E=0.5e9)
    half = solve(soft, 1.5)
    full = solve(soft, 4.0)
    assert np.degrees(half.tip_angle_rad) > 180
    assert np.degrees(full.tip_angle_rad) > 360
    # Arc length is preserved: node spacing along the curve equals the cell lengths.
    steps = np.linalg.norm(np.diff(full.positions, axis=0), axis=1)
    assert np.all(steps <= np.diff(full.s) + 1e-12)


def test_notch_narrower_than_a_default_cell_and_w_t_zero_are_solved():
    narrow = preset("paper-experiment").with_overrides(w_n=1e-5)
    assert solve(narrow, 20).converged
    touching = preset("paper-experiment").with_overrides(w_t=0.0)
    assert solve(touching, 20, settings=SolverSettings(routing="free")).converged


def test_custom_profile_is_validated_and_used():
    from tdcm_ros.model import CustomProfile

    base = preset("paper-experiment")
    rect = solve(base.with_overrides(profile="rectangular"), 10).tip_position
    same = solve(base.with_overrides(profile=CustomProfile(lambda s: 0 * s + base.w_d / 2)),
                 10).tip_position
    assert np.allclose(rect, same, atol=1e-12)
    with pytest.raises(InvalidDesignError, match=r"h1\(s\)"):
        solve(base.with_overrides(profile=CustomProfile(lambda s: s - 1.0)), 10)


@st.composite
def tendon_sets(draw, design):
    """One to three tendons inside the wall on either side, each with its routing, the last
    ones possibly anchored at a segment boundary short of the tip."""
    import dataclasses

    from tdcm_ros.model import Tendon

    ends = design.segment_ends()
    count = draw(st.integers(1, 3))
    tendons = tuple(
        Tendon(draw(st.floats(0.1, 0.99)) * design.R_outer * draw(st.sampled_from([1.0, -1.0])),
               routing=draw(st.sampled_from([None, "paper", "free"])),
               anchor=None if k == 0 else draw(st.sampled_from([None, *ends[:3].tolist()])))
        for k in range(count))
    return dataclasses.replace(design, R_c=abs(tendons[0].offset), tendons=tendons)


@settings(max_examples=60, suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(data=st.data(), design=hard_designs(), routing=st.sampled_from(["paper", "free"]),
       axial=st.sampled_from(["rigid", "compressible"]))
def test_several_tendons_pulling_against_each_other_converge_or_raise_a_typed_limit(
        data, design, routing, axial):
    """Issue 28's stability cases: tendons on both sides at any tensions up to 5 kN (cancelling
    ones among them), any routings and anchors, with or without axial compression."""
    body = data.draw(tendon_sets(design))
    tensions = data.draw(st.lists(st.floats(0.0, 5e3), min_size=len(body.tendons),
                                  max_size=len(body.tendons)))
    config = SolverSettings(routing=routing, axial=axial)
    try:
        first = solve(body, tensions, settings=config)
    except LIMITS as error:
        event(type(error).__name__)
        assert str(error)
        with pytest.raises(type(error)):
            solve(body, tensions, settings=config)
        return
    event("converged")
    assert first.converged and first.residual_history[-1] <= config.tol
    assert np.all(np.isfinite(first.positions)) and np.all(np.isfinite(first.theta))
    assert np.all(np.isfinite(first.tendon_lengths_m))
    assert np.array_equal(first.positions, solve(body, tensions, settings=config).positions)


@settings(max_examples=40, suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(design=hard_designs(), stroke=st.floats(0.0, 2e-2),
       stiffness=st.sampled_from([None, 1e3, 1e5]), slack=st.sampled_from([0.0, 1e-4]))
def test_a_stroke_input_finds_its_tension_or_raises_a_typed_error(design, stroke, stiffness,
                                                                  slack):
    """Stroke inputs over hard designs: the tension that pulls the actuator in by ``stroke``
    round-trips to 1e-9 m, or a typed error says why not (out of reach, a model limit)."""
    import dataclasses

    from tdcm_ros.model import Tendon, UnreachableTargetError, solve_inverse

    body = dataclasses.replace(design, tendons=(Tendon(design.R_c, stiffness=stiffness,
                                                       slack=slack),))
    try:
        found = solve_inverse(body, tendon_stroke=stroke, tol=1e-11)
    except (UnreachableTargetError, *LIMITS) as error:
        event(type(error).__name__)
        assert str(error)
        return
    event("found")
    assert 0.0 <= found.tension_n <= 50.0
    again = solve(body, found.tension_n)
    assert again.actuator_strokes_m[0] == pytest.approx(stroke, abs=1e-9)


@settings(max_examples=25, suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(design=hard_designs(), tension=st.floats(0.0, 5e3), onset=st.floats(1e-3, 0.05),
       ratio=st.floats(0.01, 1.0), routing=st.sampled_from(["paper", "free"]))
def test_a_superelastic_plateau_converges_or_raises_a_typed_limit(design, tension, onset,
                                                                   ratio, routing):
    """The plateau softens the notches up to 100x: still a finite converged shape, bent at
    least as far as the linear law's, or a typed limit."""
    import dataclasses

    from tdcm_ros.model.material import Material

    law = dataclasses.replace(design, material=Material("bilinear", onset, ratio * design.E))
    config = SolverSettings(routing=routing)
    try:
        result = solve(law, tension, settings=config)
    except LIMITS as error:
        event(type(error).__name__)
        assert str(error)
        return
    event("converged")
    assert result.converged and result.residual_history[-1] <= config.tol
    assert np.all(np.isfinite(result.positions)) and np.all(np.isfinite(result.theta))
    assert np.all(result.material_scale >= 1.0)
