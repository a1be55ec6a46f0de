"""Algorithm 1: the fixed point between the tendon's moment and the body's shape.

Each iteration computes the moment of the current shape (eq. 11, closed or literal form),
the curvature ``kappa = m / (E I)`` (eq. 14) and the new shape by exact planar integration
(eq. 2), until no midline node moves more than ``tol``. The unknown of the fixed point is
the vector of cell end moments.

Convergence strategy (``acceleration="auto"``): plain iteration while it contracts fast;
Anderson mixing once it slows; if that fails, damped relaxation; if that fails, load
continuation (tension ramped in ``continuation_steps`` warm-started steps). Under a
loading: plain iteration, handing over to Anderson restarted from the initial iterate if it
slows (a quarter of ``max_iter``), then adaptive continuation, then relaxation.
Failure after all of them raises :class:`ConvergenceError`. The moment model
(:mod:`tdcm_ros.model.moment_model`: closed form, literal sum, or a
:class:`~tdcm_ros.model.loading.Loading`) supplies the moments, its strategy list and its
physical-limit checks before and after iterating; the closed form's plain iteration runs in
the compiled kernel (:func:`tdcm_ros.model.kernel.iterate`).

The common case (no loading, one paper-like tendon, ``loads=closed``, ``acceleration=auto``,
a linear material) first takes a fast path: the closed form of the last design and settings
objects (kept by identity), one compiled call of its plain iteration into one buffer, and a
:class:`SolveResult` that makes its arrays from that buffer on use. When that call does not
converge with every notch open, the general path solves from the start; either way the
result is the same to the bit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from time import perf_counter
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.compiled import is_compiled
from tdcm_ros.model.design import Design, preset
from tdcm_ros.model.errors import InvalidSettingsError
from tdcm_ros.model.grid import Grid, build_grid, on_clear
from tdcm_ros.model.kernel import CONVERGED, DIVERGING, NON_FINITE, SLOWED
from tdcm_ros.model.kinematics import PlanarShape, integrate
from tdcm_ros.model.limits import check_tension, check_tensions, notch_gaps
from tdcm_ros.model.loading import InvalidLoadingError, LoadedModel, Loading
from tdcm_ros.model.material_model import MaterialLaw
from tdcm_ros.model.moment_model import (
    AUTO_PLAN,
    DIVERGENCE_GROWTH,
    ClosedForm,
    LiteralSum,
    MomentModel,
    PlainRun,
    Plan,
)
from tdcm_ros.model.quiet import quiet_fp
from tdcm_ros.model.result import ConvergenceError, SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.tendon_model import TendonSet
from tdcm_ros.model.tendons import is_paper_like

Array = NDArray[np.float64]

DEFAULT_SETTINGS = SolverSettings()
SLOW_CONTRACTION = 0.3
CONTINUATION_HALVINGS = 5


class _Problem(NamedTuple):
    """What the strategies iterate: a moment model on its grid, under settings."""

    grid: Grid
    settings: SolverSettings
    model: MomentModel

    def shape_of(self, x: Array, level: float) -> PlanarShape:
        """Shape integrated from the bending moments of ``x = [m_a, m_b]`` (N m) at tension
        ``level`` (N; it bows the moment on chords)."""
        y = self.model.bend_moments(x)
        n = self.grid.n_cells
        return integrate(self.grid, y[:n], y[n:], self.model.chord_tension(level),
                         self.model.axis_tension(level))



@dataclass
class _Run:
    """Outcome of one strategy: the last iterate, its residuals and whether it converged."""

    x: Array
    shape: PlanarShape
    history: list[float]
    converged: bool
    reason: str
    min_gap: float | None = None


def solve(design: Design, tension: float | Sequence[float], *,
          settings: SolverSettings = DEFAULT_SETTINGS,
          warm_start: SolveResult | None = None, strict: bool = True,
          loading: Loading | None = None) -> SolveResult:
    """Shape of ``design`` under tendon tension ``tension`` (N), the tension at the base: one
    number, or one per tendon of a design with several (``Design.tendons``: the paper's closed
    form, no ``loading``; ``warm_start`` is not used).

    ``warm_start`` reuses a previous result of the same design and settings as the initial
    iterate (scaled by the tension ratio). With ``strict=False`` a non-converged solve returns
    its last finite iterate with ``converged=False`` instead of raising. ``loading`` adds a
    varying tension, external loads and notch contact; None (or ``Loading()``) is the paper's
    model.

    Floating-point overflow at hostile inputs is handled, not printed: a non-finite iterate ends
    its strategy, the limits compare an overflowed ``R_c kappa`` correctly, and no non-finite
    value reaches LAPACK; so NumPy's overflow and invalid-value warnings are off on every
    NumPy path of the solve (:func:`~tdcm_ros.model.quiet.quiet_fp`; the compiled kernel
    raises none).
    """
    started = perf_counter()
    if loading is None:
        result = _solve_closed(design, tension, settings, warm_start, started)
        if result is not None:
            return result
    if is_paper_like(design.tendons):
        if isinstance(tension, (list, tuple, np.ndarray)):
            tension = check_tensions(tension, 1)[0]
        return _solve(design, check_tension(tension), settings, warm_start, strict, loading,
                      started)
    tensions = np.array(check_tensions(tension, len(design.tendons)))
    return _solve(design, float(np.max(tensions)), settings, warm_start, strict, loading,
                  started, tensions)


def warm_up() -> bool:
    """Compile (or load from the cache) every kernel a solve can reach, so that the first
    real solve of a long-running process is not slow; returns whether the kernels are the
    compiled build. Under the plain build it costs three small solves."""
    design = preset("paper-experiment")
    result = solve(design, 1.0)  # kernel.iterate_one from the own moment
    solve(design, 1.0, warm_start=result)  # and from a given start
    solve(design, 1.0, settings=DEFAULT_SETTINGS.with_overrides(acceleration="anderson"))
    notch_gaps(result.grid, integrate(result.grid, result.cell_moments[:, 0],
                                      result.cell_moments[:, 1], 1.0))  # the wrappers
    return is_compiled()


def _closed_form(design: Design, settings: SolverSettings) -> ClosedForm | None:
    """The paper's closed form on the grid of ``design`` under ``settings`` where they ask for
    it and the default strategy (a linear material, ``loads=closed``, ``acceleration=auto``),
    else None; kept for the last pair, by identity (both are frozen: a node or a loop solves
    the same objects again and again; :func:`~tdcm_ros.model.grid.clear_grid_cache` forgets
    it)."""
    last = _last_closed.get("pair")
    if last is not None and last[0] is design and last[1] is settings:
        return last[2]
    model = None
    if settings.acceleration == "auto":  # the model the general path takes, if the closed form
        found = _problem(design, settings, 0.0, None).model
        model = found if type(found) is ClosedForm else None
    _last_closed["pair"] = (design, settings, model)
    return model


_last_closed: dict[str, tuple[Design, SolverSettings, ClosedForm | None]] = {}
on_clear(_last_closed.clear)


def _solve_closed(design: Design, tension: float | Sequence[float], settings: SolverSettings,
                  warm_start: SolveResult | None, started: float) -> SolveResult | None:
    """:func:`solve` without a loading where its first strategy settles it: one paper-like
    tendon at one ``tension`` (N), :func:`_closed_form`, and its plain iteration (one
    compiled call) converges with every notch open. None otherwise: then the general path
    solves from the start (its other strategies need it; the compiled part it repeats costs
    microseconds against their milliseconds). ``started``: the solve's start (s,
    ``perf_counter``)."""
    if isinstance(tension, (list, tuple, np.ndarray)) or not is_paper_like(design.tendons):
        return None
    level = check_tension(tension)
    model = _closed_form(design, settings)
    if model is None:
        return None
    model.check_before(level)
    x0 = None if warm_start is None else _warm_guess(model.grid, settings, level, warm_start,
                                                      model)
    out, steps, status, gap = model.run(x0, level, settings.max_iter, settings.tol, 1.0,
                                        SLOW_CONTRACTION)
    if status != CONVERGED or not gap > 0.0:
        return None
    return SolveResult.of_run(model.grid, settings, level, out, steps, AUTO_PLAN,
                              perf_counter() - started)


def _solve(design: Design, t_base: float, settings: SolverSettings,
           warm_start: SolveResult | None, strict: bool, loading: Loading | None,
           started: float, tensions: Array | None = None) -> SolveResult:
    """:func:`solve` for a checked base tension ``t_base`` (N; the largest of ``tensions``,
    one per tendon where the design lists them); ``started`` is its start time (s,
    ``perf_counter``)."""
    problem = _problem(design, settings, t_base, loading, tensions)
    grid, _, model = problem
    model.check_before(t_base)
    x0 = _initial_guess(grid, settings, t_base, warm_start, model)

    runs: list[tuple[str, _Run]] = []
    history: list[float] = []
    budget = settings.max_iter
    for plan in model.plans(settings):
        run = _run_plan(problem, plan, t_base, x0, min(budget, plan.budget))
        runs.append((plan.name, run))
        history += run.history
        budget -= len(run.history)
        if run.converged or budget <= 0:
            break
    last = _last_finite(runs)
    if last is None:
        raise ConvergenceError(
            f"Algorithm 1 found no finite iterate at tension {t_base:g} N ({_reasons(runs)})")
    strategy, final = last
    if final.converged:
        model.check_after(final.x, final.shape, t_base, final.min_gap)
    result = _result(grid, settings, t_base, final, strategy, tuple(history),
                     perf_counter() - started, loading, model)
    if not final.converged and strict:
        raise ConvergenceError(
            f"Algorithm 1 did not converge to tol = {settings.tol:g} m at tension {t_base:g} N "
            f"within max_iter = {settings.max_iter} ({_reasons(runs)})", result=result)
    return result


def _reasons(runs: list[tuple[str, _Run]]) -> str:
    """Why each strategy run stopped, for an error message."""
    return "; ".join(f"{name}: {r.reason}" for name, r in runs)


def _last_finite(runs: list[tuple[str, _Run]]) -> tuple[str, _Run] | None:
    """The last strategy run whose iterate (N m) and shape (m, rad) are all finite, if any.
    A converged run is: its last step, a finite distance between finite shapes, ends it."""
    for name, run in reversed(runs):
        if run.converged or (np.all(np.isfinite(run.x)) and np.all(np.isfinite(run.shape.p))
                             and np.all(np.isfinite(run.shape.theta))):
            return name, run
    return None


def _problem(design: Design, settings: SolverSettings, tension: float,
             loading: Loading | None, tensions: Array | None = None) -> _Problem:
    """The (cached) grid of ``design`` under ``settings`` and its moment model under
    ``loading`` at ``tension`` (N), or its tendons' at ``tensions`` (N, largest ``tension``)."""
    grid = build_grid(design, settings)
    model: MomentModel = _model(grid, settings, tension, loading) if tensions is None else \
        _tendon_model(grid, settings, tension, tensions, loading)
    if not design.material.is_trivial:
        model = MaterialLaw(model, design.material)
    return _Problem(grid, settings, model)


