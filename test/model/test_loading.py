"""Loading: varying tension, external loads and notch contact inside Algorithm 1."""

from itertools import pairwise

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from tdcm_ros.errors import InputError
from tdcm_ros.model import (
    PRESETS,
    ConvergenceError,
    ModelLimitError,
    NotchClosureError,
    SolverSettings,
    TendonSingularityError,
    preset,
    solve,
)
from tdcm_ros.model.grid import build_grid
from tdcm_ros.model.kinematics import integrate
from tdcm_ros.model.limits import closure_angles
from tdcm_ros.model.loading import (
    Capstan,
    InvalidLoadingError,
    LoadedModel,
    Loading,
    NotchContact,
)
from tdcm_ros.model.section import notched_area, notched_moment, tube_area
from tdcm_ros.model.solver import _continuation, _Problem

RHO_G = 1010.0 * 9.81  # N/m^3, Nylon 12 under 1 g
TIGHT = SolverSettings(tol=1e-14, max_iter=400)
FINE = SolverSettings(cells_per_notch=32, cells_per_tube=32, quad_order=8, tol=1e-14,
                      max_iter=400)
HYPO = settings(max_examples=25, suppress_health_check=[HealthCheck.too_slow])


def constant(s, wrap, tension):
    return np.full_like(s, tension)


def compliance_function(design):
    """``1/(E I(s))`` written directly in ``s`` (eqs. 12-13), independent of the grid."""
    left, right = design.notch_bounds()

    def compliance(s: float) -> float:
        for lo, hi in zip(left, right, strict=True):
            if lo < s < hi:
                half = design.w_n / 2
                h1 = (design.w_n + design.w_d) / 2 - np.sqrt(max(half**2 - (s - lo - half) ** 2, 0))
                return 1.0 / (design.E * float(notched_moment(h1, design.R_outer, design.r_inner)))
        return 1.0 / (design.E * design.tube_second_moment)

    breaks = sorted({0.0, design.length, *left, *right})
    return compliance, list(pairwise(breaks))


def linear_tip_x(design, weight) -> float:
    """Small-deflection tip x (m): ``int_0^L (L - s) m(s) / (E I(s)) ds`` for a moment ``m(s)``."""
    compliance, pieces = compliance_function(design)
    length = design.length
    return sum(quad(lambda s: (length - s) * weight(s) * compliance(s), a, b, limit=200,
                    epsrel=1e-12)[0] for a, b in pieces)


# --- section area ----------------------------------------------------------------------------

@HYPO
@given(h1=st.floats(1e-5, 5e-3), r_inner=st.floats(0.0, 3e-3))
def test_notched_area_matches_quadrature(h1, r_inner):
    r_outer = 3.92e-3
    outer = quad(lambda y: 2 * np.sqrt(max(r_outer**2 - y**2, 0)), -min(h1, r_outer),
                 min(h1, r_outer), epsabs=1e-14)[0]
    h2 = min(h1, r_inner)
    inner = quad(lambda y: 2 * np.sqrt(max(r_inner**2 - y**2, 0)), -h2, h2, epsabs=1e-14)[0]
    assert float(notched_area(h1, r_outer, r_inner)) == pytest.approx(outer - inner, rel=1e-9,
                                                                      abs=1e-15)


def test_area_of_uncut_notch_is_the_tube():
    assert float(notched_area(5e-3, 3.92e-3, 1.55e-3)) == pytest.approx(
        tube_area(3.92e-3, 1.55e-3), rel=1e-14)


# --- identity with the base model ------------------------------------------------------------

@HYPO
@given(name=st.sampled_from(list(PRESETS)), tension=st.floats(0.0, 20.0),
       routing=st.sampled_from(["paper", "free"]))
def test_empty_loading_is_the_base_model(name, tension, routing):
    cfg = SolverSettings(routing=routing)
    base = solve(preset(name), tension, settings=cfg)
    same = solve(preset(name), tension, settings=cfg, loading=Loading())
    assert np.array_equal(base.positions, same.positions)
    assert np.array_equal(base.cell_moments, same.cell_moments)


