"""Algorithm 1 on the presets: physics trends, limits, load forms and grid convergence."""

from itertools import pairwise

import numpy as np
import pytest
from scipy.integrate import quad

from tdcm_ros.model import (
    PRESETS,
    ConvergenceError,
    ModelError,
    NotchClosureError,
    SolverSettings,
    TendonSingularityError,
    TensionRangeError,
    preset,
    solve,
)
from tdcm_ros.model.baselines.shooting import ShootingOptions, solve_shooting_segmented
from tdcm_ros.model.section import notched_moment

REFERENCE = SolverSettings(cells_per_notch=128, cells_per_tube=16, quad_order=12, tol=1e-14)


def linear_tip_x(design, tension: float) -> float:
    """Small-angle solution from first principles: x(L) = R_c T int_0^L (L - s) / (E I(s)) ds,
    with I(s) from eqs. 12-13 written directly in s (independent of the solver's grid)."""
    length = design.length

    def compliance(s: float) -> float:
        left, right = design.notch_bounds()
        widths, backbones = design.per_notch("w_n"), design.per_notch("w_d")
        kinds = [p.name for p in design.notch_profiles()]
        for lo, hi, w_n, w_d, kind in zip(left, right, widths, backbones, kinds):
            if lo < s < hi:
                centre = 0.5 * (lo + hi)
                h1 = w_d / 2 if kind == "rectangular" else (w_n + w_d) / 2 - np.sqrt(
                    max((w_n / 2) ** 2 - (s - centre) ** 2, 0))
                return 1.0 / (design.E * float(notched_moment(h1, design.R_outer, design.r_inner)))
        return 1.0 / (design.E * design.tube_second_moment)

    breaks = sorted({0.0, length, *design.notch_bounds()[0], *design.notch_bounds()[1]})
    total = sum(quad(lambda s: (length - s) * compliance(s), a, b, limit=200, epsrel=1e-12)[0]
                for a, b in pairwise(breaks))
    return design.R_c * tension * total


def test_zero_tension_is_exactly_straight():
    result = solve(preset("paper-experiment"), 0.0)
    assert np.all(result.positions[:, 0] == 0.0)
    assert np.all(result.theta == 0.0)
    assert np.allclose(result.positions[:, 2], result.s, rtol=0, atol=1e-15)
    assert result.converged and result.tip_deflection_m == 0.0


#: A wrist with every notch different: widths, backbones (deeper toward the tip) and tubes,
#: two notches with no tube between them.
PER_NOTCH = preset("paper-experiment").with_overrides(
    w_n=[2.0e-3, 2.5e-3, 1.5e-3, 2.0e-3, 2.2e-3, 3.0e-3, 2.0e-3, 1.8e-3],
    w_d=[1.6e-3, 1.5e-3, 1.4e-3, 1.3e-3, 1.2e-3, 1.1e-3, 1.0e-3, 0.9e-3],
    w_t=[4e-3, 3e-3, 5e-3, 4e-3, 0.0, 4e-3, 2e-3])
#: The same with every other notch rectangular.
MIXED_PROFILES = PER_NOTCH.with_overrides(profile=["circular", "rectangular"] * 4)
CASES = {**PRESETS, "per-notch": PER_NOTCH, "mixed-profiles": MIXED_PROFILES}


@pytest.mark.parametrize("name", list(CASES))
def test_small_load_matches_linear_solution(name):
    design = CASES[name]
    tension = 1e-3
    expected = linear_tip_x(design, tension)
    # The default grid is within 1e-4 (the 1 um budget at 20 N); a fine grid matches closely.
    assert solve(design, tension).tip_position[0] == pytest.approx(expected, rel=1e-4)
    assert solve(design, tension, settings=REFERENCE).tip_position[0] == pytest.approx(
        expected, rel=1e-8)


@pytest.mark.parametrize("design", [PER_NOTCH, MIXED_PROFILES], ids=["per-notch", "mixed"])
@pytest.mark.parametrize("tension", [5.0, 10.0, 20.0])
def test_a_per_notch_body_matches_a_second_solver_to_a_tenth_of_a_micron(design, tension):
    # segmented shooting (scipy's ODE integrator, its own compliance per notch) on the fully
    # constrained tendon: the model difference from paper routing is tens of nm on the presets
    tight = ShootingOptions(rtol=1e-11, atol=1e-14)
    reference = solve_shooting_segmented(design, tension, options=tight).tip_position
    assert np.linalg.norm(solve(design, tension).tip_position - reference) < 0.1e-6


