"""Notch profiles: the backbone half-width ``h1`` across one notch (eq. 13 and alternatives).

A profile maps a reference coordinate ``u`` in [0, 1] across the notch to the local arc
length ``sigma = s - l_i`` in [0, w_n] (m) and gives ``h1`` there (m). The map is chosen so
that ``h1`` is smooth in ``u``: the circular notch uses the paper's own angle ``t``, in which
the profile is a sine, instead of ``s``, in which it has an infinite slope at the edges.
Quadrature and cell boundaries are placed uniformly in ``u``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from tdcm_ros.model.sections import SectionProperties

Array = NDArray[np.float64]
#: A width (m): one number, or one per row of ``u`` (broadcasting against it).
Width = float | Array


@dataclass(frozen=True)
class CircularProfile:
    """Eq. 13: a slot of width ``w_n`` with a semicircular bottom reaching ``w_d/2`` at its centre.

    With ``t = pi (1 + u)``, ``sigma = (w_n/2)(1 + cos t)`` and
    ``h1 = (w_n + w_d)/2 + (w_n/2) sin t``.
    """

    name: str = "circular"

    def sigma(self, u: Array, w_n: Width) -> Array:
        """Local arc length (m) at reference coordinate ``u``."""
        return _circular(u, w_n, 0.0)[0]

    def h1(self, u: Array, w_n: Width, w_d: Width) -> Array:
        """Backbone half-width (m) at ``u``."""
        return _circular(u, w_n, w_d)[1]


def _circular(u: Array, w_n: Width, w_d: Width) -> tuple[Array, Array]:
    """``sigma`` and ``h1`` (m) of eq. 13 at ``u`` (widths broadcast against it): the formula
    the cells are integrated with (:func:`tdcm_ros.model.grid_kernel.geometry`), in its
    build."""
    # lazily: the compiled module imports tdcm_ros.model, which imports this one
    from tdcm_ros.model.compiled import grid_kernels
    from tdcm_ros.model.grid_kernel import CIRCULAR

    at, width, depth = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (u, w_n, w_d)))
    sigma, h1 = np.empty(at.size), np.empty(at.size)
    grid_kernels().profile_points(float(CIRCULAR), np.ascontiguousarray(width).ravel(),
                                  np.ascontiguousarray(depth).ravel(),
                                  np.ascontiguousarray(at).ravel(), sigma, h1)
    return sigma.reshape(at.shape), h1.reshape(at.shape)


class _StraightSlot:
    """A notch the same all along it: ``sigma = w_n u`` and ``h1 = w_d/2`` at every ``u``."""

    def sigma(self, u: Array, w_n: Width) -> Array:
        """Local arc length (m) at reference coordinate ``u``."""
        return w_n * u

    def h1(self, u: Array, w_n: Width, w_d: Width) -> Array:
        """Backbone half-width (m) at ``u``: ``w_d / 2``."""
        return np.full_like(u, 0.5 * w_d)


@dataclass(frozen=True)
class RectangularProfile(_StraightSlot):
    """A straight-bottomed slot: ``h1 = w_d/2`` across the whole notch."""

    name: str = "rectangular"


@dataclass(frozen=True)
class CustomProfile:
    """A user-supplied profile ``h1(sigma)``: half-width (m) at local arc length ``sigma`` (m).

    ``h1`` must accept a NumPy array of ``sigma`` in [0, w_n] and return positive, finite
    half-widths of the same shape. Quadrature is uniform in ``sigma``; a profile with infinite
    slopes converges more slowly than the built-in circular one.
    """

    half_width: Callable[[Array], Array] = field(compare=True)
    name: str = "custom"

    def sigma(self, u: Array, w_n: Width) -> Array:
        """Local arc length (m) at reference coordinate ``u``."""
        return w_n * u

    def h1(self, u: Array, w_n: Width, w_d: Width) -> Array:
        """Backbone half-width (m) at ``u`` from the user's function."""
        return np.asarray(self.half_width(w_n * u), dtype=float) * np.ones_like(u)


