"""A shape-design problem: free variables over a base body, shape targets each at a load, hard
limits; and the evaluation of one candidate (SI units).

A :class:`Load` is a tendon tension (N) or a tendon stroke (m, the actuator's travel, found by
:func:`~tdcm_ros.model.inverse.solve_inverse` within ``tension_max``), optionally with capstan
friction ``mu`` along the tendon (:class:`~tdcm_ros.model.loading.Capstan`, tension only).
Each :class:`Goal` is a target (:mod:`tdcm_ros.model.shape_targets`) at a load; the candidate
is solved once per distinct load, and the limits hold at every one.

:meth:`ShapeProblem.evaluate` gives an :class:`Evaluation`; :attr:`Evaluation.score` orders
candidates for a search, Deb's feasibility rules as one number: a feasible candidate scores
its objective (the sum of squared residuals, below :data:`PENALTY`); an infeasible one
:data:`PENALTY` plus how far it passes the shape limits; one whose solve fails (a notch
closes, the tendon singularity, no convergence, the material's strain limit) ``2 PENALTY``;
one short of a fabrication minimum ``3 PENALTY`` plus the shortfall (mm); an impossible design
``4 PENALTY``. So every feasible candidate beats every infeasible one, and among infeasible
ones the nearer to feasibility wins.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.design import Design
from tdcm_ros.model.design_variables import VariableSet
from tdcm_ros.model.errors import InvalidDesignError, ModelLimitError
from tdcm_ros.model.inverse import (
    DEFAULT_TENSION_MAX_N,
    InvalidTargetError,
    solve_inverse,
)
from tdcm_ros.model.loading import Capstan, Loading
from tdcm_ros.model.result import ConvergenceError, SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.shape_targets import Limits, NotchAngleTarget, Target, TipTarget
from tdcm_ros.model.solver import DEFAULT_SETTINGS, solve

Array = NDArray[np.float64]

#: Largest capstan friction coefficient (that of :class:`~tdcm_ros.model.loading.Capstan`).
MAX_MU = 10.0
#: The score step between feasibility classes (see the module docstring).
PENALTY = 1e12


@dataclass(frozen=True)
class Load:
    """A tendon ``tension`` (N) or ``stroke`` (m), one of them, and capstan friction ``mu``."""

    tension: float | None = None
    stroke: float | None = None
    mu: float = 0.0

    def __post_init__(self) -> None:
        if (self.tension is None) == (self.stroke is None):
            raise InvalidTargetError("load gives neither or both of tension and stroke; "
                                     "allowed: one", parameter="load",
                                     value={"tension": self.tension, "stroke": self.stroke},
                                     allowed="tension (N) or stroke (m)")
        for name, top in (("tension", 1e6), ("stroke", 1.0)):
            value = getattr(self, name)
            if value is not None and (isinstance(value, bool) or not isinstance(
                    value, (int, float)) or not 0.0 < value <= top):
                raise out_of_range(f"load.{name}", value, f"(0, {top:g}]",
                                   unit="N" if name == "tension" else "m",
                                   error=InvalidTargetError)
        if isinstance(self.mu, bool) or not isinstance(self.mu, (int, float)) or \
                not 0.0 <= self.mu <= MAX_MU:
            raise out_of_range("load.mu", self.mu, f"[0, {MAX_MU:g}]", error=InvalidTargetError)
        if self.stroke is not None and self.mu != 0.0:
            raise out_of_range("load.mu", self.mu, "0 with a stroke load (the stroke's "
                               "tension is found without friction)", error=InvalidTargetError)

    @property
    def label(self) -> str:
        """``20 N``, ``0.6 mm stroke``, with ``, mu 0.2`` where there is friction."""
        text = f"{self.tension:g} N" if self.tension is not None else \
            f"{self.stroke * 1e3:g} mm stroke"  # type: ignore[operator]
        return text + (f", mu {self.mu:g}" if self.mu else "")


@dataclass(frozen=True)
class Goal:
    """A target at a load."""

    target: Target
    load: Load


@dataclass(frozen=True, eq=False)
class Evaluation:
    """One candidate: its ``design`` (None if impossible), per goal its ``residuals``, the
    ``violations`` of each limit (0 where it holds; fabrication in m, strain relative, stop
    margin rad), each load's ``results``, and why it failed (``failure``, empty if it did not)."""

    design: Design | None
    residuals: tuple[Array, ...]
    violations: dict[str, float]
    results: dict[Load, SolveResult]
    failure: str = ""
    #: Deb's feasibility rules as one number; orders candidates for a search (see the module
    #: docstring).
    score: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "score", self._score())

    def _score(self) -> float:
        if self.design is None:
            return 4.0 * PENALTY
        fabrication = sum(v for k, v in self.violations.items() if k.startswith("min_"))
        if fabrication > 0.0:
            return 3.0 * PENALTY + 1e3 * fabrication
        if self.failure:
            return 2.0 * PENALTY
        shape = sum(v for k, v in self.violations.items() if not k.startswith("min_"))
        if shape > 0.0:
            return PENALTY + shape
        return min(self.objective, 0.5 * PENALTY)

    @property
    def objective(self) -> float:
        """Sum of squared residuals (inf where there are none: the candidate failed)."""
        if not self.residuals:
            return math.inf
        return float(sum(np.sum(r**2) for r in self.residuals))

    @property
    def feasible(self) -> bool:
        """Solved, inside every limit."""
        return self.score < PENALTY

    @property
    def met(self) -> bool:
        """Feasible, every residual within [-1, 1]: every target met within its tolerance."""
        return self.feasible and all(np.all(np.abs(r) <= 1.0) for r in self.residuals)


