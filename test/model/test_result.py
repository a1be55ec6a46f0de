"""Per-notch outputs of a solve against references written here: the notch angle as the integral
of M/(E I) across the notch (adaptive quadrature in s, eq. 13 written in s), the face gaps from
the published poses, the closure angle of a uniformly bent notch, and the peak strain by dense
sampling."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from tdcm_ros.model import SolverSettings, preset, solve
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.design import Design
from tdcm_ros.model.grid_kernel import offset_section
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.section import notched_moment

DESIGNS = [preset("paper-experiment"),
           preset("fig3-wd-1.2").with_overrides(profile="rectangular", E=2.5e9)]


def half_width(design: Design, sigma: float) -> float:
    """``h1`` (m) at ``sigma`` (m) into a notch: eq. 13 in s for the circular notch."""
    if design.profile.name == "rectangular":
        return design.w_d / 2.0
    w_n = design.w_n
    return (w_n + design.w_d) / 2.0 - math.sqrt(max(sigma * (w_n - sigma), 0.0))


def moment_at(result: SolveResult, s: float) -> float:
    """The solution's bending moment (N m) at ``s``: linear inside each cell (paper routing)."""
    nodes = result.grid.s_nodes
    cell = min(int(np.searchsorted(nodes, s, side="right")) - 1, nodes.size - 2)
    xi = (s - nodes[cell]) / (nodes[cell + 1] - nodes[cell])
    m_a, m_b = result.cell_moments[cell]
    return float(m_a * (1.0 - xi) + m_b * xi)


def curvature_at(s: float, result: SolveResult, left: float) -> float:
    """Curvature (1/m) at ``s`` in the notch starting at ``left`` (m)."""
    d = result.design
    inertia = float(notched_moment(half_width(d, s - left), d.R_outer, d.r_inner))
    return moment_at(result, s) / (d.E * inertia)


def integrated_angles(result: SolveResult) -> list[float]:
    """Per notch: ``int M / (E I) ds`` across it by adaptive quadrature, split at the nodes."""
    left, right = result.design.notch_bounds()
    nodes = result.grid.s_nodes
    out = []
    for l_i, r_i in zip(left, right, strict=True):
        breaks = [l_i, *nodes[(nodes > l_i) & (nodes < r_i)], r_i]
        out.append(sum(quad(curvature_at, a, b, args=(result, l_i), epsabs=0.0,
                            epsrel=1e-12)[0] for a, b in itertools.pairwise(breaks)))
    return out


#: Relative error of a notch's compliance integral on the default grid (measured on
#: paper-experiment: 3.8e-8, falling to 3.5e-10 at 32 cells per notch; the rectangular notch's
#: constant section is integrated exactly).
DEFAULT_GRID_REL = 1e-7


@pytest.mark.parametrize("design", DESIGNS, ids=["paper-experiment", "rectangular"])
def test_notch_angles_are_the_curvature_integrated_across_each_notch(design: Design) -> None:
    result = solve(design, 12.0)
    np.testing.assert_allclose(result.notch_angles_rad, integrated_angles(result),
                               rtol=DEFAULT_GRID_REL)
    fine = solve(design, 12.0, settings=SolverSettings(cells_per_notch=32))
    np.testing.assert_allclose(fine.notch_angles_rad, integrated_angles(fine), rtol=1e-9)


def face_gaps(result: SolveResult) -> list[float]:
    """Per notch: the smaller signed distance of a face's surface corner (either side) from the
    other face, from the nodes' positions and tangent angles."""
    d, grid = result.design, result.grid
    out = []
    for left, right in zip(grid.notch_left_node, grid.notch_right_node, strict=True):
        gaps = []
        for side in (1.0, -1.0):
            corner = []
            tangents = []
            for node in (left, right):
                theta = result.theta[node]
                tangent = np.array([math.sin(theta), math.cos(theta)])  # (x, z)
                normal = np.array([math.cos(theta), -math.sin(theta)])  # toward +x at theta 0
                corner.append(result.positions[node, [0, 2]] + side * d.R_outer * normal)
                tangents.append(tangent)
            span = corner[1] - corner[0]
            gaps += [float(span @ tangents[0]), float(span @ tangents[1])]
        out.append(min(gaps))
    return out


