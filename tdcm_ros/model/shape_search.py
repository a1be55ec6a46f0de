"""Search a shape-design problem (:mod:`tdcm_ros.model.shape_problem`): a global stage by
SciPy's differential evolution, a local stage by SciPy's least squares.

Why these: the variables are continuous and bounded, the score has cliffs (Deb's feasibility
rules: failed solves, limits) and is not differentiable everywhere, so the global stage is a
population method that needs no gradient, seeds reproducibly and takes any map for parallel
evaluation: :func:`scipy.optimize.differential_evolution` (``updating="deferred"``: the
answer does not depend on ``workers``). Once a feasible candidate exists the targets are
residuals, so the local stage is :func:`scipy.optimize.least_squares` (trust-region
reflective, within the bounds) on the residual vector, the shape limits appended as stiff
penalty residuals (see :class:`_Local` for when it runs); the answer is the best of both.

The global stage stops early once its best candidate meets every target
(:attr:`~tdcm_ros.model.shape_problem.Evaluation.met`), at ``maxiter`` generations, or when
DE's population has converged.

Candidates are scored one ``solve`` each, or, where every target is a tip target at a
tension without friction (:attr:`~tdcm_ros.model.shape_problem.ShapeProblem.batchable`), a
generation at once by the batch solver (the same scores bit for bit, 2-3x faster).
``workers``: an int runs that many processes (``multiprocessing``; -1: every core), or that
many threads of the batch solver; a map-like callable ``workers(function, candidates)`` runs
the evaluations one by one wherever it sends them, e.g. a Dask cluster's
``lambda f, xs: client.gather(client.map(f, list(xs)))``.

A ``state`` file (JSON) holds the population after every generation; ``resume=True`` starts
from it (its variables must be the problem's), so an interrupted search goes on from where it
stopped (not bit for bit the uninterrupted one: the random stream restarts from ``seed``).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from time import perf_counter
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import ModelLimitError
from tdcm_ros.model.inverse import InvalidTargetError
from tdcm_ros.model.progress import Progress, report_progress
from tdcm_ros.model.shape_problem import PENALTY, Evaluation, ShapeProblem

Array = NDArray[np.float64]
Workers = int | Callable[[Callable[[Any], float], Iterable[Any]], Iterable[float]]

DEFAULT_POPSIZE = 15
DEFAULT_MAXITER = 300
#: Weight of a shape-limit violation in the local stage's residuals.
LIMIT_WEIGHT = 1e3
#: Residual of every entry where the local stage meets a failed candidate.
FAILED_RESIDUAL = 1e6
STATE_VERSION = 1


class NoShapeDesignError(ModelLimitError):
    """No candidate meets every target inside the limits; the message names the closest one
    found, ``found`` holds it."""

    kind = "no_shape_design"

    def __init__(self, message: str, *, found: ShapeDesign) -> None:
        super().__init__(message)
        self.found = found


@dataclass(frozen=True, eq=False)
class ShapeDesign:
    """A search's answer: the variable vector ``x``, its ``design`` and ``evaluation``, the
    generations run (``generations``, those of a resumed state included), the evaluations
    made (``evaluations``), the wall time (``seconds``) and the best score per generation."""

    problem: ShapeProblem
    x: Array
    evaluation: Evaluation
    generations: int
    evaluations: int
    seconds: float
    history: tuple[float, ...]

    @property
    def design(self) -> Design | None:
        """The design found (None if not even one candidate was a possible design)."""
        return self.evaluation.design

    def summary(self) -> dict[str, Any]:
        """JSON-ready: whether every target is met, the variables, each target's residuals
        and achieved values, each load's peak strain, the limits passed, the search's cost."""
        evaluation = self.evaluation
        goals = []
        for goal, residuals in zip(self.problem.goals, evaluation.residuals, strict=True):
            result = evaluation.results[goal.load]
            goals.append({"target": type(goal.target).__name__, "load": goal.load.label,
                          "max_residual": float(np.max(np.abs(residuals))),
                          "achieved": goal.target.achieved(result)})
        return {
            "met": evaluation.met, "objective": evaluation.objective,
            "variables": dict(zip(self.problem.variables.names(), self.x.tolist(), strict=True)),
            "targets": goals,
            "peak_strain": {load.label: float(np.max(result.notch_peak_strains))
                            for load, result in evaluation.results.items()},
            "tension_n": {load.label: result.tension_n
                          for load, result in evaluation.results.items()},
            "limits_passed": {k: v for k, v in evaluation.violations.items() if v > 0.0},
            "failure": evaluation.failure, "generations": self.generations,
            "evaluations": self.evaluations, "seconds": self.seconds,
        }


def _workers(workers: Workers) -> Workers:
    if callable(workers):
        return workers
    if isinstance(workers, bool) or not isinstance(workers, int) or workers == 0 or workers < -1:
        raise out_of_range("workers", workers, "a positive integer, -1 (every core) or a "
                           "map-like callable", error=InvalidTargetError)
    return len(os.sched_getaffinity(0)) if workers == -1 else workers


def _residual_vector(evaluation: Evaluation, size: int | None = None) -> Array:
    """The local stage's residuals of ``evaluation``: its targets' and the shape limits'
    (``size`` of them: a failed candidate's are all :data:`FAILED_RESIDUAL`)."""
    if size is not None and not evaluation.residuals:
        return np.full(size, FAILED_RESIDUAL)
    shape = [LIMIT_WEIGHT * v for k, v in evaluation.violations.items() if not k.startswith("min_")]
    return np.concatenate([*evaluation.residuals, shape])


class _Local:
    """The local stage: least squares from a feasible candidate. It runs after a generation
    whose best is feasible and at most half the score of the last start (so a few times per
    search, each a few dozen evaluations), and from DE's answer at the end unless one met; a
    start that meets every target ends the search. ``best`` is its best answer so far."""

    def __init__(self, problem: ShapeProblem, bounds: Array) -> None:
        self.problem, self.bounds = problem, bounds
        self.best: tuple[Array, float] | None = None
        self.met = False  # whether ``best`` meets every target
        self.started_at = math.inf
        self.evaluations = 0

    def due(self, score: float) -> bool:
        """Whether a generation's best ``score`` (feasible below PENALTY) deserves a start."""
        return score < PENALTY and score <= 0.5 * self.started_at

    def run(self, x0: Array) -> tuple[Array, float]:
        """Least squares from ``x0``; keeps and returns the better of it and ``best``."""
        from scipy.optimize import least_squares

        start = self.problem.evaluate(x0)
        self.started_at = start.score
        self.evaluations += 1
        if start.feasible:
            size = _residual_vector(start).size

            def residuals(x: Array) -> Array:
                return _residual_vector(self.problem.evaluate(x), size)

            fit = least_squares(residuals, x0, bounds=(self.bounds[:, 0], self.bounds[:, 1]),
                                x_scale="jac", diff_step=np.full(x0.size, 1e-6),
                                max_nfev=10 * (x0.size + 1))
            self.evaluations += int(fit.nfev) + int(fit.njev or 0) * x0.size
            self._keep(np.asarray(fit.x, dtype=float), self.problem.evaluate(fit.x))
        self._keep(np.asarray(x0, dtype=float), start)
        assert self.best is not None  # kept just now
        return self.best

    def _keep(self, x: Array, evaluation: Evaluation) -> None:
        """``x`` as ``best`` if it scores lower (the first always)."""
        if self.best is None or evaluation.score < self.best[1]:
            self.best, self.met = (x, evaluation.score), evaluation.met


def _read_state(path: Path, problem: ShapeProblem) -> tuple[Array, int, list[float]]:
    """The population (S, n), generations and score history of a state file."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        names, population = data["variables"], np.array(data["population"], dtype=float)
        generations, history = int(data["generations"]), [float(v) for v in data["history"]]
        version = data["version"]
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise out_of_range("resume", str(path), f"a state file this search wrote ({error})",
                           error=InvalidTargetError) from error
    expected = list(problem.variables.names())
    if version != STATE_VERSION or names != expected or population.ndim != 2 or \
            population.shape[1] != len(expected) or population.shape[0] < 5:
        raise out_of_range("resume", str(path), f"a state of the variables {expected}",
                           error=InvalidTargetError)
    return population, generations, history


def _write_state(path: Path, problem: ShapeProblem, population: Array, generations: int,
                 history: list[float]) -> None:
    data = {"version": STATE_VERSION, "variables": list(problem.variables.names()),
            "generations": generations, "history": history, "population": population.tolist()}
    temporary = path.with_name(path.name + ".tmp")
    temporary.write_text(json.dumps(data), encoding="utf-8")
    temporary.replace(path)


def design_for_shape(problem: ShapeProblem, *, seed: int = 0, popsize: int = DEFAULT_POPSIZE,
                     maxiter: int = DEFAULT_MAXITER, workers: Workers = 1,
                     progress: Progress | None = None, state: str | Path | None = None,
                     resume: bool = False) -> ShapeDesign:
    """Search ``problem`` (see the module docstring): ``popsize`` candidates per variable
    per generation, at most ``maxiter`` generations. Raises :class:`NoShapeDesignError`
    naming the closest candidate when none meets every target inside the limits."""
    from scipy.optimize import Bounds, OptimizeResult, differential_evolution

    for name, value, low in (("seed", seed, 0), ("popsize", popsize, 5), ("maxiter", maxiter, 1)):
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= 10**7:
            raise out_of_range(name, value, f"an integer in [{low}, 10000000]",
                               error=InvalidTargetError)
    pool = _workers(workers)
    bounds = problem.variables.bounds()
    state_path = None if state is None else Path(state)
    if resume and state_path is None:
        raise out_of_range("resume", resume, "with a state file", error=InvalidTargetError)
    init: Any = "latinhypercube"
    generations, history = 0, list[float]()
    if resume and state_path is not None and state_path.exists():
        init, generations, history = _read_state(state_path, problem)
    started, first = perf_counter(), generations
    local = _Local(problem, bounds)

    def generation(intermediate_result: OptimizeResult) -> None:
        nonlocal generations
        generations += 1
        history.append(float(intermediate_result.fun))
        if state_path is not None:
            _write_state(state_path, problem, np.asarray(intermediate_result.population),
                         generations, history)
        report_progress(progress, "search", generations - first, maxiter)
        if local.due(float(intermediate_result.fun)):
            local.run(np.asarray(intermediate_result.x, dtype=float))
        if local.met:
            raise StopIteration  # DE's way to stop from a callback

    batch = problem.batchable and isinstance(pool, int)

    def scores(columns: Array) -> Array:  # DE's vectorised call: one candidate per column
        return problem.scores(columns.T, workers=pool if isinstance(pool, int) else 1)

    objective: Any = scores if batch else problem  # the stubs know no vectorised objective
    found = differential_evolution(
        objective, Bounds(bounds[:, 0], bounds[:, 1]), popsize=popsize,
        maxiter=maxiter, init=init, rng=seed, callback=generation, polish=False,
        updating="deferred", workers=1 if batch else pool, vectorized=batch, tol=1e-6)
    x, _ = local.best if local.met and local.best is not None else local.run(
        np.asarray(found.x, dtype=float))
    evaluation = problem.evaluate(x)
    answer = ShapeDesign(problem, x, evaluation, generations,
                         int(found.nfev) + local.evaluations, perf_counter() - started,
                         tuple(history))
    if not evaluation.met:
        raise NoShapeDesignError(_closest(answer), found=answer)
    return answer


def _closest(found: ShapeDesign) -> str:
    """Why the search failed, naming the closest candidate's variables and shortfalls."""
    evaluation = found.evaluation
    values = ", ".join(f"{name} = {value:.6g}" for name, value in
                       zip(found.problem.variables.names(), found.x, strict=True))
    if not evaluation.feasible:
        why = evaluation.failure or "; ".join(
            f"{k} passed by {v:.3g}" for k, v in evaluation.violations.items() if v > 0.0)
        return (f"no candidate is inside every limit after {found.generations} generations; "
                f"the closest ({values}): {why}")
    worst = [f"target {i + 1} residual {float(np.max(np.abs(r))):.3g} (|r| <= 1 meets it)"
             for i, r in enumerate(evaluation.residuals) if np.any(np.abs(r) > 1.0)]
    return (f"no candidate meets every target after {found.generations} generations; the "
            f"closest ({values}) misses " + ", ".join(worst) +
            (f"; objective {evaluation.objective:.4g}" if math.isfinite(evaluation.objective)
             else ""))
