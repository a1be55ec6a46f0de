"""Several tendons: an antagonistic pair is one tendon at the difference, equal tensions leave
the body straight, the moments are the tendons' own equilibria summed (checked against paths
drawn here and an ODE solve), anchors end a tendon's pull, and bad tendons name their key."""

from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from tdcm_ros.model import (
    InvalidDesignError,
    SolverSettings,
    TensionRangeError,
    body_file_text,
    preset,
    read_body_file,
    solve,
)
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidSettingsError
from tdcm_ros.model.inverse import InvalidTargetError, solve_inverse
from tdcm_ros.model.loading import InvalidLoadingError, Loading
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.section import notched_moment
from tdcm_ros.model.tendons import Tendon

REPO = Path(__file__).resolve().parents[2]
PAPER = preset("paper-experiment")
R_C = PAPER.R_c


def with_tendons(design: Design, *tendons: Tendon) -> Design:
    return dataclasses.replace(design, R_c=abs(tendons[0].offset), tendons=tendons)


PAIR = with_tendons(PAPER, Tendon(R_C), Tendon(-R_C))


@pytest.mark.parametrize(("pull", "preload"), [(20.0, 5.0), (10.0, 10.0), (3.0, 17.0)])
def test_an_antagonistic_pair_is_one_tendon_at_the_difference_under_paper_routing(
        pull: float, preload: float) -> None:
    """Issue 28's target: within 0.02 um. Under ``paper`` routing both tendons follow the
    notches; across the nearly straight tubes their chords differ from the offset curve by
    the tubes' sagitta only."""
    single = solve(PAPER, pull)
    pair = solve(PAIR, [pull + preload, preload])
    assert np.max(np.abs(pair.tip_position - single.tip_position)) <= 0.02e-6
    assert pair.tensions_n == (pull + preload, preload) and pair.tension_n == pull + preload


def test_under_free_routing_the_preload_bends_further_through_the_chords() -> None:
    """Under ``free`` routing both tendons cross the bent notches as chords. A chord on the
    inside of the bend (+x) runs farther from the backbone than the offset curve, one on the
    outside (-x) nearer to it: both add ``T d`` to the bend. So the pair bends more than one
    tendon at the difference, more with more preload, and exactly as much without preload."""
    free = SolverSettings(routing="free")
    single = solve(PAPER, 10.0, settings=free).tip_position[0]
    extra = [solve(PAIR, [10.0 + p, p], settings=free).tip_position[0] - single
             for p in (0.0, 5.0, 10.0)]
    assert abs(extra[0]) <= 1e-12
    assert 0.0 < extra[1] < extra[2]


@settings(max_examples=25, deadline=None)
@given(tension=st.floats(0.0, 40.0), routing=st.sampled_from(["paper", "free"]))
def test_equal_antagonistic_tensions_leave_the_body_straight(tension: float, routing: str
                                                             ) -> None:
    result = solve(PAIR, [tension, tension], settings=SolverSettings(routing=routing))
    assert result.converged
    assert np.all(result.positions[:, 0] == 0.0) and np.all(result.theta == 0.0)
    assert np.allclose(result.tendon_strokes_m, 0.0, atol=1e-15)


@settings(max_examples=30, deadline=None)
@given(flexor=st.floats(0.0, 30.0), extensor=st.floats(0.0, 30.0),
       routing=st.sampled_from(["paper", "free"]))
def test_tendons_pulling_against_each_other_converge_or_raise_a_typed_error(
        flexor: float, extensor: float, routing: str) -> None:
    """The stability suite's several-tendon case: any pair of tensions gives a finite
    converged shape that bends toward the stronger tendon, mirrored when they swap. A
    difference too small for its deflection to be a double (0 and 5e-324 N: hypothesis found
    it) leaves the body straight, as it should."""
    free = SolverSettings(routing=routing)
    result = solve(PAIR, [flexor, extensor], settings=free)
    mirrored = solve(PAIR, [extensor, flexor], settings=free)
    assert result.converged and np.all(np.isfinite(result.positions))
    toward = np.sign(result.tip_position[0])
    assert toward in (np.sign(flexor - extensor), 0.0)
    if abs(flexor - extensor) > 1e-12:  # N: bends visibly (~1e-15 m and more)
        assert toward == np.sign(flexor - extensor)
    assert result.tip_position[0] == pytest.approx(-mirrored.tip_position[0], abs=1e-12)


