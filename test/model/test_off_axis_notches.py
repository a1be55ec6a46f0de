"""Notches whose backbone is off the tube axis (``Design.w_o``; one-sided cuts) against
references written independently of the package: the section by numerical quadrature, and
the shape by the second solver of :mod:`test.support.second_solver`."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tdcm_ros.model import solve
from tdcm_ros.model.baselines import solve_with
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.design import Design, preset
from tdcm_ros.model.errors import InvalidDesignError, TendonSingularityError
from tdcm_ros.model.grid_kernel import offset_section
from tdcm_ros.model.solver import DEFAULT_SETTINGS
from test.support.second_solver import reference_tip, strip_by_quadrature

MM = 1e-3


@settings(max_examples=60, deadline=None)
@example(r_outer=0.00390625, inner=0.875, backbone=0.875, side=1e-13)  # ends at the lumen's edge
@given(r_outer=st.floats(0.3 * MM, 5 * MM), inner=st.floats(0.0, 0.9),
       backbone=st.floats(0.05, 0.95), side=st.floats(-1.0, 1.0))
def test_the_offset_section_matches_quadrature_to_1e9(r_outer: float, inner: float,
                                                      backbone: float, side: float) -> None:
    r_inner = inner * r_outer
    h1 = backbone * r_outer
    offset = side * (r_outer - h1)
    area, inertia, x_bar, fibre = offset_section(h1, offset, r_outer, r_inner)
    lo, hi = max(offset - h1, -r_outer), min(offset + h1, r_outer)
    ref_area, ref_centroid, ref_inertia = strip_by_quadrature(lo, hi, r_outer, r_inner)
    assert area == pytest.approx(ref_area, rel=1e-9)
    assert inertia == pytest.approx(ref_inertia, rel=1e-9)
    assert x_bar == pytest.approx(ref_centroid, rel=1e-9, abs=1e-9 * r_outer)
    assert fibre == pytest.approx(max(hi - ref_centroid, ref_centroid - lo), rel=1e-9)


def one_sided(design: Design, depth: float | list[float]) -> Design:
    """``design`` with one-sided cuts of ``depth`` (m) from +x: w_d = 2 R - c, w_o = -c/2."""
    depths = np.atleast_1d(np.asarray(depth, dtype=float))
    return design.with_overrides(w_d=[2.0 * design.R_outer - c for c in depths] if depths.size > 1
                                 else 2.0 * design.R_outer - float(depths[0]),
                                 w_o=[-c / 2 for c in depths] if depths.size > 1
                                 else -float(depths[0]) / 2)


RECTANGULAR = preset("paper-experiment").with_overrides(profile="rectangular")


@pytest.mark.parametrize("tension", [2.0, 5.0])
@pytest.mark.parametrize("grid", ["uniform", "adaptive"])
def test_a_one_sided_cut_matches_the_centroid_line_solver_to_a_tenth_of_a_micron(
        grid: str, tension: float) -> None:
    design = one_sided(RECTANGULAR, 6.4 * MM)  # 6.4 of 7.84 mm: past the lumen, 1.44 mm left
    result = solve(design, tension, settings=DEFAULT_SETTINGS.with_overrides(grid=grid))
    tip, bends = reference_tip(design, tension)
    got = complex(result.positions[-1, 2], result.positions[-1, 0])
    assert abs(got - tip) <= 0.1e-6
    assert result.notch_angles_rad == pytest.approx(bends, abs=1e-9)
    # the published midline integrates the same stretched axis (unstretched: 0.1 mm off)
    assert float(np.max(np.abs(result.pose_at([design.length])[0][0] - result.positions[-1]))
                 ) <= 1e-9


def test_cuts_of_different_depths_and_sides_match_the_second_solver() -> None:
    base = RECTANGULAR.with_overrides(w_d=1.4 * MM)
    room = base.R_outer - 0.7 * MM
    design = base.with_overrides(w_o=[0.0, -room, -0.5 * room, room * 0.3, 0.0, -room, -room,
                                      0.0], w_d=[1.4 * MM] * 7 + [2.0 * MM])
    result = solve(design, 4.0)
    tip, bends = reference_tip(design, 4.0)
    assert abs(complex(result.positions[-1, 2], result.positions[-1, 0]) - tip) <= 0.1e-6
    assert result.notch_angles_rad == pytest.approx(bends, abs=1e-9)


@pytest.mark.parametrize("depth", [3.0 * MM, 6.4 * MM])
def test_a_circular_one_sided_cut_matches_the_axis_ode_to_a_tenth_of_a_micron(depth: float
                                                                            ) -> None:
    """A cut whose depth follows eq. 13's circle: its centroid moves along the notch, so the
    moment about it is not linear in a cell; the grid's correction for that (``D``, ``K2``)
    keeps the default grid within 0.1 um of the ODE (without it: 12 um at 6.4 mm, 2 N)."""
    design = one_sided(preset("paper-experiment"), depth)
    result = solve(design, 2.0)
    tip, bends = reference_tip(design, 2.0)
    assert abs(complex(result.positions[-1, 2], result.positions[-1, 0]) - tip) <= 0.1e-6
    assert result.notch_angles_rad == pytest.approx(bends, abs=1e-9)
    assert float(np.max(np.abs(result.pose_at([design.length])[0][0] - result.positions[-1]))
                 ) <= 1e-9


def test_the_symmetric_notch_is_the_reference_too_and_the_offset_bends_more() -> None:
    """The same second solver with w_o = 0 agrees with the paper's model (so what it checks
    above is the offset), and moving the backbone away from the tendon lengthens the arm."""
    tip, _ = reference_tip(RECTANGULAR, 5.0)
    result = solve(RECTANGULAR, 5.0)
    assert abs(complex(result.positions[-1, 2], result.positions[-1, 0]) - tip) <= 0.1e-6
    tips = [solve(RECTANGULAR.with_overrides(w_o=w_o), 5.0).tip_deflection_m
            for w_o in (0.0, -0.5 * MM, -1.5 * MM)]
    assert tips[0] < tips[1] < tips[2]


def test_a_one_sided_cut_closes_when_its_faces_meet_at_the_outer_surface() -> None:
    """The hard stop of a prismatic cut is w / (R_outer - x_bar) (the faces' corners, R_outer
    from the axis, are R_outer - x_bar from the neutral fibre)."""
    design = one_sided(RECTANGULAR, 6.4 * MM)
    result = solve(design, 1.0)
    _, _, x_bar, _ = offset_section(0.72 * MM, -3.2 * MM, design.R_outer, design.r_inner)
    expected = 2 * MM / (design.R_outer - x_bar)
    margins = result.notch_stop_margins_rad + result.notch_angles_rad
    assert margins == pytest.approx(np.full(design.N, expected), rel=1e-6)


@pytest.mark.parametrize(("overrides", "named"), [
    ({"w_o": -3.3 * MM}, "w_o"),
    ({"w_o": [0.0] * 7 + [3.3 * MM]}, "w_o[7]"),
])
def test_a_backbone_outside_the_tube_is_refused_naming_the_entry(overrides: dict[str, object],
                                                                 named: str) -> None:
    with pytest.raises(InvalidDesignError, match=rf"^{re.escape(named)} = .*R_outer - w_d/2"):
        preset("paper-experiment").with_overrides(**overrides)


@pytest.mark.parametrize("method", ["constant-curvature", "pseudo-rigid-body", "shooting-whole",
                                    "shooting-segmented"])
def test_the_baselines_refuse_an_off_axis_backbone_naming_w_o(method: str) -> None:
    """They model the paper's symmetric notch only; an answer for a cut would be wrong."""
    with pytest.raises(InvalidDesignError, match=rf"^w_o = .*the {method} baseline"):
        solve_with(method, one_sided(RECTANGULAR, 6.4 * MM), 2.0)


def test_the_tendon_singularity_takes_the_arm_from_the_centroid_in_solve_and_batch() -> None:
    """The tendon's path p + R_c n cusps where (R_c - x_bar) kappa = 1 under its own moment
    (R_c - x_bar) T: with the centroid 3 mm from the axis that is at a tension the paper's
    R_c kappa would still allow. solve and the batch refuse it alike; just below, both solve
    (or stop only at the notch closing, a limit of its own)."""
    design = one_sided(RECTANGULAR, 6.4 * MM)
    _, inertia, x_bar, _ = offset_section(0.72 * MM, -3.2 * MM, design.R_outer, design.r_inner)
    arm = design.R_c - x_bar
    cusp = design.E * inertia / arm**2  # N: (R_c - x_bar)^2 T / (E I) = 1
    assert design.R_c**2 * 1.01 * cusp / (design.E * inertia) < 1.0  # R_c alone would allow it
    with pytest.raises(TendonSingularityError):
        solve(design, 1.01 * cusp)
    batch = solve_batch([design, design], np.array([0.99 * cusp, 1.01 * cusp]))
    assert batch.status[1] == "singularity"
    assert batch.status[0] != "singularity"