def _tendon_model(grid: Grid, settings: SolverSettings, level: float, tensions: Array,
                  loading: Loading | None) -> TendonSet:
    """The moment model of the design's tendons at ``tensions`` (N; ``level`` the largest)."""
    if loading is not None and not (isinstance(loading, Loading) and loading.is_trivial):
        raise InvalidLoadingError(
            "loading is not supported with several tendons (a tendon list in the design); "
            "allowed: None", parameter="loading", value=getattr(loading, "describe",
                                                                 lambda: loading)(),
            allowed="None")
    if settings.loads != "closed":
        raise InvalidSettingsError(
            f"loads = {settings.loads!r} is not supported with several tendons (a tendon list "
            "in the design); allowed: closed", parameter="loads", value=settings.loads,
            allowed="closed")
    fractions = tensions / level if level > 0.0 else np.zeros_like(tensions)
    return TendonSet(grid, settings.routing, fractions)


def _model(grid: Grid, settings: SolverSettings, tension: float,
           loading: Loading | None) -> MomentModel:
    """The moment model of ``settings.loads`` under ``loading`` (None or trivial: the
    paper's)."""
    if loading is not None and not isinstance(loading, Loading):
        raise InvalidLoadingError(f"loading = {loading!r} is not a Loading; allowed: None or "
                                  "Loading(...)", parameter="loading", value=loading,
                                  allowed="None | Loading")
    if loading is None or loading.is_trivial:
        return _paper_model(grid, settings.loads)
    if settings.loads != "closed":
        raise InvalidLoadingError(
            f"loading is not supported with loads = {settings.loads!r}; allowed: loads=closed "
            "(the literal sum of eqs. 8-10 assumes a constant tension and no external load)",
            parameter="loading", value=loading.describe(), allowed="loads=closed")
    return LoadedModel(grid, loading, tension)