@HYPO
@given(name=st.sampled_from(list(PRESETS)), tension=st.floats(0.0, 20.0),
       routing=st.sampled_from(["paper", "free"]), cells=st.sampled_from([1, 4, 9]))
def test_constant_profile_is_the_base_model(name, tension, routing, cells):
    cfg = SolverSettings(routing=routing, cells_per_notch=cells, cells_per_tube=cells)
    base = solve(preset(name), tension, settings=cfg)
    varying = solve(preset(name), tension, settings=cfg, loading=Loading(tension_profile=constant))
    assert np.max(np.abs(varying.positions - base.positions)) <= 1e-12
    assert np.array_equal(varying.tendon_tension, np.full(base.s.shape, tension))


# --- varying tension -------------------------------------------------------------------------

@pytest.mark.parametrize("routing", ["paper", "free"])
def test_tension_lost_along_s_deflects_less(routing):
    design = preset("paper-experiment")
    cfg = SolverSettings(routing=routing)
    base = solve(design, 20.0, settings=cfg)
    friction = solve(design, 20.0, settings=cfg, loading=Loading(tension_profile=Capstan(0.2)))
    linear = solve(design, 20.0, settings=cfg, loading=Loading(
        tension_profile=lambda s, w, t: t * (1.0 - 0.5 * s / s[-1])))
    unloading = solve(design, 20.0, settings=cfg,
                      loading=Loading(tension_profile=Capstan(0.2, unloading=True)))
    assert friction.tip_position[0] < base.tip_position[0] < unloading.tip_position[0]
    assert linear.tip_position[0] < friction.tip_position[0]
    # The capstan loss follows the tendon's turning: exp(-mu * wrap) at the tip.
    assert np.all(np.diff(friction.tendon_tension) <= 0.0)
    assert friction.tendon_tension[-1] < 20.0 * np.exp(-0.2 * 0.9 * friction.tip_angle_rad)


@pytest.mark.parametrize("routing", ["paper", "free"])
def test_chord_tension_is_constant_along_the_chord(routing):
    design = preset("paper-experiment")
    cfg = SolverSettings(routing=routing, cells_per_tube=4, cells_per_notch=4)
    seen = []

    def falling(s, wrap, tension):
        return tension * (1.0 - 0.5 * s / s[-1])

    def recording(s, wrap, tension):
        seen.append(wrap.copy())
        return falling(s, wrap, tension)

    loading = Loading(tension_profile=recording)
    result = solve(design, 20.0, settings=cfg, loading=loading)
    grid = result.grid
    model = LoadedModel(grid, loading, 20.0)
    shape = integrate(grid, result.cell_moments[:, 0], result.cell_moments[:, 1])
    t_a, t_b = model.cell_tensions(shape, 20.0)
    chords = grid.chord_cells
    start = grid.chord_start_node[chords]
    # Every cell of a chord carries the tension just past the chord's proximal node...
    assert np.array_equal(t_a[chords], t_b[chords])
    assert np.array_equal(t_a[chords], falling(grid.s_nodes, None, 20.0)[start])
    # ...while on the offset curve the tension follows the profile node by node.
    on_curve = grid.constrained_cells
    assert np.array_equal(t_b[on_curve], falling(grid.s_nodes, None, 20.0)[on_curve + 1])
    assert np.all(np.diff(t_a) <= 0.0)
    # The wrap angle never decreases along the tendon.
    assert all(np.all(np.diff(w) >= 0.0) for w in seen)