@dataclass(frozen=True)
class PolygonProfile(_StraightSlot):
    """A prismatic notch whose section is a polygon of material. Along the body it is the
    rectangular slot; ``h1`` is half the polygon's extent in ``x``, which a
    :class:`~tdcm_ros.model.design.Design` holds as the notch's ``w_d`` (and the extent's middle
    as ``w_o``). The mechanics read the section whole (:meth:`section`), not ``h1``.

    ``shell`` and ``holes`` are :class:`~tdcm_ros.model.sections.PolygonSection`'s (vertices
    ``(x, y)`` in m in the section plane, ``x`` toward the tendon).
    """

    shell: tuple[tuple[float, float], ...]
    holes: tuple[tuple[tuple[float, float], ...], ...] = ()
    name: str = "polygon"

    def __post_init__(self) -> None:
        def ring(points: Any) -> tuple[tuple[float, float], ...]:
            try:
                return tuple((float(x), float(y)) for x, y in points)
            except (TypeError, ValueError):
                return tuple(points)  # the section's check names what is wrong with it

        object.__setattr__(self, "shell", ring(self.shell))
        object.__setattr__(self, "holes", tuple(ring(hole) for hole in self.holes))

    def section(self, r_outer: float) -> SectionProperties:
        """The polygon's section properties in a tube of outer radius ``r_outer`` (m); checked
        (a simple polygon of positive area) and computed once per polygon and radius."""
        return _polygon_properties(self.shell, self.holes, float(r_outer))

    def x_extent(self) -> tuple[float, float]:
        """The smallest and largest ``x`` of the polygon's material (m)."""
        xs = [x for x, _ in self.shell]
        return min(xs), max(xs)

    def check_inside(self, r_outer: float, where: str) -> None:
        """Raise :class:`~tdcm_ros.model.errors.InvalidDesignError` naming ``where`` unless
        every vertex is within ``r_outer`` (m, to rounding) of the tube axis."""
        from tdcm_ros.errors import out_of_range
        from tdcm_ros.model.errors import InvalidDesignError
        from tdcm_ros.model.sections import OFFSET_SLACK

        reach = max(math.hypot(x, y) for x, y in self.shell)
        if reach > r_outer * (1.0 + OFFSET_SLACK):
            raise out_of_range(where, reach, f"vertices within R_outer = {r_outer:g} m of the "
                               "tube axis", error=InvalidDesignError)


@dataclass(frozen=True)
class SectionProfile(_StraightSlot):
    """A prismatic notch whose section is given by its numbers (a slice of a mesh,
    :mod:`tdcm_ros.model.mesh_body`): ``area`` (m^2), ``centroid_x`` (m), ``second_moment``
    about the centroid (m^4), ``x_low``/``x_high``, the material's extent in ``x`` (m)."""

    area: float
    centroid_x: float
    second_moment: float
    x_low: float
    x_high: float
    name: str = "section"

    def section(self, r_outer: float) -> SectionProperties:
        """The section's properties in a tube of outer radius ``r_outer`` (m)."""
        from tdcm_ros.model.sections import SectionProperties, keeps_wall

        x_bar = self.centroid_x
        return SectionProperties(
            area=np.array(self.area), centroid_x=np.array(x_bar),
            second_moment=np.array(self.second_moment),
            fibre_tendon_side=np.array(self.x_high - x_bar),
            fibre_far_side=np.array(x_bar - self.x_low),
            face_arm=np.array(np.inf if keeps_wall(self.x_high, r_outer) else r_outer - x_bar))

    def x_extent(self) -> tuple[float, float]:
        """The smallest and largest ``x`` of the section's material (m)."""
        return self.x_low, self.x_high


#: Where a :class:`SlicedProfile` samples each slab, as fractions of it: the 5 Chebyshev
#: points (interior; the middle one exactly 0.5), through which a quartic is exact.
SLAB_NODES = (0.5 - 0.5 * math.cos(math.pi / 10.0), 0.5 - 0.5 * math.cos(0.3 * math.pi), 0.5,
              0.5 + 0.5 * math.cos(0.3 * math.pi), 0.5 + 0.5 * math.cos(math.pi / 10.0))
#: The quantities a :class:`SlicedProfile` samples, in the order of its rows.
SLAB_QUANTITIES = ("area", "first", "second", "x_low", "x_high")


