"""A shape-design problem's evaluation: loads (tension, stroke, friction) solved as the model's
own entry points solve them, and the score's feasibility classes in order."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdcm_ros.model import Capstan, Loading, preset, solve
from tdcm_ros.model.design_variables import Variable, VariableSet
from tdcm_ros.model.inverse import InvalidTargetError
from tdcm_ros.model.shape_problem import PENALTY, Goal, Load, ShapeProblem
from tdcm_ros.model.shape_targets import Limits, NotchAngleTarget, TipTarget

PAPER = preset("paper-experiment")
WD = VariableSet(PAPER, (Variable("w_d", 0.3e-3, 2.0e-3, "each"),))
TIP = TipTarget(angle=math.radians(60.0))


LIMITS = Limits(max_strain=0.06)


def problem(load: Load, limits: Limits = LIMITS, variables: VariableSet = WD) -> ShapeProblem:
    return ShapeProblem(variables, (Goal(TIP, load), Goal(NotchAngleTarget("equal"), load)),
                        limits)


def test_a_load_with_friction_is_the_capstan_solve() -> None:
    load = Load(tension=20.0, mu=0.2)
    x = np.linspace(1.4e-3, 0.9e-3, 8)
    evaluation = problem(load).evaluate(x)
    reference = solve(WD.design(x), 20.0, loading=Loading(tension_profile=Capstan(0.2)))
    result = evaluation.results[load]
    assert result.tip_position == pytest.approx(reference.tip_position, rel=1e-12)
    assert evaluation.residuals[0] == pytest.approx(
        [(reference.tip_angle_rad - math.radians(60.0)) / TIP.angle_tol])
    assert solve(WD.design(x), 20.0).tip_angle_rad > result.tip_angle_rad  # friction costs bend


def test_a_stroke_load_finds_the_tension_of_that_stroke() -> None:
    load = Load(stroke=0.5e-3)
    evaluation = problem(load).evaluate(np.full(8, 1.2e-3))
    result = evaluation.results[load]
    assert result.actuator_strokes_m[0] == pytest.approx(0.5e-3, abs=1e-6)


def test_goals_at_one_load_solve_once() -> None:
    load = Load(tension=20.0)
    shared = problem(load)
    assert shared.loads == (load,)
    two = ShapeProblem(WD, (Goal(TIP, load), Goal(TIP, Load(tension=10.0))), Limits(0.06))
    assert len(two.loads) == 2 and len(two.evaluate(np.full(8, 1e-3)).results) == 2


def test_scores_order_impossible_fabrication_failed_infeasible_feasible() -> None:
    load = Load(tension=20.0)
    limits = Limits(max_strain=0.03, min_backbone=0.5e-3)
    cut = VariableSet(PAPER, (Variable("cut", 0.1e-3, 9e-3, "uniform"),))
    impossible = problem(load, limits, cut).evaluate([8.5e-3])  # deeper than the tube
    short = problem(load, limits).evaluate(np.full(8, 0.4e-3))  # backbone under 0.5 mm
    failed = problem(Load(tension=5e4), limits).evaluate(np.full(8, 0.6e-3))  # singularity
    strained = problem(load, limits).evaluate(np.full(8, 0.6e-3))
    feasible = problem(load, limits).evaluate(np.full(8, 1.4e-3))
    assert impossible.design is None and impossible.score == 4 * PENALTY
    assert 3 * PENALTY < short.score < 4 * PENALTY and short.violations["min_backbone"] > 0
    assert failed.score == 2 * PENALTY and "singularity" in failed.failure
    assert PENALTY < strained.score < 2 * PENALTY and strained.violations["max_strain"] > 0
    assert feasible.feasible and feasible.score == pytest.approx(feasible.objective)
    assert not feasible.met  # 14.5 deg, far from 60
    assert [e.feasible for e in (impossible, short, failed, strained)] == [False] * 4


@pytest.mark.parametrize(("load", "parameter"), [
    ({}, "load"), ({"tension": 1.0, "stroke": 1e-3}, "load"),
    ({"tension": -1.0}, "load.tension"), ({"stroke": 2.0}, "load.stroke"),
    ({"tension": 1.0, "mu": -0.1}, "load.mu"), ({"stroke": 1e-3, "mu": 0.2}, "load.mu"),
])
def test_a_bad_load_names_its_key(load: dict, parameter: str) -> None:
    with pytest.raises(InvalidTargetError) as caught:
        Load(**load)
    assert caught.value.parameter == parameter


def test_a_problem_needs_targets() -> None:
    with pytest.raises(InvalidTargetError, match="targets lists none"):
        ShapeProblem(WD, (), Limits(0.06))


def test_the_batch_solver_scores_tip_problems_as_evaluate_does_bit_for_bit() -> None:
    variables = VariableSet(PAPER, (Variable("w_n", 0.5e-3, 3e-3, "uniform"),
                                    Variable("w_d", 0.3e-3, 2.2e-3, "linear"),
                                    Variable("R_c", 1e-3, 3.5e-3)))
    problem = ShapeProblem(variables, (
        Goal(TipTarget(angle=0.8), Load(tension=10.0)),
        Goal(TipTarget(x=0.01, z=0.045, position_tol=1e-3), Load(tension=15.0))),
        Limits(0.04, min_backbone=0.4e-3))
    assert problem.batchable
    bounds = variables.bounds()
    xs = np.random.default_rng(0).uniform(bounds[:, 0], bounds[:, 1], (120, variables.size))
    singles = np.array([problem.evaluate(x).score for x in xs])
    assert np.array_equal(problem.scores(xs), singles)
    assert np.array_equal(problem.scores(xs, workers=2), singles)
    classes = set(np.floor(singles / PENALTY).astype(int).tolist())
    assert classes >= {0, 1, 2, 3}  # feasible, strained, failed, short of the backbone
    assert not problem_with_friction().batchable


def problem_with_friction() -> ShapeProblem:
    return ShapeProblem(WD, (Goal(TIP, Load(tension=20.0, mu=0.2)),), LIMITS)