def vertex_force_moments(result, mu, samples):
    """Node moments (N m; cell starts and ends) of a polyline tendon's vertex forces on the body.

    The tendon is sampled densely on the offset curve and straight on chords; its tension drops
    by ``exp(-mu * turning)`` at each vertex (capstan), so every vertex force has a friction
    (tangential) part. Independent of the closed form: forces summed beyond each cut.
    """
    grid, design = result.grid, result.design
    vertices, where = [], []
    for k in range(grid.n_cells):
        if grid.constrained[k]:
            s = np.linspace(grid.s_nodes[k], grid.s_nodes[k + 1], samples + 1)
        elif grid.chord_start_node[k] == k:
            s = grid.s_nodes[[k, grid.chord_end_node[k]]]
        else:
            continue
        pos, quat = result.pose_at(s)
        theta = 2 * np.arctan2(quat[:, 1], quat[:, 3])
        tendon = np.stack([pos[:, 0] + design.R_c * np.cos(theta),
                           pos[:, 2] - design.R_c * np.sin(theta)], axis=1)
        first = 1 if vertices else 0
        vertices.extend(tendon[first:])
        where.extend(s[first:])
    q, where = np.array(vertices), np.array(where)
    u = np.diff(q, axis=0)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    u_in = np.vstack([[0.0, 1.0], u])  # arriving direction; +z at the base
    turn = np.abs(np.arctan2(u_in[:-1, 0] * u[:, 1] - u_in[:-1, 1] * u[:, 0],
                             np.sum(u_in[:-1] * u, axis=1)))
    tension = result.tension_n * np.exp(-mu * np.cumsum(turn))
    pull_out = np.vstack([u * tension[:, None], [[0.0, 0.0]]])
    force = pull_out - u_in * np.concatenate([[result.tension_n], tension])[:, None]
    p = result.positions[:, [0, 2]]

    def moment(node, inclusive):
        s = grid.s_nodes[node]
        beyond = where >= s - 1e-15 if inclusive else where > s
        arm = q[beyond] - p[node]
        return np.sum(arm[:, 1] * force[beyond, 0] - arm[:, 0] * force[beyond, 1])

    nodes = range(grid.n_cells)
    return (np.array([moment(k, False) for k in nodes]),
            np.array([moment(k + 1, True) for k in nodes]))


@pytest.mark.parametrize("routing", ["paper", "free"])
def test_closed_form_with_friction_equals_the_sum_of_channel_forces(routing):
    # The equilibrium argument: channel forces (normal + friction) act between tendon and body,
    # so beyond a cut they sum to the tendon's cut force -T(s) t_c(s) at p_c(s).
    design = preset("paper-experiment")
    mu = 0.3
    loading = Loading(tension_profile=Capstan(mu))
    result = solve(design, 20.0, settings=SolverSettings(routing=routing), loading=loading)
    closed = result.cell_moments
    errors = []
    for samples in (32, 128):
        m_a, m_b = vertex_force_moments(result, mu, samples)
        errors.append(max(np.max(np.abs(m_a - closed[:, 0])), np.max(np.abs(m_b - closed[:, 1])))
                      / np.max(np.abs(closed)))
    assert errors[1] < 5e-5
    assert errors[1] < 0.35 * errors[0]  # first order in the tendon's sampling


# --- tip force -------------------------------------------------------------------------------

def uniform_tube():
    """A design whose notches remove nothing (h1 >= R_outer): a plain tube of stiffness E I0."""
    from tdcm_ros.model import CustomProfile

    return preset("paper-experiment").with_overrides(
        profile=CustomProfile(lambda s: 0 * s + 3.92e-3))


@pytest.mark.parametrize("tension", [0.0, 5.0])
def test_tip_force_on_uniform_tube_is_the_cantilever(tension):
    design = uniform_tube()
    force = 1e-3
    length, stiffness = design.length, design.E * design.tube_second_moment
    expected = force * length**3 / (3 * stiffness) + design.R_c * tension * length**2 / (
        2 * stiffness)
    # The formula's tendon follows the body at R_c. Under ``paper`` routing it runs as straight
    # chords across the 4-6 mm tube segments, whose sag changes the tip by 1.6e-5 relative at
    # 5 N once the grid resolves chords; ``free`` routing keeps it on the body except across
    # the (here uncut) 2 mm notches, 1e-6 relative.
    result = solve(design, tension, settings=TIGHT.with_overrides(routing="free"),
                   loading=Loading(tip_force=(force, 0.0)))
    # Geometric nonlinearity at this load is below 1e-6 relative.
    assert result.tip_position[0] == pytest.approx(expected, rel=1e-5)