def drawn_moment(result: SolveResult, s: float) -> float:
    """The tendons' moment (N m) about the tube axis at ``s`` from each tendon's path drawn
    here: equilibrium of the tendon piece beyond the cut, ``(p_c - p) x (-T t_c)``, with
    ``p_c`` on the offset curve where the tendon follows the body (``t_c`` the body's
    tangent) and on the straight line between its chord's ends elsewhere; zero past its
    anchor."""
    design = result.design
    left, right = design.notch_bounds()
    bounds = np.concatenate([[0.0], np.ravel(np.column_stack([left, right])), [design.length]])
    segment = min(int(np.searchsorted(bounds, s, side="right")) - 1, bounds.size - 2)
    in_notch = segment % 2 == 1

    def pose(at: float) -> tuple[complex, complex]:
        position, quaternion = result.pose_at(at)
        theta = 2.0 * math.atan2(quaternion[0, 1], quaternion[0, 3])
        return complex(position[0, 2], position[0, 0]), complex(math.cos(theta), math.sin(theta))

    p, tangent = pose(s)
    total = 0.0
    for tendon, tension in zip(design.tendon_list(), result.tensions_n, strict=True):
        if tendon.anchor is not None and s >= tendon.anchor:
            continue
        offset = 1j * tendon.offset
        follows = in_notch == ((tendon.routing or result.settings.routing) == "paper")
        if follows:
            p_c, t_c = p + offset * tangent, tangent
        else:
            (pa, ta), (pb, tb) = pose(float(bounds[segment])), pose(float(bounds[segment + 1]))
            start, end = pa + offset * ta, pb + offset * tb
            t_c = (end - start) / abs(end - start)
            p_c = start + ((p - start).conjugate() * t_c).real * t_c  # foot of p on the chord
        arm = p_c - p
        total += -tension * (arm.conjugate() * t_c).imag
    return total


MIXED = with_tendons(PAPER, Tendon(R_C, routing="paper"), Tendon(-1.5e-3, routing="free"),
                     Tendon(2.0e-3, anchor=float(PAPER.notch_bounds()[1][3])))


@pytest.mark.parametrize(("design", "tensions"), [(PAIR, [18.0, 6.0]), (MIXED, [9.0, 4.0, 6.0])],
                         ids=["antagonistic", "mixed-routing-and-anchor"])
def test_the_solved_moments_are_the_drawn_tendons_equilibria(design: Design,
                                                             tensions: list[float]) -> None:
    """At every cell's ends the fixed point's moments are the sum of the tendons' moments
    computed from their paths drawn on the solution here (the poses of ``pose_at``, checked
    against an ODE solve in test_result)."""
    result = solve(design, tensions)
    nodes = result.grid.s_nodes
    scale = max(tensions) * R_C
    for cell in range(result.grid.n_cells):
        for end, s in ((0, nodes[cell]), (1, nodes[cell + 1])):
            inside = s + (1e-12 if end == 0 else -1e-12)  # the cell's own side of a kink
            assert result.cell_moments[cell, end] == pytest.approx(
                drawn_moment(result, inside), abs=2e-7 * scale), (cell, end)


def test_two_tendons_on_one_side_with_an_anchor_match_an_ode_solve() -> None:
    """A body of notches only (no tubes: every tendon follows the body everywhere, so the
    moment is exactly ``sum r_j T_j`` before each anchor): the tip against scipy's DOP853 of
    ``theta' = m(s) / (E I(s))`` with eq. 12's ``I`` and eq. 13's half-width written here, on a
    grid fine enough that its own error (3e-9 rad at the default 8 cells a notch) is below
    the comparison's."""
    body = PAPER.with_overrides(w_base=0.0, w_t=0.0, w_tip=0.0)
    anchor = float(body.notch_bounds()[1][4])  # the end of notch 5
    design = with_tendons(body, Tendon(2.75e-3), Tendon(1.0e-3, anchor=anchor),
                          Tendon(-2.0e-3))
    tensions = (6.0, 10.0, 2.0)
    result = solve(design, list(tensions), settings=SolverSettings(cells_per_notch=64))

    def half_width(sigma: float) -> float:
        w_n, w_d = body.w_n, body.w_d
        return (w_n + w_d) / 2.0 - math.sqrt(max(sigma * (w_n - sigma), 0.0))

    def rhs(s: float, y: np.ndarray, moment: float, left: float) -> list[float]:
        inertia = float(notched_moment(half_width(s - left), body.R_outer, body.r_inner))
        return [math.sin(y[2]), math.cos(y[2]), moment / (body.E * inertia)]

    y = np.zeros(3)
    for left, right in zip(*body.notch_bounds(), strict=True):
        moment = 2.75e-3 * 6.0 - 2.0e-3 * 2.0 + (1.0e-3 * 10.0 if right <= anchor + 1e-12 else 0.0)
        y = solve_ivp(rhs, (left, right), y, method="DOP853", args=(moment, left), rtol=1e-12,
                      atol=1e-15).y[:, -1]
    assert result.tip_position[0] == pytest.approx(y[0], abs=1e-11)
    assert result.tip_position[2] == pytest.approx(y[1], abs=1e-11)
    assert result.tip_angle_rad == pytest.approx(y[2], abs=1e-10)


