"""Model marker positions at many tensions: solves on a grid of tensions, linear in between.

Used where a solve per sample would be too slow (the live node's per-sample errors, simulated
recordings). :class:`MarkerTable` covers one tendon: a 1-D grid solved up front.
:class:`MarkerLattice` covers J > 1 tendons: the lattice of multiples of ``step_n`` per tendon
is too large to solve up front (``(max / step_n)**J`` points), so it solves the lattice points
around the tension vectors asked for, caches them and interpolates multilinearly. The spacing
``step_n`` bounds the interpolation error; the tests measure it against a direct solve.
"""

from __future__ import annotations

from collections import OrderedDict
from itertools import product

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
#: A tension within this fraction of ``step_n`` of a grid point is on it (float rounding:
#: ``12 / 0.1`` is 119.99999999999999), so a hold at a grid level takes that point's solve alone.
ON_GRID = 1e-9


def _solve_markers(design: Design, layout: MarkerLayout, tension: float | list[float],
                   settings: SolverSettings, warm: SolveResult | None
                   ) -> tuple[SolveResult, Array]:
    """The model at ``tension`` (N, one per tendon) and its marker points (k, 3) m."""
    result = solve(design, tension, settings=settings, warm_start=warm)
    return result, surface_points(result, layout.s, layout.radius(design.R_outer),
                                  layout.side_rad)[0]


def _check_step(step_n: float) -> float:
    if not (np.isfinite(step_n) and step_n > 0.0):
        raise out_of_range("step_n", step_n, "(0, inf) N")
    return float(step_n)


def _check_tensions(t: Array) -> None:
    if not np.all(np.isfinite(t)) or np.any(t < 0.0):
        raise out_of_range("tension", t.tolist() if t.size < 8 else "array", "[0, inf) N")


class MarkerTable:
    """Predicted marker points (k, 3) m in ``tdcm_base`` for tensions in ``[0, max_n]`` N of a
    design with one tendon.

    The grid grows on demand (doubling ``max_n``) when a larger tension is asked for.
    """

    def __init__(self, design: Design, layout: MarkerLayout, *,
                 settings: SolverSettings | None = None, max_n: float = 20.0,
                 step_n: float = 0.1) -> None:
        self.step_n = _check_step(step_n)
        if not (np.isfinite(max_n) and max_n > 0.0):
            raise out_of_range("max_n", max_n, "(0, inf) N")
        self.design = design
        self.layout = layout
        self.settings = settings or SolverSettings()
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
        rows = []
        for tension in grid:
            self._last, points = _solve_markers(self.design, self.layout, float(tension),
                                                self.settings, self._last)
            rows.append(points)
        self._tensions = np.concatenate([self._tensions, grid])
        self._markers = np.concatenate([self._markers, np.asarray(rows)])

    def markers(self, tensions_n: ArrayLike) -> Array:
        """Marker points (..., k, 3) m for tensions (...) N (finite, >= 0)."""
        t = np.asarray(tensions_n, dtype=float)
        _check_tensions(t)
        if t.size and float(t.max()) > self.max_n:
            self._extend(max(float(t.max()), 2.0 * self.max_n))
        pos = t / self.step_n
        lo = np.clip(np.floor(pos).astype(np.int64), 0, self._tensions.size - 2)
        frac = (pos - lo)[..., None, None]
        return (1.0 - frac) * self._markers[lo] + frac * self._markers[lo + 1]


class MarkerLattice:
    """Predicted marker points (k, 3) m in ``tdcm_base`` for tension vectors (J,) N of a design
    with J tendons: multilinear between the model's points at the ``2**J`` corners of the
    vector's cell of the lattice of multiples of ``step_n`` (N) per tendon (a corner of zero
    weight is not solved: a vector on the lattice takes its own solve alone).

    Corners are solved when first needed, each warm-started from the previous solve, and cached;
    at most ``max_points`` are kept (the least recently used is dropped).
    """

    def __init__(self, design: Design, layout: MarkerLayout, *,
                 settings: SolverSettings | None = None, step_n: float = 0.1,
                 max_points: int = 4096) -> None:
        self.step_n = _check_step(step_n)
        self.tendons = len(design.tendon_list())
        if max_points < 2 ** self.tendons:
            raise out_of_range("max_points", max_points, f">= {2 ** self.tendons} (2**tendons)")
        self.design = design
        self.layout = layout
        self.settings = settings or SolverSettings()
        self.max_points = int(max_points)
        self._corners = np.array(list(product((0, 1), repeat=self.tendons)), dtype=np.int64)
        self._points: OrderedDict[tuple[int, ...], Array] = OrderedDict()
        self._last: SolveResult | None = None
        self.solves = 0  #: lattice points solved so far

    def _point(self, index: tuple[int, ...]) -> Array:
        """Marker points (k, 3) m at the lattice point ``index`` (multiples of ``step_n``)."""
        points = self._points.get(index)
        if points is not None:
            self._points.move_to_end(index)
            return points
        self._last, points = _solve_markers(self.design, self.layout,
                                            [i * self.step_n for i in index], self.settings,
                                            self._last)
        self.solves += 1
        self._points[index] = points
        if len(self._points) > self.max_points:
            self._points.popitem(last=False)
        return points

    def markers(self, tensions_n: ArrayLike) -> Array:
        """Marker points (..., k, 3) m for tension vectors (..., J) N (finite, >= 0)."""
        t = np.asarray(tensions_n, dtype=float)
        if t.ndim < 1 or t.shape[-1] != self.tendons:
            raise out_of_range("tension", t.shape, f"(..., {self.tendons}): one per tendon (N)")
        _check_tensions(t)
        pos = t.reshape(-1, self.tendons) / self.step_n
        pos = np.where(np.abs(pos - np.rint(pos)) <= ON_GRID, np.rint(pos), pos)
        lo = np.floor(pos).astype(np.int64)
        frac = pos - lo
        out = np.zeros((len(pos), len(self.layout.labels), 3))
        for row, (corner_lo, corner_frac) in enumerate(zip(lo, frac, strict=True)):
            weights = np.prod(np.where(self._corners == 1, corner_frac, 1.0 - corner_frac),
                              axis=1)
            for weight, corner in zip(weights.tolist(), self._corners, strict=True):
                if weight > 0.0:
                    out[row] += weight * self._point(tuple((corner_lo + corner).tolist()))
        return out.reshape(*t.shape[:-1], len(self.layout.labels), 3)
