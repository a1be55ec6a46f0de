"""Eq. 12 in closed form against quadrature, and I(s) along the body."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from tdcm_ros.model import SolverSettings, preset
from tdcm_ros.model.grid import build_grid
from tdcm_ros.model.section import notched_moment, tube_moment


def quadrature_moment(h1: float, r_outer: float, r_inner: float) -> float:
    h2 = min(h1, r_inner)
    outer = quad(lambda y: y * y * np.sqrt(max(r_outer**2 - y * y, 0.0)), 0.0, min(h1, r_outer),
                 epsabs=0, epsrel=1e-12)[0]
    inner = quad(lambda y: y * y * np.sqrt(max(r_inner**2 - y * y, 0.0)), 0.0, h2,
                 epsabs=0, epsrel=1e-12)[0] if r_inner > 0 else 0.0
    return 4.0 * (outer - inner)


@settings(max_examples=200)
@given(r_outer=st.floats(1e-4, 0.05), inner_ratio=st.floats(0.0, 0.95),
       h_ratio=st.floats(0.01, 1.5))
def test_closed_form_matches_quadrature(r_outer, inner_ratio, h_ratio):
    r_inner = inner_ratio * r_outer
    h1 = h_ratio * r_outer
    expected = quadrature_moment(h1, r_outer, r_inner)
    assert float(notched_moment(h1, r_outer, r_inner)) == pytest.approx(expected, rel=1e-9,
                                                                        abs=1e-30)


def test_no_cut_equals_tube_and_is_continuous_in_h1():
    r_outer, r_inner = 3.92e-3, 1.55e-3
    assert float(notched_moment(r_outer, r_outer, r_inner)) == pytest.approx(
        tube_moment(r_outer, r_inner), rel=1e-14)
    assert float(notched_moment(2 * r_outer, r_outer, r_inner)) == pytest.approx(
        tube_moment(r_outer, r_inner), rel=1e-14)
    for h in (r_inner, r_outer):  # where h2 clips and where the cut vanishes
        below = float(notched_moment(h - 1e-12, r_outer, r_inner))
        above = float(notched_moment(h + 1e-12, r_outer, r_inner))
        assert abs(above - below) < 1e-6 * below  # a clipping jump would be ~10 %
    h = np.linspace(1e-5, r_outer, 500)
    assert np.all(np.diff(notched_moment(h, r_outer, r_inner)) > 0)


def test_stiffness_jumps_at_notch_edges_and_is_smooth_inside():
    design = preset("paper-experiment")
    grid = build_grid(design, SolverSettings(cells_per_notch=8))
    c0 = 1.0 / (design.E * design.tube_second_moment)
    first_notch = np.flatnonzero(grid.is_notch)[0]
    # Just inside the notch the section is much softer than the tube just outside.
    assert grid.c_start[first_notch] > 5 * c0
    assert grid.c_end[first_notch - 1] == pytest.approx(c0)
    # Inside a notch the compliance is continuous across cell boundaries.
    inside = np.flatnonzero(grid.is_notch[:-1] & grid.is_notch[1:] &
                            (grid.notch_index[:-1] == grid.notch_index[1:]))
    assert np.allclose(grid.c_end[inside], grid.c_start[inside + 1], rtol=1e-12)
    # The softest point is the notch centre, with h1 = w_d / 2.
    i_min = float(notched_moment(design.w_d / 2, design.R_outer, design.r_inner))
    assert grid.peak_c.max() == pytest.approx(1.0 / (design.E * i_min), rel=1e-12)


@pytest.mark.parametrize("ratio", [1e-12, 1e-6, 1e-3, 0.049, 0.051, 0.3])
def test_second_moment_of_a_thin_backbone_keeps_full_precision(ratio):
    """Issue 13: the closed form cancels for h << R (a 1 nm backbone in a 0.5 m tube gave a
    zero or negative I); the series keeps the relative error at rounding level."""
    radius = 0.5
    h = ratio * radius
    exact, _ = quad(lambda y: y * y * np.sqrt(radius * radius - y * y), 0.0, h,
                    epsabs=0.0, epsrel=1e-13)
    got = notched_moment(h, radius, 0.0) / 4.0
    assert got == pytest.approx(exact, rel=1e-13)
    hollow = notched_moment(h, radius, 0.5 * radius)
    assert hollow > 0.0
