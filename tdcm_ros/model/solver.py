"""Algorithm 1: the fixed point between the tendon's moment and the body's shape.

Each iteration computes the moment of the current shape (eq. 11, closed or literal form),
the curvature ``kappa = m / (E I)`` (eq. 14) and the new shape by exact planar integration
(eq. 2), until no midline node moves more than ``tol``. The unknown of the fixed point is
the vector of cell end moments.

Convergence strategy (``acceleration="auto"``): plain iteration while it contracts fast;
Anderson mixing once it slows; if that fails, damped relaxation; if that fails, load
continuation (tension ramped in ``continuation_steps`` warm-started steps). Failure after all
of them raises :class:`ConvergenceError`. Physical limits are checked explicitly: the
tendon-offset singularity before iterating and again on the solution, notch closure on the
solution.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from time import perf_counter

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model import loads
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import ConvergenceError
from tdcm_ros.model.grid import Grid, build_grid
from tdcm_ros.model.kinematics import PlanarShape, integrate
from tdcm_ros.model.limits import (
    check_closure,
    check_singularity,
    check_tendon_singularity,
    check_tension,
)
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.settings import SolverSettings

Array = NDArray[np.float64]
MomentMap = Callable[[PlanarShape, Array], Array]

DEFAULT_SETTINGS = SolverSettings()
SLOW_CONTRACTION = 0.3
DIVERGENCE_GROWTH = 1e3


@dataclass
class _Run:
    """Outcome of one strategy: the last iterate, its residuals and whether it converged."""

    x: Array
    shape: PlanarShape
    history: list[float]
    converged: bool
    reason: str


def solve(design: Design, tension: float, *, settings: SolverSettings = DEFAULT_SETTINGS,
          warm_start: SolveResult | None = None, strict: bool = True) -> SolveResult:
    """Shape of ``design`` under tendon tension ``tension`` (N).

    ``warm_start`` reuses a previous result of the same design and settings as the initial
    iterate (scaled by the tension ratio). With ``strict=False`` a non-converged solve returns
    its last finite iterate with ``converged=False`` instead of raising.
    """
    started = perf_counter()
    t_base = check_tension(tension)
    grid = build_grid(design, settings)
    n = grid.n_cells
    check_tendon_singularity(grid, t_base)
    moment_map = _moment_map(grid, settings)
    x0 = _initial_guess(grid, settings, t_base, warm_start)

    runs: list[tuple[str, _Run]] = []
    budget = settings.max_iter
    for name, run_strategy in _strategies(settings):
        run = run_strategy(grid, moment_map, t_base, x0, settings, budget)
        runs.append((name, run))
        budget -= len(run.history)
        if run.converged or budget <= 0:
            break
    strategy, final = runs[-1]
    iterations = sum(len(r.history) for _, r in runs)
    history = tuple(v for _, r in runs for v in r.history)
    if final.converged:
        if settings.loads == "literal":
            check_singularity(grid, final.x[:n], final.x[n:])
        check_closure(grid, final.shape, t_base)
    result = _result(grid, settings, t_base, final, strategy, iterations, history,
                     perf_counter() - started)
    if not final.converged and strict:
        reasons = "; ".join(f"{name}: {r.reason}" for name, r in runs)
        raise ConvergenceError(
            f"Algorithm 1 did not converge to tol = {settings.tol:g} m at tension {t_base:g} N "
            f"within max_iter = {settings.max_iter} ({reasons})",
            result=result if np.all(np.isfinite(result.positions)) else None)
    return result


def _moment_map(grid: Grid, settings: SolverSettings) -> MomentMap:
    """The map from (shape, current moments) to new moments for the chosen load form."""
    n = grid.n_cells

    def closed(shape: PlanarShape, x: Array, tension: float) -> Array:
        m_a, m_b = loads.closed_form(grid, shape, np.float64(tension))
        return np.concatenate([m_a, m_b])

    def literal(shape: PlanarShape, x: Array, tension: float) -> Array:
        m_a, m_b = loads.literal(grid, shape, tension, x[:n], x[n:])
        return np.concatenate([m_a, m_b])

    return closed if settings.loads == "closed" else literal  # type: ignore[return-value]


def _initial_guess(grid: Grid, settings: SolverSettings, tension: float,
                   warm_start: SolveResult | None) -> Array:
    """The tendon moment ``R_c T`` everywhere, or a compatible previous solution rescaled."""
    if (warm_start is not None and warm_start.grid is grid and warm_start.settings == settings
            and warm_start.tension_n > 0.0 and warm_start.converged):
        scale = tension / warm_start.tension_n
        return np.concatenate([warm_start.cell_moments[:, 0], warm_start.cell_moments[:, 1]]) * scale
    return np.full(2 * grid.n_cells, grid.design.R_c * tension)


Strategy = Callable[[Grid, MomentMap, float, Array, SolverSettings, int], _Run]


def _strategies(settings: SolverSettings) -> list[tuple[str, Strategy]]:
    """Strategies to try in order for ``settings.acceleration``."""
    if settings.acceleration == "auto":
        out: list[tuple[str, Strategy]] = [("picard+anderson", partial(_iterate, mode="auto")),
                                           ("relaxation", partial(_iterate, mode="relaxation"))]
        if settings.continuation_steps > 0:
            out.append(("continuation", _continuation))
        return out
    mode = "picard" if settings.acceleration == "none" else settings.acceleration
    return [(settings.acceleration, partial(_iterate, mode=mode))]


def _continuation(grid: Grid, moment_map: MomentMap, tension: float, x0: Array,
                  settings: SolverSettings, budget: int) -> _Run:
    """Ramp the tension in equal steps, each warm-started from the previous solution."""
    steps = settings.continuation_steps
    x = np.full_like(x0, grid.design.R_c * tension / steps)
    history: list[float] = []
    run = _Run(x, integrate(grid, x[: grid.n_cells], x[grid.n_cells:]), history, False,
               "no steps")
    previous = tension / steps
    for k in range(1, steps + 1):
        level = tension * k / steps
        x = x * (level / previous)
        previous = level
        run = _iterate(grid, moment_map, level, x, settings, budget - len(history),
                       mode="anderson")
        history.extend(run.history)
        if not run.converged:
            return _Run(run.x, run.shape, history, False,
                        f"step {k}/{steps} at {level:g} N: {run.reason}")
        x = run.x
    return _Run(run.x, run.shape, history, True, "converged")


def _iterate(grid: Grid, moment_map: MomentMap, tension: float, x0: Array,
             settings: SolverSettings, budget: int, *, mode: str) -> _Run:
    """Fixed-point iteration on the cell moments; ``mode`` picks the update rule."""
    n = grid.n_cells
    x = x0
    shape = integrate(grid, x[:n], x[n:])
    history: list[float] = []
    using = "picard" if mode == "auto" else mode
    d_x: list[Array] = []
    d_f: list[Array] = []
    last: tuple[Array, Array] | None = None
    length = grid.design.length
    for _ in range(max(budget, 0)):
        g = moment_map(shape, x, tension)
        f = g - x
        if using == "anderson":
            x_new = _anderson_step(x, f, last, d_x, d_f, settings.anderson_depth)
            last = (x, f)
        elif using == "relaxation":
            x_new = x + settings.relaxation * f
        else:
            x_new = g
        new_shape = integrate(grid, x_new[:n], x_new[n:])
        step = float(np.max(np.abs(new_shape.p - shape.p)))
        if not np.isfinite(step):
            return _Run(x, shape, history, False, "iterate became non-finite")
        history.append(step)
        x, shape = x_new, new_shape
        if step <= settings.tol:
            return _Run(x, shape, history, True, "converged")
        if step > 2.0 * length or (len(history) > 5 and step > DIVERGENCE_GROWTH * min(history)):
            return _Run(x, shape, history, False, f"diverging (step {step:.3g} m)")
        if mode == "auto" and using == "picard" and len(history) >= 2 and \
                step > SLOW_CONTRACTION * history[-2]:
            using = "anderson"
    return _Run(x, shape, history, False,
                f"budget exhausted, last step {history[-1]:.3g} m" if history else "no budget")


def _anderson_step(x: Array, f: Array, last: tuple[Array, Array] | None, d_x: list[Array],
                   d_f: list[Array], depth: int) -> Array:
    """One Anderson (type II) update with memory ``depth``; plain iteration without history."""
    if last is not None:
        d_x.append(x - last[0])
        d_f.append(f - last[1])
        if len(d_x) > depth:
            d_x.pop(0)
            d_f.pop(0)
    if not d_x:
        return x + f
    big_x = np.stack(d_x, axis=1)
    big_f = np.stack(d_f, axis=1)
    gamma, *_ = np.linalg.lstsq(big_f, f, rcond=None)
    return x + f - (big_x + big_f) @ gamma


def _result(grid: Grid, settings: SolverSettings, tension: float, run: _Run, strategy: str,
            iterations: int, history: tuple[float, ...], elapsed: float) -> SolveResult:
    n = grid.n_cells
    shape = run.shape
    positions = np.zeros((n + 1, 3))
    positions[:, 0] = shape.p.imag
    positions[:, 2] = shape.p.real
    return SolveResult(
        design=grid.design, settings=settings, tension_n=tension, s=grid.s_nodes,
        positions=positions, theta=shape.theta, cell_moments=run.x.reshape(2, n).T,
        iterations=iterations, residual_history=history, converged=run.converged,
        strategy=strategy, solve_time_s=elapsed, grid=grid)