def test_each_tendon_has_its_length_and_stroke_to_its_anchor() -> None:
    """A tendon's length runs to its anchor; on the straight body it is the anchor's arc
    length; a tendon on the outside of the bend is paid out (negative stroke)."""
    anchor = float(PAPER.notch_bounds()[1][3])
    design = with_tendons(PAPER, Tendon(R_C), Tendon(R_C, anchor=anchor), Tendon(-R_C))
    straight = solve(design, [0.0, 0.0, 0.0])
    assert straight.tendon_lengths_m == pytest.approx([PAPER.length, anchor, PAPER.length],
                                                      abs=1e-15)
    bent = solve(design, [12.0, 0.0, 0.0])
    assert bent.tendon_strokes_m[0] > 0.0 > bent.tendon_strokes_m[2]
    assert 0.0 < bent.tendon_strokes_m[1] < bent.tendon_strokes_m[0]
    # the first tendon alone is the paper's tendon at 12 N: the same path, the same length
    single = solve(PAPER, 12.0)
    assert bent.tendon_lengths_m[0] == pytest.approx(single.tendon_lengths_m[0], abs=1e-12)


def test_a_tendon_on_the_minus_x_side_mirrors_the_paper_tendon() -> None:
    mirrored = solve(with_tendons(PAPER, Tendon(-R_C)), [20.0])
    paper = solve(PAPER, 20.0)
    assert np.allclose(mirrored.positions[:, 0], -paper.positions[:, 0], atol=1e-15)
    assert np.allclose(mirrored.positions[:, 2], paper.positions[:, 2], atol=1e-15)


def test_a_tendon_list_with_the_paper_tendon_is_the_paper_model() -> None:
    listed = solve(with_tendons(PAPER, Tendon(R_C)), [20.0])
    paper = solve(PAPER, 20.0)
    assert np.max(np.abs(listed.positions - paper.positions)) <= 1e-15


def test_the_shipped_bodies_with_several_tendons_solve_and_round_trip(tmp_path: Path) -> None:
    for name in ("antagonistic_pair", "disk_routed"):
        design = read_body_file(REPO / "config" / "bodies" / f"{name}.yaml").design()
        path = tmp_path / f"{name}.yaml"
        path.write_text(body_file_text(design), encoding="utf-8")
        assert read_body_file(path).design() == design
    pair = read_body_file(REPO / "config" / "bodies" / "antagonistic_pair.yaml").design()
    assert [t.name for t in pair.tendons] == ["flexor", "extensor"]
    # the file's r_inner is 1.55e-3 as written, the preset's 1.5500000000000002e-3
    assert np.max(np.abs(solve(pair, [25.0, 5.0]).positions - solve(PAIR, [25.0, 5.0]).positions
                         )) <= 1e-12


def test_a_disk_routed_robot_bends_as_its_tendon_pulls_through_the_disks() -> None:
    """Rao et al.'s benchmark numbers: tendons 10 mm off a 0.7 mm backbone, outside it."""
    design = read_body_file(REPO / "config" / "bodies" / "disk_routed.yaml").design()
    result = solve(design, [0.3, 0.0])
    assert result.converged and result.tip_position[0] > 0.05
    # between the disks the tendon runs straight, on the inside of the bend: the chord lies
    # farther from the backbone than the 10 mm offset arc, so the moment inside a rod segment
    # exceeds ``r T`` at its disks, where the tendon follows the body
    rod = np.flatnonzero(result.grid.is_notch & (result.grid.notch_index == 0))
    disk = np.flatnonzero(~result.grid.is_notch)[0]
    assert result.cell_moments[disk, 0] == pytest.approx(10e-3 * 0.3, rel=1e-12)
    assert np.all(result.cell_moments[rod[1:], 0] > 10e-3 * 0.3)