@pytest.mark.parametrize("design", DESIGNS, ids=["paper-experiment", "rectangular"])
def test_notch_gaps_are_the_face_corners_distances(design: Design) -> None:
    result = solve(design, 12.0)
    np.testing.assert_allclose(result.notch_gaps_m, face_gaps(result), rtol=0.0, atol=1e-15)
    unloaded = solve(design, 0.0)
    np.testing.assert_allclose(unloaded.notch_gaps_m, design.w_n, rtol=1e-12)


def test_a_uniformly_bent_notch_stops_at_its_width_over_the_radius() -> None:
    """Rectangular notches under the paper routing's constant moment bend uniformly: the faces'
    outer corners meet at ``w_n / R_outer``."""
    design = DESIGNS[1]
    result = solve(design, 12.0)
    np.testing.assert_allclose(result.notch_stop_margins_rad + result.notch_angles_rad,
                               design.w_n / design.R_outer, rtol=1e-9)
    assert np.all(result.notch_stop_margins_rad > 0.0)


@pytest.mark.parametrize("design", DESIGNS, ids=["paper-experiment", "rectangular"])
def test_notch_peak_strains_are_the_largest_fibre_strain_in_each_notch(design: Design) -> None:
    result = solve(design, 12.0)
    left, _ = design.notch_bounds()
    want = []
    for l_i in left:
        s = np.linspace(l_i, l_i + design.w_n, 4001)
        strain = [abs(curvature_at(x, result, l_i)) * min(half_width(design, x - l_i),
                                                          design.R_outer) for x in s]
        want.append(max(strain))
    np.testing.assert_allclose(result.notch_peak_strains, want, rtol=1e-6)
    batch = solve_batch([design], np.array([[12.0]]))
    assert float(batch.max_bending_strain[0, 0]) == pytest.approx(
        float(np.max(result.notch_peak_strains)), rel=1e-12)


def test_the_json_summary_lists_every_notch_base_to_tip() -> None:
    design = preset("paper-experiment")
    summary = solve(design, 20.0).summary()
    for key in ("notch_angles_rad", "notch_gaps_m", "notch_stop_margins_rad",
                "notch_peak_strains"):
        assert len(summary[key]) == design.N, key
        assert all(math.isfinite(v) for v in summary[key]), key


def cell_pose_reference(result: SolveResult, s: float) -> tuple[complex, float]:
    """Tube-axis position (z + i x, m) and tangent angle (rad) at ``s`` by scipy's ODE solver
    from the start of its cell: the solution's end moments there taken linear along the cell
    (about the section's centroid, less ``T dx`` where the centroid moves off the line between
    the cell's end centroids), the section of eq. 13's half-width in s (by
    :func:`~tdcm_ros.model.grid_kernel.offset_section`, which ``test_off_axis_notches``
    checks against quadrature), and the axis stretching by ``x_bar kappa`` where the centroid
    is off it."""
    design, grid = result.design, result.grid
    nodes = grid.s_nodes
    cell = min(int(np.searchsorted(nodes, s, side="right")) - 1, nodes.size - 2)
    a, b = nodes[cell], nodes[cell + 1]
    left, right = design.notch_bounds()
    r_outer, r_inner = design.R_outer, design.r_inner

    def section(t: float) -> tuple[float, float]:
        """Centroid offset (m) and compliance 1/(E I) (1/(N m^2)) at arc length ``t``."""
        inside = np.flatnonzero((left <= t) & (t <= right))
        if not inside.size:
            return 0.0, 4.0 / (design.E * math.pi * (r_outer**4 - r_inner**4))
        k = int(inside[0])
        h1 = half_width(design, t - left[k])
        _, inertia, centroid, _ = offset_section(h1, design.per_notch("w_o")[k], r_outer,
                                                  r_inner)
        return centroid, 1.0 / (design.E * inertia)

    # a cell lies in one segment: its ends' sections are the limits from inside it
    x_a = section(a + 1e-12 * (b - a))[0]
    x_b = section(b - 1e-12 * (b - a))[0]
    m_a, m_b = result.bend_moments[cell]
    tension = result.tension_n

    def rhs(t: float, y: np.ndarray) -> list[float]:
        xi = (t - a) / (b - a)
        centroid, compliance = section(t)
        moved = centroid - ((1.0 - xi) * x_a + xi * x_b)
        kappa = compliance * ((1.0 - xi) * m_a + xi * m_b - tension * moved)
        stretch = 1.0 + centroid * kappa
        return [stretch * math.cos(y[2]), stretch * math.sin(y[2]), kappa]

    start = [result.positions[cell, 2], result.positions[cell, 0], result.theta[cell]]
    end = solve_ivp(rhs, (a, s), start, method="DOP853", rtol=1e-10, atol=1e-14).y[:, -1]
    return complex(end[0], end[1]), float(end[2])