def test_deeper_cuts_toward_the_tip_bend_the_tip_first():
    angles = solve(PER_NOTCH.with_overrides(w_n=2e-3, w_t=4e-3), 10.0).notch_angles_rad
    assert np.all(np.diff(angles) > 0.0)
    uniform = solve(preset("paper-experiment"), 10.0).notch_angles_rad
    assert np.ptp(uniform) < 1e-12 * uniform[0]   # a uniform body bends every notch alike


def test_deflection_grows_with_tension_and_notch_width_and_falls_with_backbone():
    tensions = np.arange(0.0, 20.01, 2.0)
    for name in PRESETS:
        tips = [solve(preset(name), t).tip_deflection_m for t in tensions]
        assert np.all(np.diff(tips) > 0), name
    wn = [solve(preset(f"fig2-wn-{w}"), 20).tip_deflection_m for w in ("1", "1.9", "2.5")]
    wd = [solve(preset(f"fig3-wd-{w}"), 20).tip_deflection_m for w in ("1.2", "1.52", "2")]
    assert wn[0] < wn[1] < wn[2]
    assert wd[0] > wd[1] > wd[2]


@pytest.mark.parametrize("name", list(PRESETS))
def test_default_setting_within_one_micron_of_converged_reference(name):
    for tension in (4.0, 20.0):
        default = solve(preset(name), tension).tip_position
        reference = solve(preset(name), tension, settings=REFERENCE).tip_position
        assert np.linalg.norm(default - reference) < 1e-6


@pytest.fixture
def linear_chord_moments(monkeypatch):
    """Grids without their chord terms: the moment taken linear in every cell, chords too."""
    from tdcm_ros.model import grid as grid_module
    from tdcm_ros.model import grid_kernel

    integrals = grid_module._prototype_integrals

    def zero(*args):
        fc, fq, strain = integrals(*args)
        fc[:, [grid_kernel.C0_T, grid_kernel.C1_T]] = 0.0
        fq[:, [grid_kernel.A0_T, grid_kernel.A1_T]] = 0.0
        return fc, fq, strain

    monkeypatch.setattr(grid_module, "_prototype_integrals", zero)
    grid_module.clear_grid_cache()
    yield
    grid_module.clear_grid_cache()


def test_tip_converges_at_second_order_where_moments_vary_inside_cells(linear_chord_moments):
    # Free routing: the chord moment varies inside notch cells, linear in each cell -> O(h^2).
    design = preset("paper-experiment")
    base = {"routing": "free", "cells_per_tube": 4, "quad_order": 8, "tol": 1e-14}
    ref = solve(design, 20, settings=SolverSettings(cells_per_notch=512, **base)).tip_position
    errors = [np.linalg.norm(solve(design, 20, settings=SolverSettings(cells_per_notch=c, **base))
                             .tip_position - ref) for c in (16, 32, 64)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 1.7) & (orders < 2.5)), orders


def test_chord_terms_carry_the_bowing_chord_moment():
    # With the chord terms (m'' = -T c m inside a chord cell) the same free-routing grids err
    # far below the linear moment's O(h^2) (1.4e-7 m at 16 cells per notch).
    design = preset("paper-experiment")
    base = {"routing": "free", "cells_per_tube": 4, "quad_order": 8, "tol": 1e-14}
    ref = solve(design, 20, settings=SolverSettings(cells_per_notch=512, **base)).tip_position
    errors = [np.linalg.norm(solve(design, 20, settings=SolverSettings(cells_per_notch=c, **base))
                             .tip_position - ref) for c in (4, 8, 16)]
    assert errors[0] < 1e-9 and errors[1] < errors[0] / 4 and errors[2] < 1e-11, errors


def test_literal_loads_converge_to_closed_form_as_cells_refine():
    design = preset("paper-experiment")
    gaps = []
    for cells in (1, 2, 4, 8):
        st = SolverSettings(cells_per_notch=cells, cells_per_tube=cells, tol=1e-13)
        closed = solve(design, 20, settings=st).tip_position
        literal = solve(design, 20, settings=st.with_overrides(loads="literal")).tip_position
        gaps.append(np.linalg.norm(closed - literal))
    assert all(a > 4 * b for a, b in pairwise(gaps)), gaps
    assert gaps[-1] < 1e-9