@lru_cache(maxsize=512)
@quiet_fp
def _paper_model(grid: Grid, loads: str) -> MomentModel:
    """The paper's moment model of ``loads`` on ``grid`` (cached: it holds only the grid)."""
    return ClosedForm(grid) if loads == "closed" else LiteralSum(grid)


def _initial_guess(grid: Grid, settings: SolverSettings, tension: float,
                   warm_start: SolveResult | None, model: MomentModel) -> Array:
    """The tendons' own moments on the straight body (the model's ``start``: ``R_c T``
    everywhere for the paper's tendon), or :func:`_warm_guess`."""
    warm = _warm_guess(grid, settings, tension, warm_start, model)
    return model.start(tension) if warm is None else warm


def _warm_guess(grid: Grid, settings: SolverSettings, tension: float,
                warm_start: SolveResult | None, model: MomentModel) -> Array | None:
    """A compatible converged result's moments (N m) rescaled to ``tension`` (N) by the model's
    :meth:`~tdcm_ros.model.moment_model.MomentModel.warm_scale`, or None."""
    if (warm_start is not None and warm_start.grid is grid and warm_start.converged
            and (warm_start.settings is settings or warm_start.settings == settings)):
        scale = model.warm_scale(warm_start.tension_n, tension)
        if scale is not None:
            return _rescaled(warm_start.cell_moments, scale)
    return None


