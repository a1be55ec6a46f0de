"""Cross-sections of a notch: what the mechanics needs from the material a cut leaves.

Coordinates in the section plane (m): ``x`` in the bending plane, + toward the tendon's side,
where one-sided cuts open; ``y`` across it; the tube axis at the origin. Every section type
gives its :class:`SectionProperties` (each field an array, broadcast over the section's
parameters, e.g. the paper's half-width ``h1`` at many stations of a notch):

- ``area`` ``A`` (m^2);
- ``centroid_x`` (m): the centroid's signed offset from the tube axis. A cut from +x moves it
  to -x, so a tendon at offset ``d`` bends the section with the arm ``d - centroid_x``;
- ``second_moment`` (m^4): ``int (x - centroid_x)^2 dA``, about the centroid's axis along
  ``y``; ``E`` times it is the section's bending stiffness;
- ``fibre_tendon_side`` / ``fibre_far_side`` (m): from the centroid to the farthest material on
  the +x side (compressed as the tendon bends the body) and on the -x side (stretched);
- ``face_arm`` (m): from the centroid to where the notch's faces meet as it closes, the tube's
  outer surface on the +x side (``R_outer - centroid_x``); ``inf`` where nothing is cut there
  (:func:`keeps_wall`). A prismatic notch of width ``w`` closes at the bend ``w / face_arm``
  (rad).

Three types: :class:`BandSection` (the paper's symmetric pair of cuts, eq. 12),
:class:`OneSidedCut` (a tube cut from +x to a depth, in closed form) and
:class:`PolygonSection` (any simple polygon of material, exact polygon integrals).
:func:`plateau_excess` integrates a bilinear material law over a polygon
(:mod:`tdcm_ros.model.material`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.grid_kernel import offset_section
from tdcm_ros.model.section import notched_area, notched_moment

Array = NDArray[np.float64]
#: A section whose material comes within this fraction of ``R_outer`` of the tube's outer
#: surface at ``x = +-R_outer`` keeps the wall on that side: the notch's faces do not meet
#: there (a polygon drawn round the tube with 23 or more edges reaches it wherever its vertices
#: fall).
SURFACE_TOL = 0.01
#: Relative slack (of ``R_outer``) for rounding of a section's reach into the wall: the check
#: ``|w_o| <= R_outer - w_d/2`` and a polygon's vertices within ``R_outer``.
OFFSET_SLACK = 1e-12


def keeps_wall(reach: ArrayLike, r_outer: ArrayLike) -> NDArray[np.bool_]:
    """Whether material reaching ``reach`` (m) toward a side keeps the tube's wall there
    (:data:`SURFACE_TOL`): ``reach`` is the section's largest ``x`` for the +x side, minus its
    smallest ``x`` for the -x side."""
    return np.asarray(np.asarray(reach) >= (1.0 - SURFACE_TOL) * np.asarray(r_outer))


def open_faces(w_d: ArrayLike, w_o: ArrayLike, r_outer: ArrayLike) -> NDArray[np.bool_]:
    """Whether a notch of backbone ``w_d`` (m) centred ``w_o`` (m) off the axis opens at the
    outer surface of a tube of ``r_outer`` (m) on the +x side (first axis, row 0) and the -x
    side (row 1): its section's material ``w_o +- w_d/2`` does not keep the wall there
    (:func:`keeps_wall`); inputs broadcast."""
    half = 0.5 * np.asarray(w_d)
    offset = np.asarray(w_o)
    return ~np.stack([keeps_wall(offset + half, r_outer), keeps_wall(half - offset, r_outer)])


@dataclass(frozen=True, eq=False)
class SectionProperties:
    """What a section gives the mechanics (SI units; see the module docstring)."""

    area: Array
    centroid_x: Array
    second_moment: Array
    fibre_tendon_side: Array
    fibre_far_side: Array
    face_arm: Array


class Section(Protocol):
    """A notch's cross-section: its :class:`SectionProperties`."""

    def properties(self) -> SectionProperties:
        """Area, centroid, centroidal second moment, extreme fibres and face arm (SI units)."""
        ...


