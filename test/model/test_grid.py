"""Grid layouts: the adaptive default's boundaries and accuracy, and the many-design build."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from tdcm_ros.model import CustomProfile, SolverSettings, preset, solve
from tdcm_ros.model.accuracy import converged_tip
from tdcm_ros.model.design import MM
from tdcm_ros.model.errors import InvalidDesignError, InvalidSettingsError
from tdcm_ros.model.grid import (
    INTERPOLATED,
    NESTED,
    build_grid,
    build_grids,
    clear_grid_cache,
    gauss_legendre,
    partial_weights,
)
from tdcm_ros.model.grid_layout import PEAK_SAMPLES, Members
from tdcm_ros.model.section import notched_moment

PER_CELL = ("s_nodes", "is_notch", "notch_index", "shape", "seg_start", "seg_length", "u_a", "u_b",
            "constrained", "chord_start_node", "chord_end_node", "s_q", "w_q", "xi_q", "c_q",
            "C0", "C1", "A0", "A1", "A0_T", "A1_T", "C0_T", "C1_T", "c_start", "c_end", "peak_c",
            "peak_s")
PREVIOUS_DEFAULT = SolverSettings(grid="uniform", cells_per_notch=4, cells_per_tube=1,
                                  quad_order=4)


def circular_crossing(design, level):
    """``u`` in (0, 0.5) where eq. 13's ``h1`` equals ``level`` (m)."""
    return float(np.arcsin((design.w_n + design.w_d - 2.0 * level) / design.w_n) / np.pi)


def test_adaptive_boundaries_include_the_r_inner_crossings():
    design = preset("paper-experiment")
    grid = build_grid(design, SolverSettings())
    u_star = circular_crossing(design, design.r_inner)
    assert 0.0 < u_star < 0.5
    for i, (left, right) in enumerate(zip(*design.notch_bounds())):
        cells = np.flatnonzero(grid.notch_index == i)
        bounds = np.append(grid.u_a[cells], grid.u_b[cells[-1]])
        for u in (u_star, 1.0 - u_star):
            assert np.min(np.abs(bounds - u)) <= 1e-15
            s = left + design.profile.sigma(np.array(u), design.w_n)
            assert np.min(np.abs(grid.s_nodes - s)) <= 1e-15
        h1 = design.profile.h1(bounds, design.w_n, design.w_d)
        assert np.sum(np.isclose(h1, design.r_inner, rtol=1e-14, atol=0.0)) == 2
    uniform = build_grid(design, SolverSettings(grid="uniform"))
    assert np.min(np.abs(uniform.u_a - u_star)) > 1e-3


def test_adaptive_boundaries_include_the_r_outer_crossings():
    # (w_n + w_d)/2 = 4.2 mm > R_outer: the cut vanishes near the notch edges.
    design = preset("paper-experiment").with_overrides(w_n=6.0 * MM, w_d=2.4 * MM)
    grid = build_grid(design, SolverSettings())
    cells = np.flatnonzero(grid.notch_index == 0)
    bounds = np.append(grid.u_a[cells], grid.u_b[cells[-1]])
    for level in (design.r_inner, design.R_outer):
        u = circular_crossing(design, level)
        assert np.min(np.abs(bounds - u)) <= 1e-15
        assert np.min(np.abs(bounds - (1.0 - u))) <= 1e-15


def test_custom_profile_crossings_are_found_by_search():
    circular = preset("paper-experiment")
    w_n, w_d = circular.w_n, circular.w_d

    def h1(sigma):
        return 0.5 * (w_n + w_d) - np.sqrt(np.maximum(sigma * (w_n - sigma), 0.0))

    custom = circular.with_overrides(profile=CustomProfile(h1))
    grid = build_grid(custom, SolverSettings())
    cells = np.flatnonzero(grid.notch_index == 0)
    bounds = np.append(grid.u_a[cells], grid.u_b[cells[-1]])
    # The custom profile's u is sigma / w_n; the crossing is where sigma (w_n - sigma) =
    # ((w_n + w_d)/2 - r_inner)^2.
    depth = 0.5 * (w_n + w_d) - circular.r_inner
    sigma = 0.5 * (w_n - np.sqrt(w_n**2 - 4.0 * depth**2))
    for u in (sigma / w_n, 1.0 - sigma / w_n):
        assert np.min(np.abs(bounds - u)) <= 1e-12