@quiet_fp
def _rescaled(moments: Array, scale: float) -> Array:
    """Cell moments (cells, 2) N m as the iterate ``[m_a, m_b]`` times ``scale``."""
    return np.concatenate([moments[:, 0], moments[:, 1]]) * scale


def _run_plan(problem: _Problem, plan: Plan, tension: float, x0: Array, budget: int) -> _Run:
    """Run one strategy of the model's list."""
    if plan.mode == "continuation":
        return _continuation(problem, tension, x0, budget, adaptive=plan.adaptive)
    return _iterate(problem, tension, x0, budget, mode=plan.mode, restart=plan.restart)


@quiet_fp
def _continuation(problem: _Problem, tension: float, x0: Array, budget: int, *,
                  adaptive: bool = False) -> _Run:
    """Ramp the tension (and any external loads) in equal steps, each warm-started from the
    previous solution; ``adaptive`` halves a failing step (see :func:`_adaptive_continuation`)."""
    if adaptive:
        return _adaptive_continuation(problem, tension, x0, budget)
    settings = problem.settings
    steps = settings.continuation_steps
    x = problem.model.start(tension / steps)
    history: list[float] = []
    run = _Run(x, problem.shape_of(x, tension / steps), history, False, "no steps")
    previous = tension / steps
    for k in range(1, steps + 1):
        level = tension * k / steps
        x = x * (level / previous if previous > 0.0 else k / (k - 1) if k > 1 else 1.0)
        previous = level
        run = _iterate(problem, level, x, budget - len(history), mode="anderson",
                       factor=k / steps)
        history.extend(run.history)
        if not run.converged:
            return _Run(run.x, run.shape, history, False,
                        f"step {k}/{steps} at {level:g} N: {run.reason}")
        x = run.x
    return _Run(run.x, run.shape, history, True, "converged")


