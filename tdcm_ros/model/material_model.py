"""The moment model of a material law (:mod:`tdcm_ros.model.material`).

:class:`MaterialLaw` wraps a moment model: the moments that bend the body are the model's
scaled, at each cell end, by the ratio of the law's curvature to the linear one (1 where the
plateau is not reached, so such a solution is the linear model's, bit for bit): the curvature
is exact at every cell end and linear in the moment between them, like the linear model's.

The law is integrated over each cell end's own section: an annulus's chord widths for the
band and cut notches and the tubes, Green's theorem over the polygon for a
:class:`~tdcm_ros.model.profiles.PolygonProfile` notch
(:func:`~tdcm_ros.model.sections.plateau_excess`). The neutral axis stays at the section's
centroid: exact for sections symmetric about it, an approximation for one-sided ones in the
plateau.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.errors import StrainLimitError
from tdcm_ros.model.grid import Grid, gauss_legendre
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.material import Material
from tdcm_ros.model.moment_model import MomentModel, PlainRun, Plan
from tdcm_ros.model.profiles import PolygonProfile
from tdcm_ros.model.sections import material_edges, plateau_excess
from tdcm_ros.model.settings import SolverSettings

Array = NDArray[np.float64]

#: Gauss-Legendre points per piece of a section's width integral.
WIDTH_POINTS = 48
#: Largest number of false-position steps for a curvature (each row stops once converged:
#: about ten; bisection to the same precision took 80).
MAX_STEPS = 100
#: A curvature is found once its moment is within this fraction of the target, or its bracket
#: within ``BRACKET_RTOL`` of it (relative error of the curvature <= about 1e-14 E / E_p).
MOMENT_RTOL = 1e-14
BRACKET_RTOL = 4.0 * np.finfo(float).eps


@dataclass(frozen=True, eq=False)
class _Ends:
    """Every cell end's section (SI units, (2n,): starts then ends): the material's extent
    ``lo``..``hi`` in x (a polygon's own, which its notch holds as ``w_d`` and ``w_o``), the
    centroid ``x_bar``, the linear ``E I``, the tube radii, and
    ``polygon``: the index in ``polygons`` (the edges of each polygon notch's section,
    :func:`~tdcm_ros.model.sections.material_edges`) of an end in a polygon notch, -1 for an
    annulus."""

    lo: Array
    hi: Array
    x_bar: Array
    stiffness: Array
    r_outer: float
    r_inner: float
    polygon: NDArray[np.int64]
    polygons: tuple[tuple[Array, Array], ...]

    @cached_property
    def reach(self) -> Array:
        """Each end's farthest material from its centroid (m)."""
        return np.maximum(self.hi - self.x_bar, self.x_bar - self.lo)

    @classmethod
    def of(cls, grid: Grid) -> _Ends:
        design, members = grid.design, grid.members
        u = np.concatenate([grid.u_a, grid.u_b])
        notch = np.concatenate([grid.is_notch, grid.is_notch])
        shape = np.concatenate([grid.shape, grid.shape])
        half = np.full(u.size, design.R_outer)
        offset = np.zeros(u.size)
        if np.any(notch):
            half[notch] = members.h1(shape[notch], u[notch])
            offset[notch] = members.shape_w_o[shape[notch]]
        lo = np.maximum(offset - half, -design.R_outer)
        hi = np.minimum(offset + half, design.R_outer)
        polygon = np.full(u.size, -1, np.int64)
        polygons: list[tuple[Array, Array]] = []
        kinds = members.profile_of[shape]
        for k, profile in enumerate(members.profiles):
            rows = notch & (kinds == k)
            if isinstance(profile, PolygonProfile) and np.any(rows):
                polygon[rows] = len(polygons)
                polygons.append(material_edges(np.asarray(profile.shell),
                                               [np.asarray(hole) for hole in profile.holes]))
        compliance = np.concatenate([grid.c_start, grid.c_end])
        return cls(lo=lo, hi=hi, x_bar=np.concatenate([grid.xbar_start, grid.xbar_end]),
                   stiffness=1.0 / compliance, r_outer=design.R_outer, r_inner=design.r_inner,
                   polygon=polygon, polygons=tuple(polygons))

    def width(self, x: Array) -> Array:
        """The section's width (m) at abscissa ``x`` (m): the annulus's chord, both sides."""
        outer = np.sqrt(np.maximum(self.r_outer**2 - x * x, 0.0))
        inner = np.sqrt(np.maximum(self.r_inner**2 - x * x, 0.0))
        return 2.0 * (outer - inner)

    def excess(self, rows: NDArray[np.int64], d: Array) -> Array:
        """``J(d)`` (m^4) of the ends ``rows`` at plateau distances ``d`` (m): an annulus's
        (:meth:`annulus_excess`) or a polygon's
        (:func:`~tdcm_ros.model.sections.plateau_excess`)."""
        which = self.polygon[rows]
        total = np.empty(rows.size)
        for k in np.unique(which):
            chosen = np.flatnonzero(which == k)
            ends, at = rows[chosen], d[chosen]
            if k < 0:
                total[chosen] = self.annulus_excess(ends, at)
            else:
                start, end = self.polygons[k]
                total[chosen] = plateau_excess(start, end, self.x_bar[ends], at)
        return total

    def annulus_excess(self, rows: NDArray[np.int64], d: Array) -> Array:
        """``J(d)`` (m^4) of the annulus ends ``rows`` at plateau distances ``d`` (m):
        Gauss-Legendre on each side beyond ``d``, split where the width has its kinks
        (``x = +-r_inner``)."""
        nodes, weights = gauss_legendre(WIDTH_POINTS)
        x_bar = self.x_bar[rows]
        total = np.zeros(rows.size)
        sides = ((x_bar + d, self.hi[rows]), (self.lo[rows], x_bar - d))
        kinks = [k for k in (-self.r_inner, self.r_inner) if self.r_inner > 0.0]
        for low, high in sides:
            cuts = [low, *(np.clip(k, low, np.maximum(low, high)) for k in kinks),
                    np.maximum(low, high)]
            for a, b in itertools.pairwise(cuts):
                span = b - a
                x = a[:, None] + span[:, None] * nodes[None, :]
                y = np.abs(x - x_bar[:, None])
                total += span * (((y - d[:, None]) * y * self.width(x)) @ weights)
        return total


def _false_position(low: Array, high: Array, f_low: Array, f_high: Array) -> Array:
    """The secant's zero between ``low`` and ``high`` (values ``f_low <= 0 <= f_high``); the
    midpoint where it falls outside (rounding)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        guess = high - f_high * (high - low) / (f_high - f_low)
    return np.where((guess > low) & (guess < high), guess, 0.5 * (low + high))


def _illinois(rows: NDArray[np.int64], end: int, moved: NDArray[np.int8], other: Array) -> None:
    """Illinois's rule: where the same end (``end``: +1 high, -1 low) of ``rows``' brackets moves
    twice running, halve the other end's value ``other`` (so it moves too); record the move."""
    again = rows[moved[rows] == end]
    other[again] *= 0.5
    moved[rows] = end


class MaterialLaw:
    """A moment model (``inner``) whose bending moments follow ``material`` (module
    docstring); everything else is the inner model's."""

    def __init__(self, inner: MomentModel, material: Material) -> None:
        self.inner = inner
        self.grid = inner.grid
        self.material = material
        self.modulus = self.grid.design.E
        self.ends = _Ends.of(self.grid) if not material.is_linear else None

    def factors(self, y: Array) -> Array:
        """Per cell end (2n,): the law's curvature over the linear one at the bending moments
        ``y`` (N m); 1 where the plateau is not reached (and for the linear law)."""
        out = np.ones_like(y)
        ends, material = self.ends, self.material
        if ends is None:
            return out
        linear = y / ends.stiffness
        rows = np.flatnonzero(np.abs(linear) * ends.reach > material.plateau_strain)
        if rows.size == 0:
            return out
        target = np.abs(y[rows])
        stiffness = ends.stiffness[rows]
        softening = self.modulus - material.E_plateau

        def excess_moment(curvature: Array, at: NDArray[np.int64]) -> Array:
            """``M(kappa) - |m|`` (N m) of rows ``at`` of ``rows``."""
            return curvature * (stiffness[at] - softening * ends.excess(
                rows[at], material.plateau_strain / curvature)) - target[at]

        every = np.arange(rows.size)
        # M(kappa) <= E I kappa and >= E_p I kappa: the root lies in [linear, linear E / E_p]
        low = np.abs(linear[rows])
        high = low * (self.modulus / material.E_plateau)
        root = 0.5 * (low + high)
        f_low, f_high = excess_moment(low, every), excess_moment(high, every)
        moved = np.zeros(rows.size, np.int8)  # the end moved last: +1 high, -1 low
        active = every
        for _ in range(MAX_STEPS):
            if active.size == 0:
                break
            root[active] = _false_position(low[active], high[active], f_low[active],
                                           f_high[active])
            value = excess_moment(root[active], active)
            above = value > 0.0
            _illinois(active[above], 1, moved, f_low)
            high[active[above]], f_high[active[above]] = root[active[above]], value[above]
            _illinois(active[~above], -1, moved, f_high)
            low[active[~above]], f_low[active[~above]] = root[active[~above]], value[~above]
            done = (np.abs(value) <= MOMENT_RTOL * target[active]) | (
                high[active] - low[active] <= BRACKET_RTOL * high[active])
            active = active[~done]
        out[rows] = root / np.abs(linear[rows])
        return out

    def moments(self, shape: PlanarShape, x: Array, level: float, factor: float) -> Array:
        return self.inner.moments(shape, x, level, factor)

    def bend_moments(self, x: Array) -> Array:
        y = self.inner.bend_moments(x)
        return y if self.ends is None else y * self.factors(y)

    def chord_tension(self, level: float) -> float | Array:
        return self.inner.chord_tension(level)

    def axis_tension(self, level: float) -> float | Array:
        return self.inner.axis_tension(level)

    def start(self, level: float) -> Array:
        return self.inner.start(level)

    def check_before(self, tension: float) -> None:
        self.inner.check_before(tension)

    def check_after(self, x: Array, shape: PlanarShape, tension: float,
                    min_gap: float | None = None) -> None:
        self.inner.check_after(x, shape, tension, min_gap)
        limit = self.material.recoverable_strain
        if not math.isfinite(limit):
            return
        grid = self.grid
        n = grid.n_cells
        y = self.bend_moments(x)
        strain = np.abs(y[:n, None] * grid.strain0 + y[n:, None] * grid.strain1)
        peak = np.max(strain, axis=1)
        cells = np.flatnonzero(grid.is_notch)
        if cells.size == 0:
            return
        worst = cells[int(np.argmax(peak[cells]))]
        if peak[worst] > limit:
            notch = int(grid.notch_index[worst]) + 1
            raise StrainLimitError(
                f"notch {notch} strains {peak[worst] * 100:.3g} % at tension {tension:g} N, past "
                f"the material's recoverable strain {limit * 100:.3g} %",
                notch=notch, strain=float(peak[worst]))

    def plans(self, settings: SolverSettings) -> Sequence[Plan]:
        return self.inner.plans(settings)

    def warm_scale(self, previous: float, tension: float) -> float | None:
        return self.inner.warm_scale(previous, tension)

    def extras(self, x: Array, shape: PlanarShape, tension: float
               ) -> tuple[Array | None, Array | None]:
        return self.inner.extras(x, shape, tension)

    def plain(self, x: Array, level: float, budget: int, tol: float, relaxation: float,
              slow: float) -> PlainRun | None:
        """The inner model's compiled iteration where its iterate stays below the plateau
        (the linear model's result, bit for bit); else None (the solver iterates in NumPy)."""
        run = self.inner.plain(x, level, budget, tol, relaxation, slow)
        if run is None or self.ends is None:
            return run
        return run if np.all(self.factors(self.inner.bend_moments(run.x)) == 1.0) else None