def test_tip_force_on_notched_design_matches_linear_solution():
    design = preset("paper-experiment")
    force = 1e-3
    expected = force * linear_tip_x(design, lambda s: design.length - s)
    result = solve(design, 0.0, settings=FINE, loading=Loading(tip_force=(force, 0.0)))
    assert result.tip_position[0] == pytest.approx(expected, rel=1e-4)


@HYPO
@given(tension=st.floats(0.0, 20.0), angle=st.floats(0.0, 2 * np.pi))
def test_small_tip_force_response_is_linear(tension, angle):
    design = preset("paper-experiment")
    base = solve(design, tension, settings=TIGHT).tip_position
    force = 2e-3 * np.array([np.sin(angle), np.cos(angle)])
    one = solve(design, tension, settings=TIGHT, loading=Loading(tip_force=tuple(force)))
    two = solve(design, tension, settings=TIGHT, loading=Loading(tip_force=tuple(2 * force)))
    d1 = one.tip_position - base
    d2 = two.tip_position - base
    # Second-order terms at 2 mN are below 1e-3 of the first-order change.
    assert np.linalg.norm(d2 - 2 * d1) <= 1e-3 * np.linalg.norm(d2) + 1e-12


def test_tip_moment_bends_toward_x_like_the_tendon():
    design = uniform_tube()
    moment = 2e-4
    result = solve(design, 0.0, settings=TIGHT, loading=Loading(tip_moment=moment))
    stiffness = design.E * design.tube_second_moment
    assert result.tip_position[0] == pytest.approx(moment * design.length**2 / (2 * stiffness),
                                                   rel=1e-5)
    tendon = solve(design, moment / design.R_c, settings=TIGHT)
    assert result.tip_position[0] == pytest.approx(tendon.tip_position[0], rel=1e-5)


# --- body force ------------------------------------------------------------------------------

def test_body_force_on_uniform_tube_is_the_distributed_cantilever():
    design = uniform_tube()
    q = RHO_G * tube_area(design.R_outer, design.r_inner)
    expected = -q * design.length**4 / (8 * design.E * design.tube_second_moment)
    result = solve(design, 0.0, settings=FINE, loading=Loading(body_force_density=(-RHO_G, 0.0)))
    assert result.tip_position[0] == pytest.approx(expected, rel=1e-4)


@HYPO
@given(angle=st.floats(-np.pi, np.pi), tension=st.floats(0.0, 20.0),
       scale=st.floats(1.0, 1000.0))
def test_gravity_sags_toward_its_direction(angle, tension, scale):
    design = preset("paper-experiment")
    gravity = scale * RHO_G * np.array([np.sin(angle), np.cos(angle)])
    base = solve(design, tension)
    sagged = solve(design, tension, loading=Loading(body_force_density=tuple(gravity)))
    move = sagged.tip_position[[0, 2]] - base.tip_position[[0, 2]]
    # The tip moves toward the gravity direction (or not at all when gravity is along the body).
    assert move @ gravity >= -1e-12 * np.linalg.norm(gravity)


def test_gravity_along_minus_x_reduces_the_deflection():
    design = preset("paper-experiment")
    base = solve(design, 8.0)
    sagged = solve(design, 8.0, loading=Loading(body_force_density=(-100 * RHO_G, 0.0)))
    assert sagged.tip_position[0] < base.tip_position[0]
    alone = solve(design, 0.0, loading=Loading(body_force_density=(-100 * RHO_G, 0.0)))
    assert alone.tip_position[0] < 0.0


