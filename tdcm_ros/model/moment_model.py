"""The moment models Algorithm 1 iterates: one interface, three implementations.

A :class:`MomentModel` maps a shape to the cell end moments ``x = [m_a, m_b]`` (N m), says
which moments bend the body, checks its own physical limits before and after iterating, and
lists the convergence strategies that suit it. :func:`tdcm_ros.model.solver.solve` picks one:

- :class:`ClosedForm`: the paper's model with the tendon's equilibrium form (eq. 11 closed);
  its plain iteration runs in the compiled kernel (:func:`tdcm_ros.model.kernel.iterate`);
- :class:`LiteralSum`: the paper's model as the literal sum of eqs. 8-10;
- :class:`~tdcm_ros.model.loading.LoadedModel`: a :class:`~tdcm_ros.model.loading.Loading`.

"No loading" is the closed form itself (the neutral case), not a branch of the solver.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model import loads
from tdcm_ros.model.compiled import kernels
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kernel import one_offsets, one_size
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.limits import (
    check_closure,
    check_singularity,
    check_tendon_singularity,
)
from tdcm_ros.model.settings import SolverSettings

Array = NDArray[np.float64]

DIVERGENCE_GROWTH = 1e3
"""A step this many times the smallest one so far (after 5 steps) is divergence."""
AUTO_PLAN = "picard+anderson"
"""The name of ``acceleration="auto"``'s first strategy (a result's ``strategy``)."""

class Plan(NamedTuple):
    """One convergence strategy: ``mode`` (``auto``, ``picard``, ``anderson``,
    ``relaxation`` or ``continuation``), its iteration cap, whether ``auto`` restarts Anderson
    from the initial iterate and whether continuation adapts its steps."""

    name: str
    mode: str
    budget: int
    restart: bool = False
    adaptive: bool = False


class PlainRun(NamedTuple):
    """Outcome of a compiled plain iteration: last iterate, its shape, steps (m), status
    (:mod:`tdcm_ros.model.kernel`) and the shape's smallest notch gap (m)."""

    x: Array
    shape: PlanarShape
    history: list[float]
    status: int
    min_gap: float


class CompiledRun:
    """The iterate, shape and steps that :func:`tdcm_ros.model.kernel.iterate_one` left in
    its buffer ``out`` after ``steps`` steps on ``n`` cells, as views made on use."""

    __slots__ = ("n", "out", "steps")

    def __init__(self, out: Array, n: int, steps: int) -> None:
        self.out = out
        self.n = n
        self.steps = steps

    @property
    def x(self) -> Array:
        """The last iterate ``[m_a, m_b]`` (2n,) N m."""
        return self.out[:one_offsets(self.n)[0]]

    @property
    def p(self) -> NDArray[np.complex128]:
        """The last shape's nodes ``z + i x`` (m)."""
        p_at, tangent_at, *_ = one_offsets(self.n)
        return self.out[p_at:tangent_at].view(np.complex128)

    @property
    def theta(self) -> Array:
        """The last shape's tangent angles (rad)."""
        _, _, theta_at, info_at, _ = one_offsets(self.n)
        return self.out[theta_at:info_at]

    @property
    def shape(self) -> PlanarShape:
        """The last iterate's shape: nodes (m), tangent angles (rad) and unit tangents."""
        _, tangent_at, theta_at, _, _ = one_offsets(self.n)
        return PlanarShape(self.p, self.theta, self.out[tangent_at:theta_at].view(np.complex128))

    @property
    def history(self) -> tuple[float, ...]:
        """The steps (m), one per iteration."""
        start = one_offsets(self.n)[4]
        return tuple(self.out[start:start + self.steps].tolist())


class MomentModel(Protocol):
    """What the solver needs from a model of the moments on one grid."""

    grid: Grid

    def moments(self, shape: PlanarShape, x: Array, level: float, factor: float) -> Array:
        """New ``[m_a, m_b]`` (N m) for ``shape``, produced by ``x``, at tension ``level`` (N)
        with the external loads scaled by ``factor``."""
        ...

    def bend_moments(self, x: Array) -> Array:
        """The moments (N m) that set the curvature."""
        ...

    def chord_tension(self, level: float) -> float | Array:
        """Tension (N) on the chords at base tension ``level`` (N), for the chord terms of
        the shape integration: one value or one per cell."""
        ...

    def axis_tension(self, level: float) -> float | Array:
        """Tension (N) of every tendon pulling on each cell at base tension ``level`` (N),
        for the centroid's motion off the axis: one value or one per cell."""
        ...

    def start(self, level: float) -> Array:
        """The initial iterate ``[m_a, m_b]`` (N m) at base tension ``level`` (N): the
        tendons' own moments on the straight body."""
        ...

    def check_before(self, tension: float) -> None:
        """Raise a limit error known before iterating."""
        ...

    def check_after(self, x: Array, shape: PlanarShape, tension: float,
                    min_gap: float | None = None) -> None:
        """Raise a limit error of the converged solution; ``min_gap`` is its smallest notch
        gap (m) if already known."""
        ...

    def plans(self, settings: SolverSettings) -> Sequence[Plan]:
        """Strategies in order."""
        ...

    def warm_scale(self, previous: float, tension: float) -> float | None:
        """Factor on a converged solution at ``previous`` N to start at ``tension`` N (None:
        unusable)."""
        ...

    def extras(self, x: Array, shape: PlanarShape, tension: float
               ) -> tuple[Array | None, Array | None]:
        """``(contact_scale, tendon_tension)`` of a result, None where not applicable."""
        ...

    def plain(self, x: Array, level: float, budget: int, tol: float, relaxation: float,
              slow: float) -> PlainRun | None:
        """Plain (``relaxation`` 1) or damped iteration in the compiled kernel, handing over
        when a step exceeds ``slow`` times the previous (0: never); None if unavailable."""
        ...


