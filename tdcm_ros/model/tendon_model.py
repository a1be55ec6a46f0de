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

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.compiled import kernels
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.limits import check_closure, check_tendons_singularity
from tdcm_ros.model.moment_model import PlainRun, Plan, paper_plans
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.tendons import TendonLayout

Array = NDArray[np.float64]


class TendonSet:
    """Several tendons' closed-form moments on one grid, at tensions ``fractions`` (J,) times
    the solver's level (N)."""

    def __init__(self, grid: Grid, layout: TendonLayout, fractions: Array) -> None:
        self.grid = grid
        self.layout = layout
        self.fractions = fractions
        cells = grid.cells
        self._scal = []
        self._ic = []
        for j in range(layout.count):  # each tendon's offset and cells it follows
            scal = cells.scal.copy()
            scal[:, 0] = layout.offsets[j]
            ic = cells.ic.copy()
            ic[:, 2] = layout.follows[j]
            self._scal.append(scal)
            self._ic.append(ic)

    def tensions(self, level: float) -> Array:
        """Each tendon's base tension (N) at ``level``."""
        return level * self.fractions

    def moments(self, shape: PlanarShape, x: Array, level: float, factor: float) -> Array:
        per, _, _ = self.layout.cell_tensions(self.tensions(level))
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
        return self.layout.cell_tensions(self.tensions(level))[1]

    def axis_tension(self, level: float) -> Array:
        return self.layout.cell_tensions(self.tensions(level))[2]

    def start(self, level: float) -> Array:
        per, _, _ = self.layout.cell_tensions(self.tensions(level))
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