def test_body_force_on_notched_design_matches_linear_solution():
    design = preset("paper-experiment")
    area = compliance_area(design)
    left, right = design.notch_bounds()
    breaks = sorted({design.length, *left, *right})

    def moment(s: float) -> float:
        edges = [s, *(b for b in breaks if b > s)]
        return sum(quad(lambda xi: (xi - s) * area(xi), a, b, epsrel=1e-12)[0]
                   for a, b in pairwise(edges))

    expected = RHO_G * linear_tip_x(design, moment)
    result = solve(design, 0.0, settings=FINE, loading=Loading(body_force_density=(RHO_G, 0.0)))
    assert result.tip_position[0] == pytest.approx(expected, rel=1e-4)


def compliance_area(design):
    left, right = design.notch_bounds()

    def area(s: float) -> float:
        for lo, hi in zip(left, right, strict=True):
            if lo < s < hi:
                half = design.w_n / 2
                h1 = (design.w_n + design.w_d) / 2 - np.sqrt(max(half**2 - (s - lo - half) ** 2, 0))
                return float(notched_area(h1, design.R_outer, design.r_inner))
        return tube_area(design.R_outer, design.r_inner)

    return area


# --- notch contact ---------------------------------------------------------------------------

def closing_design():
    return preset("paper-experiment").with_overrides(profile="rectangular", E=0.3e9)


@pytest.mark.parametrize("routing", ["paper", "free"])
def test_contact_stiffens_a_closing_notch(routing):
    design = closing_design()
    cfg = SolverSettings(routing=routing)
    with pytest.raises(NotchClosureError):
        solve(design, 40.0, settings=cfg)
    result = solve(design, 40.0, settings=cfg, loading=Loading(notch_contact=NotchContact()))
    grid = result.grid
    angles = result.theta[grid.notch_right_node] - result.theta[grid.notch_left_node]
    closure = closure_angles(grid)[0]
    assert result.converged and result.closed_notches
    assert np.all(angles >= 0.0)
    # Past closure each notch bends only as much as the tube's stiffness allows: a few % over.
    assert np.max(angles) <= 1.05 * closure
    assert np.max(angles) > closure
    # Below closure, contact changes nothing.
    below = solve(design, 20.0, settings=cfg)
    same = solve(design, 20.0, settings=cfg, loading=Loading(notch_contact=NotchContact()))
    assert not same.closed_notches
    assert np.max(np.abs(same.positions - below.positions)) <= 1e-12


def test_closure_angle_of_a_uniform_notch():
    design = closing_design()
    grid = build_grid(design, SolverSettings())
    assert closure_angles(grid)[0] == pytest.approx(design.w_n / design.R_outer, rel=1e-9)


def test_each_notch_closes_at_its_own_width_over_the_radius():
    # a rectangular notch bends at uniform curvature: its faces meet at w_n / R_outer (rad)
    widths = [0.5e-3, 1.0e-3, 0.5e-3, 1.5e-3]
    design = closing_design().with_overrides(N=4, w_n=widths, w_t=[4e-3, 0.0, 2e-3],
                                             w_d=[1.4e-3, 1.0e-3, 1.4e-3, 1.2e-3])
    closure = closure_angles(build_grid(design, SolverSettings()))
    np.testing.assert_allclose(closure, np.array(widths) / design.R_outer, rtol=1e-9)


@pytest.mark.parametrize("stiffness", [1.0, 0.2])
def test_contact_with_a_tip_force_closes_base_notches_first(stiffness):
    # The tip force's moment grows toward the base: the base notch closes first. Without
    # contact the same load raises NotchClosureError; with it, the kinked constitutive law
    # still converges.
    design = closing_design()
    # Pinned to the previous default grid: on finer grids (uniform with >= 12 cells per notch,
    # or the adaptive default) Anderson lands on a second equilibrium, curled the other way
    # (tip at x = -15.5 mm, 7 notches closed at -0.51 rad), as plain Picard does on any grid;
    # which branch the solver should track is the solver's question (see branch grid's report).
    cfg = SolverSettings(routing="free", grid="uniform", quad_order=4)
    with pytest.raises(NotchClosureError):
        solve(design, 0.0, settings=cfg, loading=Loading(tip_force=(10.0, 0.0)))
    loading = Loading(tip_force=(10.0, 0.0), notch_contact=NotchContact(stiffness))
    result = solve(design, 0.0, settings=cfg, loading=loading)
    closed = result.closed_notches
    assert closed and closed == tuple(range(1, len(closed) + 1))
    assert len(closed) < design.N
    grid = result.grid
    angles = result.theta[grid.notch_right_node] - result.theta[grid.notch_left_node]
    assert np.all(np.diff(angles) < 0.0)
    assert closure_angles(grid)[0] < angles[0] <= 1.05 * closure_angles(grid)[0]


