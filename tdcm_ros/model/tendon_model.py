"""The paper's model with several tendons (:mod:`tdcm_ros.model.tendons`): one moment model.

Each tendon's moment is the paper's closed form for that tendon alone
(:func:`tdcm_ros.model.kernel.moments_row` with its offset, its routing's chords and its
tension, zero past its anchor), and the body bends under their sum. Inside a cell the sum
bows like one tendon's where some tendons cross it as a chord (``m'' = -T c m`` with ``T``
their tensions' sum) and the centroid's motion off the axis adds ``- T dx`` with ``T`` the
tension of every tendon pulling on it (:func:`tdcm_ros.model.kernel.integrate_row`'s two
tensions). The solver iterates it in NumPy (no compiled plain iteration): Picard, Anderson,
relaxation, continuation, as the paper's model.

The solver's scalar tension is the largest of the tendons' (``level``); the model holds the
tensions as fractions of it, so continuation scales them together.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.compiled import kernels
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.limits import check_closure, check_tendons_singularity
from tdcm_ros.model.moment_model import PlainRun, Plan, paper_plans
from tdcm_ros.model.settings import SolverSettings

Array = NDArray[np.float64]


class TendonSet:
    """Several tendons' closed-form moments on one grid, at tensions ``fractions`` (J,) times
    the solver's level (N)."""

    def __init__(self, grid: Grid, routing: str, fractions: Array) -> None:
        self.grid = grid
        self.layout = grid.tendons(routing)
        self.fractions = fractions
        self._scal, self._ic = _tendon_cells(grid, routing)
        self._level: tuple[float, tuple[Array, Array, Array]] | None = None

    def tensions(self, level: float) -> Array:
        """Each tendon's base tension (N) at ``level``."""
        return level * self.fractions

    def _cell_tensions(self, level: float) -> tuple[Array, Array, Array]:
        """:meth:`~tdcm_ros.model.tendons.TendonLayout.cell_tensions` at ``level``, kept for
        the last level (an iteration asks for it three times)."""
        if self._level is None or self._level[0] != level:
            self._level = (level, self.layout.cell_tensions(self.tensions(level)))
        return self._level[1]

    def moments(self, shape: PlanarShape, x: Array, level: float, factor: float) -> Array:
        per, _, _ = self._cell_tensions(level)
        n = self.grid.n_cells
        p = np.ascontiguousarray(shape.p).reshape(1, -1)
        tangent = np.ascontiguousarray(shape.tangent).reshape(1, -1)
        total = np.zeros(2 * n)
        part_a, part_b = np.empty((1, n)), np.empty((1, n))
        fc = self.grid.cells.fc
        for j in range(self.layout.count):
            t = np.ascontiguousarray(per[j]).reshape(1, n)
            kernels().moments(self._scal[j], p, tangent, t, t, self._ic[j], fc, part_a, part_b)
            total[:n] += part_a[0]
            total[n:] += part_b[0]
        return total

    def bend_moments(self, x: Array) -> Array:
        return x

    def chord_tension(self, level: float) -> Array:
        return self._cell_tensions(level)[1]

    def axis_tension(self, level: float) -> Array:
        return self._cell_tensions(level)[2]

    def start(self, level: float) -> Array:
        per, _, _ = self._cell_tensions(level)
        moment = self.layout.offsets @ per
        return np.concatenate([moment, moment])

    def check_before(self, tension: float) -> None:
        """Nothing: tendons may pull against each other, so no one tendon's own moment bounds
        the solution's."""

    def check_after(self, x: Array, shape: PlanarShape, tension: float,
                    min_gap: float | None = None) -> None:
        n = self.grid.n_cells
        check_tendons_singularity(self.grid, self.layout, x[:n], x[n:])
        check_closure(self.grid, shape, tension)

    def plans(self, settings: SolverSettings) -> Sequence[Plan]:
        return paper_plans(settings)

    def warm_scale(self, previous: float, tension: float) -> float | None:
        """None: a previous result's tensions need not be in the same proportions."""
        return None

    def extras(self, x: Array, shape: PlanarShape, tension: float
               ) -> tuple[Array | None, Array | None]:
        return None, None

    def plain(self, x: Array, level: float, budget: int, tol: float, relaxation: float,
              slow: float) -> PlainRun | None:
        return None


@lru_cache(maxsize=64)
def _tendon_cells(grid: Grid, routing: str) -> tuple[tuple[Array, ...], tuple[NDArray[np.int64], ...]]:
    """Per tendon of ``grid``'s design under ``routing``: the kernel's ``scal`` with its offset
    and ``ic`` with the cells it follows (:func:`tdcm_ros.model.kernel.moments_row`), built
    once per grid (cached: they hold only the grid's numbers)."""
    layout, cells = grid.tendons(routing), grid.cells
    scals, ics = [], []
    for j in range(layout.count):
        scal = cells.scal.copy()
        scal[:, 0] = layout.offsets[j]
        ic = cells.ic.copy()
        ic[:, 2] = layout.follows[j]
        scals.append(scal)
        ics.append(ic)
    return tuple(scals), tuple(ics)