@lru_cache(maxsize=64)
def paper_plans(settings: SolverSettings) -> tuple[Plan, ...]:
    """The paper model's strategies: Picard then Anderson, relaxation, continuation."""
    budget = settings.max_iter
    if settings.acceleration != "auto":
        mode = "picard" if settings.acceleration == "none" else settings.acceleration
        return (Plan(settings.acceleration, mode, budget),)
    plans = [Plan(AUTO_PLAN, "auto", budget), Plan("relaxation", "relaxation", budget)]
    if settings.continuation_steps > 0:
        plans.append(Plan("continuation", "continuation", budget))
    return tuple(plans)


def own_moment(grid: Grid, level: float) -> Array:
    """``[m_a, m_b]`` (N m) of the paper's tendon on the straight body, ``R_c T`` everywhere
    at tension ``level`` (N)."""
    x0 = np.empty(2 * grid.n_cells)
    x0.fill(grid.r_c * level)
    return x0


class ClosedForm:
    """The paper's model, tendon moment in closed form; the neutral loading."""

    def __init__(self, grid: Grid) -> None:
        self.grid = grid
        self.cells = grid.cells
        self._r_c_squared = float(grid.r_c) ** 2
        self._peak_c = float(self.cells.constrained_peak_c[0])  # Python floats: no warnings
        self.n_cells = grid.n_cells
        self._buffer = one_size(self.n_cells, 0)  # iterate_one's buffer less the steps

    def moments(self, shape: PlanarShape, x: Array, level: float, factor: float) -> Array:
        m_a, m_b = loads.closed_form(self.grid, shape, np.float64(level))
        return np.concatenate([m_a, m_b])

    def bend_moments(self, x: Array) -> Array:
        return x

    def chord_tension(self, level: float) -> float:
        return level

    def axis_tension(self, level: float) -> float:
        return level

    def start(self, level: float) -> Array:
        return own_moment(self.grid, level)

    def check_before(self, tension: float) -> None:
        if self._r_c_squared * tension * self._peak_c >= 1.0:
            check_tendon_singularity(self.grid, tension)

    def check_after(self, x: Array, shape: PlanarShape, tension: float,
                    min_gap: float | None = None) -> None:
        if min_gap is None or min_gap <= 0.0:
            check_closure(self.grid, shape, tension)

    def plans(self, settings: SolverSettings) -> Sequence[Plan]:
        return paper_plans(settings)

    def warm_scale(self, previous: float, tension: float) -> float | None:
        return tension / previous if previous > 0.0 else None

    def extras(self, x: Array, shape: PlanarShape, tension: float
               ) -> tuple[Array | None, Array | None]:
        return None, None

    def plain(self, x: Array, level: float, budget: int, tol: float, relaxation: float,
              slow: float) -> PlainRun | None:
        out, steps, status, gap = self.run(x, level, max(budget, 0), tol, relaxation, slow)
        run = CompiledRun(out, self.n_cells, steps)
        return PlainRun(run.x, run.shape, list(run.history), status, gap)

    def run(self, x: Array | None, level: float, budget: int, tol: float, relaxation: float,
            slow: float) -> tuple[Array, int, int, float]:
        """:meth:`plain` as the kernel leaves it: one compiled call, from ``x`` (N m) or,
        where None, :meth:`start`, for at most ``budget`` (>= 0) steps. Returns its buffer
        (read by :class:`CompiledRun`), the steps taken, the status
        (:mod:`tdcm_ros.model.kernel`) and the last shape's smallest notch gap (m)."""
        cells = self.cells
        out = np.empty(self._buffer + budget)
        return (out, *kernels().iterate_one(
            cells.fc, cells.fq, cells.ic, cells.notch, cells.scal, level, x, out, tol,
            relaxation, slow, DIVERGENCE_GROWTH))


class LiteralSum(ClosedForm):
    """The paper's model, tendon moment as the literal sum of eqs. 8-10; its moments are
    known only after iterating, so the singularity is also checked on the solution."""

    def moments(self, shape: PlanarShape, x: Array, level: float, factor: float) -> Array:
        n = self.grid.n_cells
        m_a, m_b = loads.literal(self.grid, shape, level, x[:n], x[n:])
        return np.concatenate([m_a, m_b])

    def check_after(self, x: Array, shape: PlanarShape, tension: float,
                    min_gap: float | None = None) -> None:
        n = self.grid.n_cells
        check_singularity(self.grid, x[:n], x[n:])
        check_closure(self.grid, shape, tension)

    def plain(self, x: Array, level: float, budget: int, tol: float, relaxation: float,
              slow: float) -> PlainRun | None:
        return None