@dataclass(frozen=True, eq=False)
class ShapeProblem:
    """Free ``variables``, ``goals``, hard ``limits``, solver ``settings`` and, for stroke
    loads, the tension bracket's top ``tension_max`` (N)."""

    variables: VariableSet
    goals: tuple[Goal, ...]
    limits: Limits
    settings: SolverSettings = DEFAULT_SETTINGS
    tension_max: float = DEFAULT_TENSION_MAX_N

    def __post_init__(self) -> None:
        if not self.goals:
            raise InvalidTargetError("targets lists none; allowed: one or more of tip, curve, "
                                     "notch_angles, stop_angle", parameter="targets",
                                     value=[], allowed="a non-empty list")
        for goal in self.goals:
            if isinstance(goal.target, NotchAngleTarget):
                goal.target.check_notches(self.variables.base.N)

    @property
    def loads(self) -> tuple[Load, ...]:
        """The distinct loads of the goals, in their order."""
        return tuple(dict.fromkeys(goal.load for goal in self.goals))

    def evaluate(self, x: Any) -> Evaluation:
        """The candidate of variable vector ``x`` (see :class:`Evaluation`)."""
        try:
            design = self.variables.design(x)
        except InvalidDesignError as error:
            return Evaluation(None, (), {}, {}, str(error))
        violations = self.limits.fabrication(design)
        if any(v > 0.0 for v in violations.values()):
            return Evaluation(design, (), violations, {}, "short of a fabrication minimum")
        results: dict[Load, SolveResult] = {}
        try:
            for load in self.loads:
                results[load] = self._solve(design, load)
        except (ModelLimitError, ConvergenceError, InvalidDesignError) as error:
            return Evaluation(design, (), violations, results, str(error))
        for result in results.values():
            for name, value in self.limits.shape(result).items():
                violations[name] = max(violations.get(name, 0.0), value)
        residuals = tuple(goal.target.residuals(results[goal.load]) for goal in self.goals)
        return Evaluation(design, residuals, violations, results)

    @property
    def batchable(self) -> bool:
        """Whether the batch solver scores candidates (:meth:`scores`): every target a tip
        target at a tension without friction, one tendon, no stop margin asked for."""
        return (all(isinstance(goal.target, TipTarget) and goal.load.tension is not None
                    and goal.load.mu == 0.0 for goal in self.goals)
                and self.limits.stop_margin == 0.0
                and len(self.variables.base.tendon_list()) == 1)

    def scores(self, xs: Any, workers: int = 1) -> Array:
        """The score (:attr:`Evaluation.score`) of each row of ``xs`` (candidates, variables):
        by one batch solve of every candidate at every load (``workers`` threads) where the
        problem is :attr:`batchable` (the same numbers as :meth:`evaluate`'s, bit for bit),
        else candidate by candidate."""
        rows = np.atleast_2d(np.asarray(xs, dtype=float))
        if not self.batchable:
            return np.array([self(x) for x in rows])
        out = np.full(len(rows), 4.0 * PENALTY)
        designs, solved = [], []
        for i, x in enumerate(rows):
            try:
                design = self.variables.design(x)
            except InvalidDesignError:
                continue
            shortfall = sum(self.limits.fabrication(design).values())
            if shortfall > 0.0:
                out[i] = 3.0 * PENALTY + 1e3 * shortfall
                continue
            designs.append(design)
            solved.append(i)
        if not designs:
            return out
        loads = self.loads
        tensions = np.tile([float(load.tension or 0.0) for load in loads], (len(designs), 1))
        batch = solve_batch(designs, tensions, settings=self.settings, workers=workers)
        failed = np.any(batch.status != "ok", axis=1)
        strain = np.max(np.maximum(0.0, batch.max_bending_strain / self.limits.max_strain - 1.0),
                        axis=1)
        objective = np.zeros(len(designs))
        for goal in self.goals:
            j = loads.index(goal.load)
            target = goal.target
            assert isinstance(target, TipTarget)  # batchable
            residuals = target.tip_residuals(batch.tip_position[:, j], batch.tip_angle_rad[:, j])
            objective += np.sum(residuals**2, axis=1)
        score = np.where(strain > 0.0, PENALTY + strain, np.minimum(objective, 0.5 * PENALTY))
        out[solved] = np.where(failed, 2.0 * PENALTY, score)
        return out

    def _solve(self, design: Design, load: Load) -> SolveResult:
        if load.stroke is not None:
            return solve_inverse(design, tendon_stroke=load.stroke, tension_max=self.tension_max,
                                 settings=self.settings).result
        loading = Loading(tension_profile=Capstan(load.mu)) if load.mu else None
        tensions: float | list[float] = load.tension  # type: ignore[assignment]
        if len(design.tendon_list()) > 1:
            tensions = [load.tension or 0.0] + [0.0] * (len(design.tendon_list()) - 1)
        return solve(design, tensions, settings=self.settings, loading=loading)

    def __call__(self, x: Any) -> float:
        """The score of ``x`` (a search's objective; picklable with the problem)."""
        return self.evaluate(x).score