def _tube(r_outer: float, r_inner: float) -> tuple[float, float]:
    """``(R_outer, r_inner)`` as floats, checked: ``0 < R_outer``, ``0 <= r_inner < R_outer`` (m)."""
    r_outer, r_inner = float(r_outer), float(r_inner)
    if not (math.isfinite(r_outer) and r_outer > 0.0):
        raise out_of_range("R_outer", r_outer, "(0, inf) m", error=InvalidDesignError)
    if not (math.isfinite(r_inner) and 0.0 <= r_inner < r_outer):
        raise out_of_range("r_inner", r_inner, f"[0, R_outer = {r_outer:g}) m",
                           error=InvalidDesignError)
    return r_outer, r_inner


@dataclass(frozen=True, eq=False)
class BandSection:
    """The paper's notch section (eq. 12): the tube's annulus ``r_inner <= rho <= R_outer``
    where ``|x| <= h1``, cut symmetrically from both sides. ``half_width`` is ``h1`` (m, > 0;
    an array gives one section per value); ``h1 >= R_outer`` is the uncut tube."""

    half_width: ArrayLike
    r_outer: float
    r_inner: float

    def properties(self) -> SectionProperties:
        """Eq. 12's ``I`` and its area, about the tube axis (the centroid, by symmetry)."""
        r_outer, r_inner = _tube(self.r_outer, self.r_inner)
        h1 = np.asarray(self.half_width, dtype=float)
        if not np.all(np.isfinite(h1) & (h1 > 0.0)):
            bad = h1[~(np.isfinite(h1) & (h1 > 0.0))].ravel()[0]
            raise out_of_range("h1", float(bad), "(0, inf) m", error=InvalidDesignError)
        fibre = np.minimum(h1, r_outer)
        return SectionProperties(
            area=notched_area(h1, r_outer, r_inner), centroid_x=np.zeros_like(h1),
            second_moment=notched_moment(h1, r_outer, r_inner), fibre_tendon_side=fibre,
            fibre_far_side=fibre.copy(), face_arm=np.where(keeps_wall(h1, r_outer), np.inf, r_outer))


@dataclass(frozen=True, eq=False)
class OneSidedCut:
    """A tube cut from the +x side, ``depth`` (m) deep from its outer surface: the annulus
    ``r_inner <= rho <= R_outer`` where ``x <= R_outer - depth``. ``0 <= depth < 2 R_outer``
    (0: uncut); an array gives one section per value. A cut past the axis opens the lumen
    (York et al. 2015's wrist: a 1.16 mm tube cut 0.97 mm deep)."""

    depth: ArrayLike
    r_outer: float
    r_inner: float

    def properties(self) -> SectionProperties:
        """The tube where ``x <= c = R_outer - depth``
        (:func:`tdcm_ros.model.grid_kernel.offset_section`, the solver's formula)."""
        r_outer, r_inner = _tube(self.r_outer, self.r_inner)
        depth = np.asarray(self.depth, dtype=float)
        ok = np.isfinite(depth) & (depth >= 0.0) & (depth < 2.0 * r_outer)
        if not np.all(ok):
            raise out_of_range("cut", float(depth[~ok].ravel()[0]),
                               f"[0, 2 R_outer = {2.0 * r_outer:g}) m", error=InvalidDesignError)
        plane = r_outer - depth
        area, second, centroid, _ = _offset_sections(0.5 * (plane + r_outer),
                                                     0.5 * (plane - r_outer), r_outer, r_inner)
        return SectionProperties(
            area=area, centroid_x=centroid, second_moment=second,
            fibre_tendon_side=plane - centroid, fibre_far_side=centroid + r_outer,
            face_arm=np.where(keeps_wall(plane, r_outer), np.inf, r_outer - centroid))


_offset_sections = np.vectorize(offset_section, otypes=[float] * 4)
""":func:`tdcm_ros.model.grid_kernel.offset_section` over arrays: the one formula of an
off-axis section, which the solver's cells use too."""