def test_rectangular_notches_have_no_crossings():
    design = preset("paper-experiment").with_overrides(profile="rectangular")
    grid = build_grid(design, SolverSettings(routing="free"))
    # Chord notches: cells_per_notch equal cells, no extra boundary.
    cells = np.flatnonzero(grid.notch_index == 0)
    assert np.allclose(np.diff(grid.u_a[cells]), 1.0 / cells.size, rtol=1e-12)


@pytest.mark.parametrize("w_d", [1.1e-3, 1.1e-3 * (1 + 1e-12), 1.1e-3 * (1 - 1e-12)])
def test_a_crossing_at_a_notch_edge_leaves_no_sliver_cell(w_d):
    # h1 at the notch's ends, (w_n + w_d)/2, equals r_inner to rounding: a crossing there would
    # cut a piece with no length in s (once a non-finite solve); the kink is at the edge
    design = preset("paper-experiment").with_overrides(w_d=w_d, r_inner=1.55e-3)
    grid = build_grid(design, SolverSettings())
    assert np.all(grid.length > 0.0)
    fine = solve(design, 10.0, settings=SolverSettings(grid="uniform", cells_per_notch=128))
    assert np.linalg.norm(solve(design, 10.0).tip_position - fine.tip_position) < 0.1e-6


@pytest.mark.parametrize("loads", ["closed", "literal"])
@pytest.mark.parametrize("name", ["paper-experiment", "fig3-wd-1.2", "fig2-wn-1"])
@pytest.mark.parametrize("notches", [1, 8, 64])
def test_default_grid_is_within_0p1_um_under_paper_routing(name, notches, loads):
    design = preset(name).with_overrides(N=notches)
    reference, uncertainty = converged_tip(design, 20.0, "paper", loads)
    assert uncertainty < 1e-8
    tip = solve(design, 20.0, settings=SolverSettings(loads=loads)).tip_position
    assert np.linalg.norm(tip - reference) < 1e-7


@pytest.mark.parametrize("loads", ["closed", "literal"])
@pytest.mark.parametrize("name", ["paper-experiment", "fig3-wd-1.2", "fig2-wn-1"])
@pytest.mark.parametrize("notches", [1, 8, 64])
def test_default_grid_is_within_0p1_um_under_free_routing(name, notches, loads):
    # The chord terms carry the chord moment's bow, so free routing needs no extra cells.
    design = preset(name).with_overrides(N=notches)
    reference, uncertainty = converged_tip(design, 20.0, "free", loads)
    assert uncertainty < 1e-8
    tip = solve(design, 20.0, settings=SolverSettings(routing="free", loads=loads)).tip_position
    assert np.linalg.norm(tip - reference) < 1e-7


@pytest.mark.parametrize("notches", [1, 8, 64])
def test_default_grid_improves_free_routing_several_fold(notches):
    # Free routing's chord moments are linear per cell (second order): the default does not
    # reach 0.1 um there (see bench/grid_accuracy.py), but it errs far less than before.
    design = preset("paper-experiment").with_overrides(N=notches)
    reference, _ = converged_tip(design, 20.0, "free", "closed")
    errors = [np.linalg.norm(solve(design, 20.0, settings=s.with_overrides(routing="free"))
                             .tip_position - reference)
              for s in (SolverSettings(), PREVIOUS_DEFAULT)]
    assert errors[0] < errors[1] / 8.0


designs_strategy = st.builds(
    lambda n, w_n, w_d, w_t, w_base, w_tip, r_inner, profile: preset(
        "paper-experiment").with_overrides(N=n, w_n=w_n * MM, w_d=w_d * MM, w_t=w_t * MM,
                                           w_base=w_base * MM, w_tip=w_tip * MM,
                                           r_inner=r_inner * MM, profile=profile),
    st.integers(1, 12), st.floats(0.5, 6.0), st.floats(0.3, 7.0),
    st.sampled_from([0.0, 0.05, 4.0]), st.sampled_from([0.0, 5.0]),
    st.sampled_from([0.0, 4.0]), st.sampled_from([0.0, 0.8, 1.55]),
    st.sampled_from(["circular", "rectangular"]))