@pytest.mark.parametrize(("tension", "parameter"), [(20.0, "tension"), ([20.0], "tension"),
                                                    ([20.0, -1.0], "tension[1]"),
                                                    ([20.0, math.nan], "tension[1]")])
def test_a_design_with_tendons_takes_one_tension_per_tendon(tension: object, parameter: str
                                                            ) -> None:
    with pytest.raises(TensionRangeError) as info:
        solve(PAIR, tension)  # type: ignore[arg-type]
    assert info.value.parameter == parameter


def test_what_takes_the_paper_tendon_only_says_so() -> None:
    with pytest.raises(InvalidTargetError, match=r"tendon is missing: this design has 2 "):
        solve_inverse(PAIR, tip_deflection=1e-3)
    with pytest.raises(InvalidLoadingError, match="several tendons"):
        solve(PAIR, [1.0, 0.0], loading=Loading(tip_force=(0.1, 0.0)))
    with pytest.raises(InvalidSettingsError, match="loads = .literal. is not supported with several"):
        solve(PAIR, [1.0, 0.0], settings=SolverSettings(loads="literal"))


@pytest.mark.parametrize(("tendons", "message"), [
    ((Tendon(4e-3),), r"tendons\[0\]\.offset = 0\.004 m .*0 < \|offset\| < R_outer"),
    ((Tendon(R_C), Tendon(0.0)), r"tendons\[1\]\.offset = 0\.0 m"),
    ((Tendon(R_C, anchor=0.012),), r"tendons\[0\]\.anchor = 0\.012 .*segment boundary"),
    ((Tendon(R_C, routing="around"),), r"tendons\[0\]\.routing = 'around'"),
    ((Tendon(R_C, guides="rails"),), r"tendons\[0\]\.guides = 'rails'"),
    ((Tendon(R_C, name="a"), Tendon(-R_C, name="a")), r"distinct names"),
])
def test_bad_tendons_name_the_tendon(tendons: tuple[Tendon, ...], message: str) -> None:
    with pytest.raises(InvalidDesignError, match=message):
        dataclasses.replace(PAPER, tendons=tendons)


def test_an_external_tendon_may_run_outside_the_wall() -> None:
    design = with_tendons(PAPER, Tendon(8e-3, guides="external"))
    inside = solve(with_tendons(PAPER, Tendon(R_C)), [5.0])
    outside = solve(design, [5.0])
    assert outside.tip_position[0] > inside.tip_position[0] > 0.0
    with pytest.raises(InvalidDesignError, match="R_c"):
        design.with_overrides(R_c=1e-3)


def test_sweeps_do_not_vary_a_listed_tendons_offset() -> None:
    assert "R_c" in PAIR.derived_fields()
    assert list(itertools.islice(PAIR.tendon_list(), 2)) == list(PAIR.tendons)


STRETCHY = with_tendons(PAPER, Tendon(R_C, stiffness=2.0e4, slack=0.5e-3))


def test_a_tendon_with_stiffness_and_slack_pulls_as_the_paper_tendon() -> None:
    """Stiffness and slack move the actuator, not the body: the listed tendon is the paper's
    model bit for bit (its compiled iteration), and the actuator's travel is the path's
    stroke, the slack and ``T / k``."""
    result = solve(STRETCHY, 20.0)
    paper = solve(PAPER, 20.0)
    assert np.array_equal(result.positions, paper.positions)
    assert np.array_equal(result.tendon_strokes_m, paper.tendon_strokes_m)
    assert result.actuator_strokes_m[0] == pytest.approx(
        paper.tendon_strokes_m[0] + 0.5e-3 + 20.0 / 2.0e4, abs=1e-15)
    assert solve(STRETCHY, 0.0).actuator_strokes_m == pytest.approx([0.5e-3], abs=1e-15)
    assert np.array_equal(paper.actuator_strokes_m, paper.tendon_strokes_m)