#: Fewest vertices of a polygon ring.
MIN_VERTICES = 3


@dataclass(frozen=True, eq=False)
class PolygonSection:
    """The material of a section as a simple polygon (m): ``shell`` (its outline, in either
    orientation) and optional ``holes`` (e.g. the lumen), each a list of ``(x, y)`` vertices,
    not closed (the last vertex joins the first). ``r_outer`` (m) is the tube's outer radius:
    a polygon that stays inside it on the +x side is a cut that opens there, whose faces meet
    at ``x = R_outer``. Validated with shapely (a maintained geometry library: simple rings,
    holes inside the shell, no self-touching); the integrals are Green's theorem's, exact for
    a polygon."""

    shell: Sequence[Sequence[float]]
    r_outer: float
    holes: Sequence[Sequence[Sequence[float]]] = ()

    def properties(self) -> SectionProperties:
        """Exact polygon integrals of area, ``int x dA`` and ``int x^2 dA``, then the centroid's."""
        r_outer = float(self.r_outer)
        if not (math.isfinite(r_outer) and r_outer > 0.0):
            raise out_of_range("R_outer", r_outer, "(0, inf) m", error=InvalidDesignError)
        shell = _ring(self.shell, "polygon")
        holes = [_ring(hole, f"polygon hole {k}") for k, hole in enumerate(self.holes)]
        _check_simple(shell, holes)
        moments = _ring_moments(shell) - sum((_ring_moments(h) for h in holes), np.zeros(3))
        area, first, second = (float(v) for v in moments)
        centroid = first / area
        x_max = float(shell[:, 0].max())
        return SectionProperties(
            area=np.array(area), centroid_x=np.array(centroid),
            second_moment=np.array(second - area * centroid * centroid),
            fibre_tendon_side=np.array(x_max - centroid),
            fibre_far_side=np.array(centroid - float(shell[:, 0].min())),
            face_arm=np.array(np.inf if keeps_wall(x_max, r_outer) else r_outer - centroid))


def _ring(points: Sequence[Sequence[float]], name: str) -> Array:
    """``points`` as an (n, 2) array of finite coordinates (m), at least ``MIN_VERTICES``."""
    try:
        ring = np.asarray(points, dtype=float)
    except (TypeError, ValueError) as error:
        raise InvalidDesignError(f"{name} must be a list of [x, y] points in m ({error})",
                                 parameter=name, value=points, allowed="[[x, y], ...] m") from error
    if ring.ndim != 2 or ring.shape[1] != 2 or ring.shape[0] < MIN_VERTICES:
        raise out_of_range(name, points, f"at least {MIN_VERTICES} [x, y] points (m)",
                           error=InvalidDesignError)
    if not np.all(np.isfinite(ring)):
        raise out_of_range(name, points, "finite coordinates (m)", error=InvalidDesignError)
    return ring


def _check_simple(shell: Array, holes: list[Array]) -> None:
    """Raise :class:`InvalidDesignError` with shapely's reason unless shell and holes make a
    valid polygon of positive area (simple rings, holes inside, nothing self-touching)."""
    import shapely
    from shapely.geometry import Polygon

    polygon = Polygon(shell, holes)
    if not polygon.is_valid or polygon.area <= 0.0:
        reason = shapely.is_valid_reason(polygon) if not polygon.is_valid else "zero area"
        raise InvalidDesignError(
            f"polygon is not a simple polygon of material: {reason}", parameter="polygon",
            value=shell.tolist(), allowed="a simple ring (holes inside it) of positive area")


def _ring_moments(ring: Array) -> Array:
    """``(A, int x dA, int x^2 dA)`` of the region a ring encloses (m^2, m^3, m^4), whatever
    its orientation: Green's theorem over its edges (:func:`edge_moments`)."""
    moments = edge_moments(ring, np.roll(ring, -1, axis=0))[:3]
    return moments if moments[0] > 0.0 else -moments