#: Per-notch designs: each notch its own width, backbone and profile from a few values (so some
#: repeat), each gap its own tube (some none).
per_notch_strategy = st.integers(2, 8).flatmap(lambda n: st.builds(
    lambda w_n, w_d, w_t, profile: preset("paper-experiment").with_overrides(
        N=n, w_n=[v * MM for v in w_n], w_d=[v * MM for v in w_d], w_t=[v * MM for v in w_t],
        profile=profile),
    st.lists(st.sampled_from([0.5, 2.0, 3.5]), min_size=n, max_size=n),
    st.lists(st.sampled_from([0.6, 1.4, 3.0]), min_size=n, max_size=n),
    st.lists(st.sampled_from([0.0, 0.05, 4.0]), min_size=n - 1, max_size=n - 1),
    st.lists(st.sampled_from(["circular", "rectangular"]), min_size=n, max_size=n)))


@settings(max_examples=25, suppress_health_check=[HealthCheck.too_slow])
@given(designs=st.lists(st.one_of(designs_strategy, per_notch_strategy), min_size=1,
                        max_size=6),
       routing=st.sampled_from(["paper", "free"]), kind=st.sampled_from(["adaptive", "uniform"]),
       quad_order=st.integers(2, 6))
def test_many_design_build_equals_each_single_build_bit_for_bit(designs, routing, kind,
                                                               quad_order):
    cfg = SolverSettings(routing=routing, grid=kind, quad_order=quad_order)
    stack = build_grids(designs, cfg, partials=NESTED)
    width = int(stack.n_cells.max())
    for m, design in enumerate(designs):
        grid = build_grid(design, cfg)
        n = grid.n_cells
        assert stack.n_cells[m] == n
        for name in PER_CELL:
            single = getattr(grid, name)
            stacked = getattr(stack, name)[m][:single.shape[0]]
            assert stacked.dtype == single.dtype and stacked.tobytes() == single.tobytes(), name
        assert np.array_equal(stack.notch_left_node[m, :design.N], grid.notch_left_node)
        assert np.array_equal(stack.notch_right_node[m, :design.N], grid.notch_right_node)
        # Padding: zero-length cells at the tip that carry nothing.
        pad = slice(n, width)
        assert np.all(stack.s_nodes[m, n:] == design.length)
        for name in ("C0", "C1", "A0", "A1", "w_q", "c_q", "A0_T", "C1_T"):
            assert not np.any(getattr(stack, name)[m, pad])
        assert np.all(stack.constrained[m, pad]) and not np.any(stack.is_notch[m, pad])
        assert np.all(stack.notch_left_node[m, design.N:] == n)
    assert np.array_equal(stack.gauss_u, build_grid(designs[0], cfg).gauss_u)


@settings(max_examples=25, deadline=None)
@given(designs=st.lists(st.builds(
    lambda n, w_n, w_d, w_o, r_inner: preset("paper-experiment").with_overrides(
        N=n, w_n=w_n * MM, w_d=w_d * MM, w_o=min(w_o, 1.95 - w_d / 2) * MM,
        r_inner=r_inner * MM),
    st.integers(1, 9), st.floats(0.5, 3.0), st.floats(0.3, 3.8),
    st.sampled_from([0.0, 0.2, 0.8, 1.9]), st.sampled_from([0.0, 1.55])), min_size=1,
    max_size=5))
def test_members_of_uniform_designs_equal_each_designs_own_faces_and_length(designs):
    members = Members.of(designs)  # the vectorised uniform layout
    for m, design in enumerate(designs):
        assert members.length[m] == design.length
        faces = members.notch_open[m]
        assert np.array_equal(faces[:, :design.N], design.open_faces())
        assert not np.any(faces[:, design.N:])