@dataclass(frozen=True)
class SlicedProfile(_StraightSlot):
    """A notch whose section changes along the body, given by slices of a mesh
    (:mod:`tdcm_ros.model.mesh_body`): ``bounds`` (m, from the notch's start, base to tip)
    cut it into slabs between the mesh's vertex heights, in each of which every corner of the
    section moves linearly along the body; ``samples`` holds, per slab, the section's area
    (m^2), ``int x dA`` (m^3), ``int x^2 dA`` (m^4) and its extent ``x_low``, ``x_high`` (m)
    at the slab's :data:`SLAB_NODES` (25 numbers: each quantity's 5 in turn).

    Area, first and second moments are polynomials of degree 2, 3 and 4 in a slab (Green's
    theorem over edges whose ends move linearly), so the 5 samples give them exactly anywhere in
    it. The extent (the fibre farthest from the centroid, for the peak strain) is the polyline
    through the samples: exact while one corner stays the extreme one across the slab."""

    bounds: tuple[float, ...]
    samples: tuple[tuple[float, ...], ...]
    name: str = "sliced"

    def __hash__(self) -> int:
        return self._hash

    @cached_property
    def _hash(self) -> int:
        """The hash of the numbers, taken once: thousands of them, and designs holding the
        profile key the grid caches."""
        return hash((self.bounds, self.samples, self.name))

    @property
    def width(self) -> float:
        """The notch's width along the body (m)."""
        return self.bounds[-1]

    def breaks(self) -> Array:
        """The slabs' inner bounds as reference coordinates ``u`` in (0, 1)."""
        return np.asarray(self.bounds[1:-1]) / self.width

    def x_extent(self) -> tuple[float, float]:
        """The smallest and largest ``x`` of the notch's material anywhere along it (m)."""
        table = _slab_table(self.samples)
        return float(table[:, 3].min()), float(table[:, 4].max())

    def section_at(self, u: Array) -> tuple[Array, Array, Array, Array, Array]:
        """Area (m^2), centroid ``x_bar`` (m), centroidal second moment (m^4) and the extent
        ``x_low``, ``x_high`` (m) of the section at reference coordinates ``u`` (any shape)."""
        bounds = np.asarray(self.bounds)
        table = _slab_table(self.samples)
        sigma = np.clip(np.asarray(u, dtype=float), 0.0, 1.0) * self.width
        slab = np.clip(np.searchsorted(bounds, sigma, side="right") - 1, 0, len(table) - 1)
        t = (sigma - bounds[slab]) / (bounds[slab + 1] - bounds[slab])
        nodes = np.asarray(SLAB_NODES)
        basis = np.ones(t.shape + (nodes.size,))
        for j in range(nodes.size):
            for k in range(nodes.size):
                if k != j:
                    basis[..., j] *= (t - nodes[k]) / (nodes[j] - nodes[k])
        area, first, second = (np.sum(basis * table[slab, q], axis=-1) for q in range(3))
        x_bar = first / area
        low, high = (_polyline(t, nodes, table[slab, q]) for q in (3, 4))
        return area, x_bar, second - area * x_bar * x_bar, low, high


@lru_cache(maxsize=256)
def _slab_table(samples: tuple[tuple[float, ...], ...]) -> Array:
    """``samples`` as an array (slabs, quantities, nodes), read-only."""
    table = np.asarray(samples, dtype=float).reshape(len(samples), len(SLAB_QUANTITIES),
                                                     len(SLAB_NODES))
    table.setflags(write=False)
    return table


def _polyline(t: Array, nodes: Array, values: Array) -> Array:
    """The polyline through ``(nodes, values[..., j])`` at ``t`` (per point), extended
    straight past the first and last node."""
    segment = np.clip(np.searchsorted(nodes, t) - 1, 0, nodes.size - 2)
    t0, t1 = nodes[segment], nodes[segment + 1]
    v0 = np.take_along_axis(values, segment[..., None], axis=-1)[..., 0]
    v1 = np.take_along_axis(values, segment[..., None] + 1, axis=-1)[..., 0]
    return v0 + (t - t0) / (t1 - t0) * (v1 - v0)


PrismaticProfile = PolygonProfile | SectionProfile
PRISMATIC_PROFILES = (PolygonProfile, SectionProfile)


@lru_cache(maxsize=256)
def _polygon_properties(shell: tuple[tuple[float, float], ...],
                        holes: tuple[tuple[tuple[float, float], ...], ...], r_outer: float
                        ) -> SectionProperties:
    from tdcm_ros.model.sections import PolygonSection

    return PolygonSection(shell, r_outer, holes).properties()


#: Profiles whose section is given, not made from ``h1``: ``w_d`` and ``w_o`` are their extent.
GIVEN_SECTION_PROFILES = (PolygonProfile, SectionProfile, SlicedProfile)

NotchProfile = (CircularProfile | RectangularProfile | CustomProfile | PolygonProfile
                | SectionProfile | SlicedProfile)

PROFILE_NAMES: tuple[str, ...] = ("circular", "rectangular")


def profile_from_name(name: str) -> CircularProfile | RectangularProfile:
    """Return a built-in profile by name (``circular`` or ``rectangular``)."""
    from tdcm_ros.errors import out_of_range
    from tdcm_ros.model.errors import InvalidDesignError

    if name == "circular":
        return CircularProfile()
    if name == "rectangular":
        return RectangularProfile()
    raise out_of_range("profile", name, " | ".join(PROFILE_NAMES), error=InvalidDesignError)