def edge_moments(start: Array, end: Array) -> Array:
    """``(A, int x dA, int x^2 dA, int y dA)`` (m^2, m^3, m^4, m^3) of the region bounded by
    the directed edges ``start[..., k, :] -> end[..., k, :]`` (arrays ``(..., n, 2)`` of
    ``(x, y)`` in m; leading axes are regions of their own, and the result has them after its
    first axis), the material on each edge's left (outer boundaries counter-clockwise, holes
    clockwise): Green's theorem, exact for straight edges, in any order and from any number of
    loops."""
    x, y = start[..., 0], start[..., 1]
    x1, y1 = end[..., 0], end[..., 1]
    cross = x * y1 - x1 * y
    return np.array([np.sum(cross, axis=-1) / 2.0, np.sum((x + x1) * cross, axis=-1) / 6.0,
                     np.sum((x * x + x * x1 + x1 * x1) * cross, axis=-1) / 12.0,
                     np.sum((y + y1) * cross, axis=-1) / 6.0])


def material_edges(shell: Array, holes: Sequence[Array]) -> tuple[Array, Array]:
    """The directed edges ``(start, end)`` ((n, 2) each, m) of a polygon of material with the
    material on each edge's left, whatever the rings' orientation: the shell turned
    counter-clockwise, the holes clockwise (by the sign of each ring's area, as
    :func:`_ring_moments` reads it)."""
    rings = [_oriented(shell, 1.0), *(_oriented(hole, -1.0) for hole in holes)]
    return (np.concatenate(rings),
            np.concatenate([np.roll(ring, -1, axis=0) for ring in rings]))


def _oriented(ring: Array, sign: float) -> Array:
    """``ring`` ((n, 2), m) turned so its signed area has the sign ``sign``."""
    area = edge_moments(ring, np.roll(ring, -1, axis=0))[0]
    return ring if area * sign > 0.0 else ring[::-1]


def plateau_excess(start: Array, end: Array, x_bar: ArrayLike, d: ArrayLike) -> Array:
    """``J(d) = int_{|x - x_bar| > d} (|x - x_bar| - d) |x - x_bar| dA`` (m^4) of the polygon
    bounded by the edges ``start -> end`` ((n, 2), m; material on the left:
    :func:`material_edges`) about the axis ``x = x_bar`` (m), at plateau distances ``d >= 0``
    (m); ``x_bar`` and ``d`` broadcast, one ``J`` per pair. ``J(0)`` is the second moment
    about ``x_bar``.

    Exact, by Green's theorem on each side: with ``w = +-(x - x_bar) - d`` the distance past
    the line ``w = 0``, the side's integrand is ``w (w + d)``, whose antiderivative
    ``F = w^3/3 + d w^2/2`` vanishes on that line; so the side's ``J`` is ``+-`` the sum, over
    each edge's part with ``w >= 0``, of ``int F dy`` (a cubic in ``w``, linear along the
    edge: in closed form), and no polygon is clipped. Edges no pair's ``w`` reaches on a side
    are left out of it."""
    x_bar, d = (a[..., None] for a in np.broadcast_arrays(np.asarray(x_bar, dtype=float),
                                                          np.asarray(d, dtype=float)))
    total = np.zeros(d.shape[:-1])
    for side in (1.0, -1.0):
        line = np.min(side * x_bar + d, initial=np.inf)
        edges = np.maximum(side * start[:, 0], side * end[:, 0]) > line
        x0, x1 = start[edges, 0], end[edges, 0]
        rise = end[edges, 1] - start[edges, 1]
        w0, w1 = side * (x0 - x_bar) - d, side * (x1 - x_bar) - d
        a, b = np.maximum(w0, 0.0), np.maximum(w1, 0.0)
        crossing = (w0 < 0.0) != (w1 < 0.0)
        kept = np.where(crossing, (a + b) / np.where(crossing, np.abs(w1 - w0), 1.0), 1.0)
        mean = (a + b) * (a * a + b * b) / 12.0 + d * (a * a + a * b + b * b) / 6.0
        total += side * np.sum(kept * rise * mean, axis=-1)
    return total