# --- bad input -------------------------------------------------------------------------------

@pytest.mark.parametrize(("field", "value"), [
    ("tip_force", (float("nan"), 0.0)),
    ("tip_force", (1.0,)),
    ("tip_force", "ab"),
    ("tip_moment", float("inf")),
    ("body_force_density", (0.0, float("-inf"))),
    ("tension_profile", 3.0),
    ("notch_contact", 1.0),
])
def test_bad_loading_fields_name_the_parameter(field, value):
    with pytest.raises(InvalidLoadingError) as info:
        Loading(**{field: value})
    assert info.value.parameter == field
    assert field in str(info.value)


@pytest.mark.parametrize("factor", [0.0, -1.0, float("nan"), 1e9])
def test_bad_contact_stiffness(factor):
    with pytest.raises(InvalidLoadingError, match="stiffness_factor"):
        NotchContact(factor)


@pytest.mark.parametrize("profile", [
    lambda s, w, t: t - 30.0 * s / s[-1],
    lambda s, w, t: np.full_like(s, np.nan),
    lambda s, w, t: np.ones(3),
    lambda s, w, t: 1 / 0,
])
def test_bad_profile_output_is_rejected(profile):
    with pytest.raises(InvalidLoadingError) as info:
        solve(preset("paper-experiment"), 20.0, loading=Loading(tension_profile=profile))
    assert info.value.parameter == "tension_profile"
    assert isinstance(info.value, InputError)


def test_literal_loads_reject_a_loading():
    with pytest.raises(InvalidLoadingError, match="loads=closed"):
        solve(preset("paper-experiment"), 5.0, settings=SolverSettings(loads="literal"),
              loading=Loading(tip_force=(0.1, 0.0)))


# --- convergence -----------------------------------------------------------------------------

def test_warm_start_under_a_loading():
    design = preset("paper-experiment")
    loading = Loading(tension_profile=Capstan(0.2), tip_force=(0.3, 0.0),
                      body_force_density=(-RHO_G, 0.0))
    cold = solve(design, 12.0, loading=loading)
    first = solve(design, 10.0, loading=loading)
    warm = solve(design, 12.0, loading=loading, warm_start=first)
    assert np.max(np.abs(warm.positions - cold.positions)) <= 1e-9
    assert warm.iterations <= cold.iterations


MIXED = Loading(tension_profile=Capstan(0.3), tip_force=(0.5, -0.5), tip_moment=-1e-3,
                body_force_density=(-50 * RHO_G, 0.0))


@pytest.mark.parametrize("acceleration", ["anderson", "relaxation", "none"])
def test_every_strategy_reaches_the_same_loaded_solution(acceleration):
    design = preset("paper-experiment")
    reference = solve(design, 12.0, loading=MIXED)
    assert reference.strategy == "picard+anderson"
    other = solve(design, 12.0, settings=SolverSettings(acceleration=acceleration, max_iter=2000),
                  loading=MIXED)
    assert np.max(np.abs(other.positions - reference.positions)) <= 1e-9