@pytest.mark.parametrize("design", [
    preset("paper-experiment"),
    # one-sided circular cuts 5.6 mm deep: the centroid moves along each notch
    preset("paper-experiment").with_overrides(w_d=2 * 3.92e-3 - 5.6e-3, w_o=-2.8e-3)],
    ids=["symmetric", "one-sided"])
def test_poses_inside_cells_match_an_ode_solve_of_the_solutions_moments(design: Design
                                                                        ) -> None:
    """``pose_at`` between nodes: notch cells (their first, middle and last) and tube cells.
    Measured: 2e-14 m and 1.6e-10 rad (symmetric), 8.6e-12 m and 2.9e-9 rad (one-sided), the
    default grid's Gauss quadrature of a section that changes along the cell."""
    result = solve(design, 6.0)
    grid = result.grid
    notch_cells = np.flatnonzero(grid.is_notch)
    tube_cells = np.flatnonzero(~grid.is_notch)
    nodes = grid.s_nodes
    stations = np.array(
        [nodes[k] + f * (nodes[k + 1] - nodes[k]) for k in notch_cells[[0, len(notch_cells) // 2, -1]]
         for f in (0.37, 0.97)]
        + [nodes[k] + 0.61 * (nodes[k + 1] - nodes[k]) for k in tube_cells[[0, -1]]])
    positions, quaternions = result.pose_at(stations)
    theta = 2.0 * np.arctan2(quaternions[:, 1], quaternions[:, 3])
    for s, position, angle in zip(stations, positions, theta, strict=True):
        reference, reference_angle = cell_pose_reference(result, float(s))
        assert abs(complex(position[2], position[0]) - reference) <= 5e-11, s
        assert angle == pytest.approx(reference_angle, abs=1e-8), s


def tendon_path_length(result: SolveResult, points: int) -> float:
    """Length (m) of the tendon drawn from ``pose_at``: a polyline of ``points`` intervals on
    the curve ``R_c`` from the tube axis along each segment the tendon follows, a straight
    line between the segment's ends where it is a chord (the tubes under ``paper`` routing,
    the notches under ``free``)."""
    design = result.design
    left, right = design.notch_bounds()
    bounds = np.concatenate([[0.0], np.ravel(np.column_stack([left, right])), [design.length]])
    chords_in_notches = result.settings.routing == "free"

    def tendon(s: np.ndarray) -> np.ndarray:
        positions, quaternions = result.pose_at(s)
        theta = 2.0 * np.arctan2(quaternions[:, 1], quaternions[:, 3])
        return positions[:, 2] + 1j * positions[:, 0] + 1j * design.R_c * np.exp(1j * theta)

    total = 0.0
    for k, (a, b) in enumerate(itertools.pairwise(bounds)):
        if b <= a:
            continue
        in_notch = k % 2 == 1
        stations = np.array([a, b]) if in_notch == chords_in_notches else \
            np.linspace(a, b, points + 1)
        total += float(np.sum(np.abs(np.diff(tendon(stations)))))
    return total


@pytest.mark.parametrize("routing", ["paper", "free"])
@pytest.mark.parametrize("design", [
    preset("paper-experiment"),
    preset("paper-experiment").with_overrides(w_d=2 * 3.92e-3 - 5.6e-3, w_o=-2.8e-3)],
    ids=["symmetric", "one-sided"])
def test_the_tendon_length_is_its_drawn_path_to_a_nanometre(design: Design, routing: str
                                                            ) -> None:
    """Against polylines of 64 and 128 intervals a segment, extrapolated (Richardson: the
    polyline's error goes as h^2); and a straight body's tendon is as long as the body."""
    result = solve(design, 6.0, settings=SolverSettings(routing=routing))
    coarse, fine = tendon_path_length(result, 64), tendon_path_length(result, 128)
    reference = (4.0 * fine - coarse) / 3.0
    assert result.tendon_lengths_m == pytest.approx([reference], abs=1e-9)
    assert result.tendon_strokes_m == pytest.approx([design.length - reference], abs=1e-9)
    assert result.tendon_strokes_m[0] > 1e-4   # 0.2 mm at 6 N: pulled in, not a rounding
    straight = solve(design, 0.0, settings=SolverSettings(routing=routing))
    assert straight.tendon_strokes_m == pytest.approx([0.0], abs=1e-15)