def test_many_design_build_with_mixed_custom_profiles():
    base = preset("paper-experiment")
    designs = [base, base.with_overrides(profile=CustomProfile(lambda s: 0.0 * s + 1.0 * MM)),
               base.with_overrides(N=3, profile="rectangular")]
    stack = build_grids(designs, SolverSettings(), partials=NESTED)
    for m, design in enumerate(designs):
        grid = build_grid(design, SolverSettings())
        assert stack.A0[m, :grid.n_cells].tobytes() == grid.A0.tobytes()


@pytest.mark.parametrize("quad_order", range(1, 33))
def test_interpolated_partial_weights_are_exact_and_do_not_amplify_rounding(quad_order):
    weights, index = partial_weights(quad_order)
    gauss_u, _ = gauss_legendre(quad_order)
    nodes = np.concatenate([gauss_u, np.linspace(0.0, 1.0, PEAK_SAMPLES)])[index]
    assert np.array_equal(index[:quad_order], np.arange(quad_order))  # every Gauss point
    degree = index.size - 1
    assert degree >= min(2 * quad_order - 1, 8)  # at least the nested rule's, up to 8
    assert np.max(np.sum(np.abs(weights), axis=1)) < 8.0
    for power in (0, degree // 2, degree):  # int_0^u x^p dx, polynomial of the rule's degree
        np.testing.assert_allclose(weights @ nodes**power, gauss_u**(power + 1) / (power + 1),
                                   rtol=0.0, atol=1e-13)


def circular_integrand(design, grid, cell):
    """``(1 - xi) c ds/du`` and ``xi c ds/du`` (1/(N m)) of a notch cell of eq. 13's profile,
    written out here (eq. 12's section by :func:`notched_moment`) as functions of ``u``."""
    w_n, w_d = design.w_n, design.w_d
    start = grid.s_nodes[cell] - grid.seg_start[cell]

    def parts(u):
        sigma = 0.5 * w_n * (1.0 - np.cos(np.pi * u))
        jac = 0.5 * w_n * np.pi * np.sin(np.pi * u)
        h1 = 0.5 * (w_n + w_d) - 0.5 * w_n * np.sin(np.pi * u)
        c = 1.0 / (design.E * float(notched_moment(h1, design.R_outer, design.r_inner)))
        xi = (sigma - start) / grid.length[cell]
        return (1.0 - xi) * c * jac, xi * c * jac
    return parts


@settings(max_examples=12, deadline=None)
@given(w_n=st.floats(0.8, 3.0), w_d=st.floats(0.6, 2.0), quad_order=st.sampled_from([4, 6, 8]))
def test_interpolated_partial_integrals_are_as_accurate_as_nested_against_scipy(
        w_n, w_d, quad_order):
    design = preset("paper-experiment").with_overrides(N=1, w_n=w_n * MM, w_d=w_d * MM)
    cfg = SolverSettings(quad_order=quad_order)
    rules = {rule: build_grids([design], cfg, partials=rule) for rule in (NESTED, INTERPOLATED)}
    grid = build_grid(design, cfg)
    errors = {rule: 0.0 for rule in rules}  # relative to the cell's compliance int c ds
    for cell in np.flatnonzero(grid.is_notch):
        parts = circular_integrand(design, grid, cell)
        u_a, u_b = grid.u_a[cell], grid.u_b[cell]
        whole = grid.C0[cell] + grid.C1[cell]
        for q, g in enumerate(gauss_legendre(quad_order)[0]):
            for row, name in ((0, "A0"), (1, "A1")):
                expected = quad(lambda u, row=row, f=parts: f(u)[row], u_a, u_a + (u_b - u_a) * g,
                                epsabs=0.0, epsrel=1e-13, limit=200)[0]
                for rule, stack in rules.items():
                    got = getattr(stack, name)[0, cell, q]
                    errors[rule] = max(errors[rule], abs(got - expected) / whole)
    assert errors[INTERPOLATED] <= max(2.0 * errors[NESTED], 1e-12), errors


def test_many_design_build_rejects_bad_input_naming_it():
    with pytest.raises(InvalidDesignError, match="number of designs = 0"):
        build_grids([], SolverSettings())
    with pytest.raises(InvalidSettingsError, match="partials = 'gauss'"):
        build_grids([preset("paper-experiment")], SolverSettings(), partials="gauss")
    soft = preset("paper-experiment").with_overrides(E=1e-300)
    with pytest.raises(InvalidDesignError, match="E\\*I") as info:
        build_grids([preset("paper-experiment"), soft], SolverSettings())
    assert "1e-300" in str(info.value)
    with pytest.raises(InvalidSettingsError, match="grid"):
        SolverSettings(grid="graded")


def test_chord_terms_in_a_tube_match_the_closed_form():
    # Constant c over a cell of length h: G0 = c h^2 (xi/3 - xi^2/2 + xi^3/6) and
    # G1 = c h^2 (xi/6 - xi^3/6), so C0_T = C1_T = c^2 h^3 / 24, A0_T(xi) = c^2 h^3 (xi^2/6 -
    # xi^3/6 + xi^4/24) and A1_T(xi) = c^2 h^3 (xi^2/12 - xi^4/24).
    design = preset("paper-experiment")
    grid = build_grid(design, SolverSettings(routing="paper"))
    tubes = np.flatnonzero(~grid.is_notch)
    assert np.all(np.isin(tubes, grid.chord_cells))
    c = 1.0 / (design.E * design.tube_second_moment)
    h = grid.length[tubes]
    xi = grid.xi_q[tubes]
    assert np.allclose(grid.C0_T[tubes], c**2 * h**3 / 24.0, rtol=1e-12, atol=0.0)
    assert np.allclose(grid.C1_T[tubes], c**2 * h**3 / 24.0, rtol=1e-12, atol=0.0)
    scale = (c**2 * h**3)[:, None]
    assert np.allclose(grid.A0_T[tubes], scale * (xi**2 / 6 - xi**3 / 6 + xi**4 / 24),
                       rtol=1e-11, atol=0.0)
    assert np.allclose(grid.A1_T[tubes], scale * (xi**2 / 12 - xi**4 / 24), rtol=1e-11,
                       atol=0.0)
    # Where the tendon follows the body (the notches, under paper routing) there is no term.
    notch = np.flatnonzero(grid.is_notch)
    assert not np.any(grid.C0_T[notch]) and not np.any(grid.A1_T[notch])


def test_chord_terms_in_a_notch_match_a_fine_trapezoid_integration():
    design = preset("paper-experiment")
    grid = build_grid(design, SolverSettings(routing="free"))
    for k in grid.chord_cells[grid.is_notch[grid.chord_cells]][:6]:
        u = np.linspace(grid.u_a[k], grid.u_b[k], 20001)
        s = grid.seg_start[k] + design.profile.sigma(u, design.w_n)
        h1 = design.profile.h1(u, design.w_n, design.w_d)
        c = 1.0 / (design.E * notched_moment(h1, design.R_outer, design.r_inner))
        xi = (s - s[0]) / (s[-1] - s[0])

        def cumulative(f, s=s):
            return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(s))])

        for shape, c_t, a_t in ((1.0 - xi, grid.C0_T, grid.A0_T), (xi, grid.C1_T, grid.A1_T)):
            inner = cumulative(cumulative(c * shape))
            g = xi * inner[-1] - inner
            total = cumulative(c * g)
            assert c_t[k] == pytest.approx(total[-1], rel=1e-6)
            assert np.allclose(a_t[k], np.interp(grid.s_q[k], s, total), rtol=1e-5)


def test_the_last_grid_is_kept_by_design_and_settings_and_cleared_with_the_cache() -> None:
    design = preset("paper-experiment")
    equal = preset("paper-experiment").with_overrides(E=design.E)   # equal, not the same object
    settings = SolverSettings()
    grid = build_grid(design, settings)
    assert build_grid(design, settings) is grid and build_grid(equal, settings) is grid
    finer = build_grid(design, SolverSettings(cells_per_notch=8))
    assert finer is not grid and finer.n_cells > grid.n_cells
    assert build_grid(design, settings) is grid
    clear_grid_cache()
    rebuilt = build_grid(design, settings)
    assert rebuilt is not grid and np.array_equal(rebuilt.s_nodes, grid.s_nodes)