@pytest.mark.parametrize("contact", [None, NotchContact()])
def test_continuation_ramps_the_external_loads_with_the_tension(contact):
    design = closing_design()
    loading = Loading(tension_profile=Capstan(0.3), tip_force=(4.0, 0.0),
                      body_force_density=(0.0, -50 * RHO_G), notch_contact=contact)
    cfg = SolverSettings(routing="free")
    reference = solve(design, 5.0, settings=cfg, loading=loading)
    grid = reference.grid
    seen: list[float] = []
    model = LoadedModel(grid, loading, 5.0)
    moments = model.moments

    def spy(shape, x, level, factor):
        seen.append(factor)
        # Loads and tension ramp together: the tension level is the same fraction of 5 N.
        assert level == pytest.approx(5.0 * factor, rel=1e-12)
        return moments(shape, x, level, factor)

    model.moments = spy  # type: ignore[method-assign]
    run = _continuation(_Problem(grid, cfg, model), 5.0, np.zeros(2 * grid.n_cells), 400,
                        adaptive=True)
    assert run.converged
    assert min(seen) < 0.2 and max(seen) == 1.0
    shape = run.shape
    assert np.max(np.abs(shape.p.imag - reference.positions[:, 0])) <= 1e-9


@settings(max_examples=40, suppress_health_check=[HealthCheck.too_slow])
@given(tension=st.floats(0.0, 60.0), fx=st.floats(-40.0, 40.0), fz=st.floats(-40.0, 40.0),
       gx=st.floats(-1e6, 1e6), mu=st.floats(0.0, 1.0), contact=st.booleans(),
       routing=st.sampled_from(["paper", "free"]))
def test_any_loading_converges_or_raises_a_typed_error(tension, fx, fz, gx, mu, contact, routing):
    design = preset("paper-experiment").with_overrides(E=0.5e9)
    loading = Loading(tension_profile=Capstan(mu), tip_force=(fx, fz),
                      body_force_density=(gx, 0.0),
                      notch_contact=NotchContact() if contact else None)
    try:
        result = solve(design, tension, settings=SolverSettings(routing=routing), loading=loading)
    except ConvergenceError as error:
        assert error.result is None or np.all(np.isfinite(error.result.positions))
        return
    except ModelLimitError:
        return
    assert result.converged
    assert np.all(np.isfinite(result.positions)) and np.all(np.isfinite(result.cell_moments))


def test_singularity_is_checked_on_the_loaded_solution():
    design = preset("paper-experiment").with_overrides(E=0.2e9)
    with pytest.raises(TendonSingularityError):
        solve(design, 40.0)
    with pytest.raises(TendonSingularityError):
        solve(design, 40.0, loading=Loading(tension_profile=constant))
    # A tip moment opposing the tendon lowers the notch moments below the singular level.
    relieved = solve(design, 40.0, loading=Loading(tip_moment=-0.6 * design.R_c * 40.0))
    assert relieved.converged


def test_the_body_force_weighs_each_section_by_its_own_area() -> None:
    """A body of polygon (tee) notches: its volume, the sum of the body force's ``A ds``
    weights, is the tee's polygon area (shoelace, here) times the notches' widths plus the
    tube's annulus times the tubes' lengths."""
    from tdcm_ros.model.loading import _body_cells
    from tdcm_ros.model.profiles import PolygonProfile

    tee = ((-3.5e-3, -1.5e-3), (-2.5e-3, -1.5e-3), (-2.5e-3, -0.3e-3), (0.5e-3, -0.3e-3),
           (0.5e-3, 0.3e-3), (-2.5e-3, 0.3e-3), (-2.5e-3, 1.5e-3), (-3.5e-3, 1.5e-3))
    xs, ys = np.array(tee).T
    shoelace = 0.5 * abs(float(np.dot(xs, np.roll(ys, -1)) - np.dot(ys, np.roll(xs, -1))))
    design = preset("paper-experiment").with_overrides(profile=PolygonProfile(tee))
    grid = build_grid(design, SolverSettings())
    volume = float(np.sum(_body_cells(grid).moments[0]))
    notches = design.N * design.w_n
    expected = shoelace * notches + tube_area(design.R_outer, design.r_inner) * (
        design.length - notches)
    assert volume == pytest.approx(expected, rel=1e-12)