def test_pose_at_agrees_with_nodes_and_quaternions_rotate_z_to_tangent():
    result = solve(preset("fig2-wn-2.5"), 20)
    positions, quats = result.pose_at(result.s)
    assert np.allclose(positions, result.positions, atol=1e-12)
    x, y, z, w = quats.T
    tangent_x = 2 * (x * z + w * y)
    tangent_z = 1 - 2 * (x * x + y * y)
    assert np.allclose(tangent_x, np.sin(result.theta)) and np.allclose(tangent_z,
                                                                        np.cos(result.theta))
    # Finite differences of pose_at give the tangent of the quaternion (away from cell
    # boundaries, where two quadratures meet with a ~1e-12 m mismatch).
    s = np.linspace(1e-3, result.design.length - 1e-3, 37)
    h = 1e-7
    s = s[np.min(np.abs(s[:, None] - result.s[None, :]), axis=1) > 10 * h]
    ahead, _ = result.pose_at(s + h)
    behind, _ = result.pose_at(s - h)
    _, q = result.pose_at(s)
    derivative = (ahead - behind) / (2 * h)
    assert np.allclose(derivative[:, 0], 2 * (q[:, 0] * q[:, 2] + q[:, 3] * q[:, 1]), atol=1e-6)


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf"), "abc", None])
def test_bad_tension_is_a_typed_error(bad):
    with pytest.raises(TensionRangeError) as info:
        solve(preset("paper-experiment"), bad)
    assert info.value.parameter == "tension"


def test_singularity_and_closure_are_typed():
    design = preset("paper-experiment")
    with pytest.raises(TendonSingularityError) as info:
        solve(design, 1000.0)
    assert info.value.rc_kappa >= 1.0
    # A rectangular notch bends uniformly, so its faces close before the tendon path cusps.
    with pytest.raises(NotchClosureError) as closure:
        solve(design.with_overrides(profile="rectangular"), 200.0)
    assert closure.value.gap_m <= 0.0 and 1 <= closure.value.notch <= design.N


def test_non_convergence_is_typed_and_keeps_a_finite_iterate():
    design = preset("paper-experiment").with_overrides(w_d=7.8e-3, E=1e7)
    tight = SolverSettings(max_iter=2, tol=1e-14, acceleration="none")
    with pytest.raises(ConvergenceError) as info:
        solve(design, 20.0, settings=tight)
    assert info.value.result is not None and not info.value.result.converged
    assert np.all(np.isfinite(info.value.result.positions))
    loose = solve(design, 20.0, settings=tight, strict=False)
    assert not loose.converged and len(loose.residual_history) == 2


def test_warm_start_reaches_the_same_shape():
    design = preset("paper-experiment").with_overrides(w_d=7.8e-3, E=1e7)
    cold = solve(design, 20.0)
    warm = solve(design, 21.0, warm_start=cold)
    again = solve(design, 21.0)
    assert np.allclose(warm.positions, again.positions, atol=1e-9)


def test_pose_at_reuses_a_grids_query_stations_without_changing_the_answer():
    """Repeated stations hit the grid's cache; the poses equal a fresh grid's to the bit."""
    from tdcm_ros.model.grid import QUERY_CACHE_SIZE

    design = preset("paper-experiment")
    first = solve(design, 12.0)
    stations = np.linspace(0.0, design.length, 54)
    before = first.pose_at(stations)
    second = solve(design, 20.0)                  # same cached grid, other moments
    assert second.grid is first.grid
    cached = second.pose_at(stations)
    first.grid._queries.clear()
    fresh = second.pose_at(stations)
    assert np.array_equal(cached[0], fresh[0]) and np.array_equal(cached[1], fresh[1])
    assert not np.allclose(before[0], cached[0])
    for k in range(QUERY_CACHE_SIZE + 3):         # bounded: old station sets are dropped
        second.pose_at(stations[: k + 2])
    assert len(second.grid._queries) == QUERY_CACHE_SIZE