def _adaptive_continuation(problem: _Problem, tension: float, x0: Array, budget: int) -> _Run:
    """Continuation on the load factor ``lam`` in [0, 1] (tension and external loads together):
    steps start at ``1/continuation_steps``; a step that fails is retried from the last solution
    at half the size (down to ``2**-CONTINUATION_HALVINGS`` of it) and a step that succeeds
    lets the next one double back. Each step is predicted by scaling the last solution and
    solved to the loose tolerance ``sqrt(tol * L)`` (it only seeds the next one); the last
    step to ``tol``."""
    largest = 1.0 / problem.settings.continuation_steps
    smallest = largest / 2**CONTINUATION_HALVINGS
    step = largest
    lam = 0.0
    x = np.zeros_like(x0)
    history: list[float] = []
    run = _Run(x, problem.shape_of(x, 0.0), history, False, "no steps")
    tol = problem.settings.tol
    loose = max(tol, math.sqrt(tol * problem.grid.design.length))
    while lam < 1.0:
        target = 1.0 if lam + step >= 1.0 - 1e-12 else lam + step
        guess = x * (target / lam) if lam > 0.0 else problem.model.start(tension * target)
        run = _iterate(problem, tension * target, guess, budget - len(history),
                       mode="anderson", factor=target, tol=tol if target == 1.0 else loose)
        history.extend(run.history)
        if run.converged:
            lam, x = target, run.x
            step = min(2.0 * step, largest)
            continue
        if step <= smallest or len(history) >= budget:
            return _Run(run.x, run.shape, history, False,
                        f"load factor {target:.4g} (step {step:.3g}): {run.reason}")
        step *= 0.5
    return _Run(run.x, run.shape, history, True, "converged")


def _iterate(problem: _Problem, tension: float, x0: Array, budget: int, *, mode: str,
             factor: float = 1.0, tol: float | None = None, restart: bool = False) -> _Run:
    """Fixed-point iteration on the cell moments; ``mode`` picks the update rule. ``factor``
    scales the external loads (continuation); ``tol`` (m) defaults to ``settings.tol``. With
    ``restart``, plain iteration that slows down (mode ``auto``) hands over to Anderson from
    ``x0`` rather than from wherever it has wandered."""
    settings, model = problem.settings, problem.model
    tol = settings.tol if tol is None else tol
    using = "picard" if mode == "auto" else mode
    plain = None
    if using in ("picard", "relaxation"):
        plain = model.plain(x0, tension, budget, tol,
                            settings.relaxation if using == "relaxation" else 1.0,
                            SLOW_CONTRACTION if mode == "auto" else 0.0)
    if plain is None:
        return _iterate_in_numpy(problem, tension, x0, None, budget, mode=mode, using=using,
                                 factor=factor, tol=tol, restart=restart)
    if plain.status != SLOWED:
        return _plain_outcome(plain)
    return _iterate_in_numpy(problem, tension, x0, plain, budget, mode=mode, using="anderson",
                             factor=factor, tol=tol, restart=restart)


