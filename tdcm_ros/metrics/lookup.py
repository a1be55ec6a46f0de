"""Model marker positions at many tensions: solves on a tension grid, linear in between.

Used where a solve per sample would be too slow (the live node's per-sample errors, simulated
recordings). The grid spacing ``step_n`` bounds the interpolation error; the test measures it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model import (
    Design,
    MarkerLayout,
    SolveResult,
    SolverSettings,
    solve,
    surface_points,
)

Array = NDArray[np.float64]


class MarkerTable:
    """Predicted marker points (k, 3) m in ``tdcm_base`` for tensions in ``[0, max_n]`` N.

    The grid grows on demand (doubling ``max_n``) when a larger tension is asked for.
    """

    def __init__(self, design: Design, layout: MarkerLayout, *,
                 settings: SolverSettings | None = None, max_n: float = 20.0,
                 step_n: float = 0.1) -> None:
        if not (np.isfinite(step_n) and step_n > 0.0):
            raise out_of_range("step_n", step_n, "(0, inf) N")
        if not (np.isfinite(max_n) and max_n > 0.0):
            raise out_of_range("max_n", max_n, "(0, inf) N")
        self.design = design
        self.layout = layout
        self.settings = settings or SolverSettings()
        self.step_n = float(step_n)
        self._tensions = np.zeros(0)
        self._markers = np.zeros((0, len(layout.labels), 3))
        self._last: SolveResult | None = None
        self._extend(max_n)

    @property
    def max_n(self) -> float:
        """Largest tension on the grid (N)."""
        return float(self._tensions[-1])

    def _extend(self, max_n: float) -> None:
        count = int(np.ceil(max_n / self.step_n))
        grid = np.arange(self._tensions.size, count + 1) * self.step_n
        radius = self.layout.radius(self.design.R_outer)
        rows = []
        for tension in grid:
            self._last = solve(self.design, float(tension), settings=self.settings,
                               warm_start=self._last)
            rows.append(surface_points(self._last, self.layout.s, radius, self.layout.side_rad)[0])
        self._tensions = np.concatenate([self._tensions, grid])
        self._markers = np.concatenate([self._markers, np.asarray(rows)])

    def markers(self, tensions_n: ArrayLike) -> Array:
        """Marker points (..., k, 3) m for tensions (...) N (finite, >= 0)."""
        t = np.asarray(tensions_n, dtype=float)
        if not np.all(np.isfinite(t)) or np.any(t < 0.0):
            raise out_of_range("tension", t.tolist() if t.size < 8 else "array", "[0, inf) N")
        if t.size and float(t.max()) > self.max_n:
            self._extend(max(float(t.max()), 2.0 * self.max_n))
        pos = t / self.step_n
        lo = np.clip(np.floor(pos).astype(np.int64), 0, self._tensions.size - 2)
        frac = (pos - lo)[..., None, None]
        return (1.0 - frac) * self._markers[lo] + frac * self._markers[lo + 1]