@pytest.mark.parametrize("stroke", [0.8e-3, 1.5e-3, 2.4e-3])
def test_an_actuator_stroke_round_trips_through_the_tension(stroke: float) -> None:
    """Issue 28's target: stroke -> tension -> stroke within 1e-9 m, the tendon's stretch and
    slack included (the path's part of it is what is left)."""
    found = solve_inverse(STRETCHY, tendon_stroke=stroke, tol=1e-11)
    again = solve(STRETCHY, found.tension_n)
    assert again.actuator_strokes_m[0] == pytest.approx(stroke, abs=1e-9)
    path = stroke - 0.5e-3 - found.tension_n / 2.0e4
    assert again.tendon_strokes_m[0] == pytest.approx(path, abs=1e-9)


def test_an_actuator_stroke_within_the_slack_is_out_of_reach() -> None:
    from tdcm_ros.model.inverse import UnreachableTargetError

    with pytest.raises(UnreachableTargetError):
        solve_inverse(STRETCHY, tendon_stroke=0.2e-3)


@pytest.mark.parametrize(("tendon", "message"), [
    (Tendon(R_C, stiffness=0.0), r"tendons\[0\]\.stiffness = 0\.0 .*\(0, 1e\+12\] N/m"),
    (Tendon(R_C, stiffness=math.inf), r"tendons\[0\]\.stiffness = inf"),
    (Tendon(R_C, slack=-1e-3), r"tendons\[0\]\.slack = -0\.001 .*\[0, 1\] m"),
])
def test_bad_stiffness_and_slack_name_the_tendon(tendon: Tendon, message: str) -> None:
    with pytest.raises(InvalidDesignError, match=message):
        dataclasses.replace(PAPER, tendons=(tendon,))


def test_stiffness_and_slack_round_trip_through_a_body_file(tmp_path: Path) -> None:
    path = tmp_path / "stretchy.yaml"
    path.write_text(body_file_text(STRETCHY), encoding="utf-8")
    assert "stiffness: 20000.0" in path.read_text(encoding="utf-8")
    assert read_body_file(path).design() == STRETCHY


NAMED = with_tendons(PAPER, Tendon(R_C, name="flexor"), Tendon(-R_C, name="extensor"))


def test_the_inverse_seeks_one_tendon_with_the_others_held() -> None:
    """The flexor against a 5 N preload needs the single tendon's tension plus 5 N (to the
    pair's 7 nm equivalence); the extensor against a 12 N flexor straightens the body at 12 N
    exactly; a stroke target is the sought tendon's, round-tripped to 1e-9 m."""
    single = solve_inverse(PAPER, tip_angle=0.2)
    flexor = solve_inverse(NAMED, tip_angle=0.2, tendon="flexor", tensions=[0.0, 5.0])
    assert flexor.tension_n - 5.0 == pytest.approx(single.tension_n, abs=5e-5)
    assert flexor.result.tensions_n == (flexor.tension_n, 5.0)
    assert flexor.summary()["tendon"] == "flexor"
    straight = solve_inverse(NAMED, tip_angle=0.0, tendon=1, tensions=[12.0, 0.0])
    assert straight.tension_n == pytest.approx(12.0, abs=1e-9)
    assert straight.sensitivity.tip_angle_rad_per_n == pytest.approx(
        -single.sensitivity.tip_angle_rad_per_n, rel=1e-3)
    pulled = solve_inverse(NAMED, tendon_stroke=4e-4, tendon="extensor", tensions=[12.0, 0.0],
                           tol=1e-11)
    assert pulled.result.actuator_strokes_m[1] == pytest.approx(4e-4, abs=1e-9)
    assert pulled.summary()["actuator_stroke_m"] == pytest.approx(4e-4, abs=1e-9)


@pytest.mark.parametrize(("design", "keywords", "parameter"), [
    (NAMED, {"tendon": "biceps"}, "tendon"),
    (NAMED, {"tendon": 2}, "tendon"),
    (NAMED, {"tendon": True}, "tendon"),
    (NAMED, {"tendon": "flexor", "tensions": [1.0]}, "tension"),
    (PAPER, {"tensions": [1.0]}, "tensions"),
])
def test_a_bad_sought_tendon_is_named(design: Design, keywords: dict[str, object],
                                      parameter: str) -> None:
    with pytest.raises((InvalidTargetError, TensionRangeError)) as info:
        solve_inverse(design, tip_angle=0.1, **keywords)  # type: ignore[arg-type]
    assert info.value.parameter == parameter