@quiet_fp
def _iterate_in_numpy(problem: _Problem, tension: float, x0: Array, plain: PlainRun | None,
                      budget: int, *, mode: str, using: str, factor: float, tol: float,
                      restart: bool) -> _Run:
    """:func:`_iterate`'s update rule ``using`` run in NumPy from ``x0``, or from where the
    compiled ``plain`` iteration slowed down (Anderson)."""
    grid, settings, model = problem
    if plain is None:
        x, shape, history = x0, problem.shape_of(x0, tension), []
    else:
        x, shape, history = plain.x, plain.shape, plain.history
        if restart:
            x, shape = x0, problem.shape_of(x0, tension)
    start = shape  # what plain iteration that slows restarts from (restart=True)
    d_x: list[Array] = []
    d_f: list[Array] = []
    last: tuple[Array, Array] | None = None
    length = grid.design.length
    for _ in range(max(budget - len(history), 0)):
        g = model.moments(shape, x, tension, factor)
        f = g - x
        if using == "anderson":
            x_new = _anderson_step(x, f, last, d_x, d_f, settings.anderson_depth)
            if x_new is None:
                return _Run(x, shape, history, False,
                            "Anderson least squares failed (non-finite residual or no SVD)")
            last = (x, f)
        elif using == "relaxation":
            x_new = x + settings.relaxation * f
        else:
            x_new = g
        new_shape = problem.shape_of(x_new, tension)
        step = float(np.max(np.abs(new_shape.p - shape.p)))
        if not np.isfinite(step):
            return _Run(x, shape, history, False, "iterate became non-finite")
        history.append(step)
        x, shape = x_new, new_shape
        if step <= tol:
            return _Run(x, shape, history, True, "converged")
        if step > 2.0 * length or (len(history) > 5 and step > DIVERGENCE_GROWTH * min(history)):
            return _Run(x, shape, history, False, f"diverging (step {step:.3g} m)")
        if mode == "auto" and using == "picard" and len(history) >= 2 and \
                step > SLOW_CONTRACTION * history[-2]:
            using = "anderson"
            if restart:
                x, shape = x0, start
    return _Run(x, shape, history, False,
                f"budget exhausted, last step {history[-1]:.3g} m" if history else "no budget")


def _plain_outcome(plain: PlainRun) -> _Run:
    """The run of a compiled plain iteration that stopped (not to hand over)."""
    x, shape, history = plain.x, plain.shape, plain.history
    if plain.status == CONVERGED:
        return _Run(x, shape, history, True, "converged", plain.min_gap)
    if plain.status == NON_FINITE:
        return _Run(x, shape, history, False, "iterate became non-finite")
    if plain.status == DIVERGING:
        return _Run(x, shape, history, False, f"diverging (step {history[-1]:.3g} m)")
    return _Run(x, shape, history, False,
                f"budget exhausted, last step {history[-1]:.3g} m" if history else "no budget")


def _anderson_step(x: Array, f: Array, last: tuple[Array, Array] | None, d_x: list[Array],
                   d_f: list[Array], depth: int) -> Array | None:
    """One Anderson (type II) update of the cell moments ``x`` (N m) from the residual ``f``
    (N m) with memory ``depth``; plain iteration without history. None when the least-squares
    problem cannot be solved: a non-finite residual (LAPACK would reject it) or an SVD that
    does not converge."""
    if last is not None:
        d_x.append(x - last[0])
        d_f.append(f - last[1])
        if len(d_x) > depth:
            d_x.pop(0)
            d_f.pop(0)
    if not d_x:
        return x + f
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(d_f[-1]))):
        return None  # older columns were checked when they were added
    big_x = np.stack(d_x, axis=1)
    big_f = np.stack(d_f, axis=1)
    try:
        gamma, *_ = np.linalg.lstsq(big_f, f, rcond=None)
    except np.linalg.LinAlgError:
        return None
    return x + f - (big_x + big_f) @ gamma


def _result(grid: Grid, settings: SolverSettings, tension: float, run: _Run, strategy: str,
            history: tuple[float, ...], elapsed: float, loading: Loading | None,
            model: MomentModel) -> SolveResult:
    """The result of the strategy run ``run`` (its ``history``: every step of the solve)."""
    shape = run.shape
    contact_scale, tendon_tension = model.extras(run.x, shape, tension)
    positions = shape.positions
    tendons = model.inner if isinstance(model, MaterialLaw) else model
    tensions = tuple(tendons.tensions(tension).tolist()) if isinstance(tendons, TendonSet) else ()
    material = None
    if isinstance(model, MaterialLaw):
        bent = model.inner.bend_moments(run.x)
        material = model.factors(bent).reshape(2, -1).T
    return SolveResult(grid.design, settings, tension, grid.s_nodes, positions, shape.theta,
                       run.x.reshape(2, -1).T, len(history), history, run.converged, strategy,
                       elapsed, grid, loading, contact_scale, tendon_tension, tensions,
                       material)