ISSUE_13_DESIGN = {"w_base": 0.0, "w_tip": 0.00554, "w_n": 0.0088, "w_t": 0.0, "w_d": 1e-9,
                   "N": 33, "R_outer": 0.5, "r_inner": 0.0005, "R_c": 0.0005, "E": 1000.0,
                   "profile": "rectangular"}


@pytest.mark.parametrize("loads", ["literal", "closed"])
def test_issue_13_fuzz_case_raises_a_typed_error_without_lapack_noise(loads, capfd):
    """It raised numpy.linalg.LinAlgError with LAPACK's DLASCL complaint on stderr: the thin
    backbone's I cancelled to ~0 and NaN moments reached lstsq."""
    design = preset("paper-experiment").with_overrides(**ISSUE_13_DESIGN)
    with pytest.raises(ModelError):
        solve(design, 20.0, settings=SolverSettings(loads=loads))
    assert capfd.readouterr().err == ""


def test_anderson_with_a_non_finite_residual_never_calls_lapack(capfd):
    from tdcm_ros.model.solver import _anderson_step

    x = np.zeros(4)
    d_x: list[np.ndarray] = []
    d_f: list[np.ndarray] = []
    assert _anderson_step(x, np.ones(4), None, d_x, d_f, 5) is not None
    assert _anderson_step(x + 1.0, np.full(4, np.nan), (x, np.ones(4)), d_x, d_f, 5) is None
    assert capfd.readouterr().err == ""


def test_a_failing_least_squares_is_a_typed_convergence_error(monkeypatch):
    """A LinAlgError inside Anderson ends that strategy with a reason naming it; with
    ``strict=False`` the last finite iterate comes back, not converged."""
    def broken(*args, **kwargs):
        raise np.linalg.LinAlgError("SVD did not converge in Linear Least Squares")

    monkeypatch.setattr(np.linalg, "lstsq", broken)
    design = preset("paper-experiment").with_overrides(w_d=0.25e-3)
    anderson = SolverSettings(routing="free", acceleration="anderson")
    with pytest.raises(ConvergenceError, match="Anderson least squares failed"):
        solve(design, 0.5, settings=anderson)
    loose = solve(design, 0.5, settings=anderson, strict=False)
    assert not loose.converged and np.all(np.isfinite(loose.positions))


def test_strict_false_never_returns_nan(monkeypatch):
    """Without any finite iterate there is nothing to return: a typed error, not NaN."""
    from tdcm_ros.model import compiled, kernel

    integrate_row = kernel.integrate_row

    def poisoned(fc, fq, m_a, m_b, t, t_axis, p, theta, tangent):
        integrate_row(fc, fq, m_a, m_b, t, t_axis, p, theta, tangent)
        p[:] = np.nan
        theta[:] = np.nan

    monkeypatch.setitem(compiled._state, "build", compiled.PLAIN)  # poisoned below
    monkeypatch.setattr(kernel, "integrate_row", poisoned)
    with pytest.raises(ConvergenceError, match="no finite iterate") as info:
        solve(preset("paper-experiment"), 20.0, strict=False)
    assert info.value.result is None


@pytest.mark.parametrize("tension", ["20", True, False, None, np.bool_(True), 1 + 0j])
def test_tension_must_be_a_real_number(tension):
    with pytest.raises(TensionRangeError, match="tension") as info:
        solve(preset("paper-experiment"), tension)
    assert info.value.parameter == "tension" and info.value.allowed == "[0, inf) N"


@pytest.mark.parametrize("tension", [[20.0], (20,), np.array([20.0])])
def test_one_tension_per_tendon_is_the_tension_of_the_one_tendon(tension):
    design = preset("paper-experiment")
    assert np.array_equal(solve(design, tension).positions, solve(design, 20.0).positions)


@pytest.mark.parametrize(("tension", "parameter"), [([20.0, 5.0], "tension"),
                                                    (["20"], "tension[0]"),
                                                    ([-1.0], "tension[0]")])
def test_a_tension_list_must_have_one_real_tension_per_tendon(tension, parameter):
    with pytest.raises(TensionRangeError) as info:
        solve(preset("paper-experiment"), tension)
    assert info.value.parameter == parameter


@pytest.mark.parametrize("tension", [20, 20.0, np.float32(20.0), np.float64(20.0), np.int64(20)])
def test_numpy_and_python_numbers_are_tensions(tension):
    assert solve(preset("paper-experiment"), tension).tension_n == 20.0
