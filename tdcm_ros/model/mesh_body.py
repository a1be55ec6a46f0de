"""Bodies from a triangle mesh (STL, or another format trimesh reads), sliced along the body.

The mesh is the body in the body file's frame: its axis +z from ``z = 0`` at the base, cuts
and the tendon on the +x side, lengths in ``unit`` (``m`` or ``mm``). It must be watertight
with outward normals (:mod:`tdcm_ros.model.mesh_file` reads and checks it). A mesh changes
along z only where it has vertices, so the body's segments end at the z values of its
vertices: the mesh is sliced once between each two consecutive ones, each plane meeting only
the triangles spanning its slab, and each slice's area and moments are Green's theorem's over
its edges (:func:`tdcm_ros.model.sections.edge_moments`), exact for the mesh: no loop
assembly, so a section of several pieces (the paper's pair of cuts through the lumen leaves
two) needs nothing more. The slices are kept on disk by the file's content
(:mod:`tdcm_ros.model.file_cache`), so reading the same mesh again skips reading and slicing.

Slices with the tube's section (the one most of the body's length has, to
:data:`SECTION_TOL`) are tube; a slice with more material (a flange, a cap) is refused, naming
where;
each run of other slices is one notch. A prismatic one (the same section all along it, to
:data:`SECTION_TOL`: a slot cut straight through, as laser and wire cuts are) has the slice's
own section (:class:`~tdcm_ros.model.profiles.SectionProfile`). One whose section changes
along the body (a circular-bottomed or slanted cut, a notch of several slots) is a
:class:`~tdcm_ros.model.profiles.SlicedProfile`: in each slab every corner of the section
moves linearly with z, so each slab is sliced at the 5 heights of
:data:`~tdcm_ros.model.profiles.SLAB_NODES`, which give its area and moments exactly at any
height, and the slabs' bounds become cell bounds of the grid.

The tube is the circle through the outermost vertices of its slice (``R_outer``) less the
circle through the innermost vertices of its lumen (``r_inner``; 0 where no edge of the slice
faces the axis). A mesh coarse enough around for that annulus' second moment to differ from
the faceted slice's by more than :data:`COARSE_TOL` gets a warning saying by how much (the
difference is a systematic error of the tubes' stiffness; the notches are the mesh's own).
"""

from __future__ import annotations

import logging
import math
from dataclasses import astuple, dataclass, fields
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.design import MIN_SEGMENT_M
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.file_cache import Row, cached_rows
from tdcm_ros.model.mesh_file import TriangleMesh, read_mesh
from tdcm_ros.model.profiles import (
    SLAB_NODES,
    SLAB_QUANTITIES,
    SectionProfile,
    SlicedProfile,
)
from tdcm_ros.model.sections import edge_moments

Array = NDArray[np.float64]
LOG = logging.getLogger(__name__)

#: Lengths of a mesh file in metres per unit.
UNITS = {"m": 1.0, "mm": 1e-3}
#: Relative tolerance of "the same section" (area and moments, against the tube's).
SECTION_TOL = 1e-4
#: Relative difference of the tube's second moment from the circles' that draws a warning.
COARSE_TOL = 1e-3
#: Vertex heights closer than this (m) are one (float32 STL coordinates round at ~1e-9 m).
Z_MERGE_M = MIN_SEGMENT_M / 10.0
#: The tube's section centroid must lie within this fraction of ``R_outer`` of the z axis.
AXIS_TOL = 1e-3


@dataclass(frozen=True)
class Slice:
    """The mesh's slab between two consecutive vertex heights ``z_low``..``z_high`` (m), sliced
    at its middle ``z`` (m): ``area`` (m^2), ``first`` = ``int x dA`` (m^3), ``second`` =
    ``int x^2 dA`` (m^4), ``first_y`` = ``int y dA`` (m^3), the material's extent
    ``x_low``..``x_high`` (m), the outermost vertex's distance from the axis and the innermost
    of the edges facing the axis (m, 0 if none); ``samples``: area, first, second, x_low and
    x_high at each of :data:`~tdcm_ros.model.profiles.SLAB_NODES` across the slab (a
    :class:`~tdcm_ros.model.profiles.SlicedProfile`'s slab)."""

    z: float
    z_low: float
    z_high: float
    area: float
    first: float
    second: float
    first_y: float
    x_low: float
    x_high: float
    outer: float
    inner: float
    samples: tuple[float, ...]

    def row(self) -> Row:
        """The slice as one row of :data:`SLICE_FIELDS`."""
        return (*astuple(self)[:-1], *self.samples)

    @classmethod
    def of_row(cls, row: Row) -> Slice:
        """The slice of a row of :data:`SLICE_FIELDS`."""
        z, z_low, z_high, area, first, second, first_y, x_low, x_high, outer, inner = (
            float(v) for v in row[:_SCALARS])
        return cls(z, z_low, z_high, area, first, second, first_y, x_low, x_high, outer, inner,
                   tuple(float(v) for v in row[_SCALARS:]))

    def same_as(self, other: Slice, scale: Slice) -> bool:
        """Whether this slice's area and moments equal ``other``'s to :data:`SECTION_TOL` of
        ``scale``'s (the tube's), at its middle and at every sample."""
        nodes = len(SLAB_NODES)
        radius = scale.outer
        tolerance = SECTION_TOL * scale.area * np.array([1.0, radius, radius**2])
        mine = np.reshape(self.samples, (len(SLAB_QUANTITIES), nodes))[:3]
        theirs = np.array([other.area, other.first, other.second])
        return bool(np.all(np.abs(mine - theirs[:, None]) <= tolerance[:, None])
                    and np.all(np.abs(np.array([self.area, self.first, self.second]) - theirs)
                               <= tolerance))

    def profile(self) -> SectionProfile:
        """The slice as a prismatic notch section."""
        x_bar = self.first / self.area
        return SectionProfile(area=self.area, centroid_x=x_bar,
                             second_moment=self.second - self.area * x_bar * x_bar,
                             x_low=self.x_low, x_high=self.x_high)


_SCALARS = len(fields(Slice)) - 1
#: The columns of a :class:`Slice`'s row (:mod:`tdcm_ros.model.file_cache`): its numbers, then
#: its samples, each quantity at each node.
SLICE_FIELDS = (*(f.name for f in fields(Slice)[:-1]),
                *(f"{q}_{j}" for q in SLAB_QUANTITIES for j in range(len(SLAB_NODES))))


@dataclass(frozen=True)
class MeshSegment:
    """A segment found in the mesh: ``length`` (m) and, for a notch, its ``section``."""

    length: float
    section: SectionProfile | SlicedProfile | None
    where: str


@dataclass(frozen=True)
class MeshBody:
    """A mesh read as a body: the tube's radii (m) and the segments base to tip."""

    R_outer: float
    r_inner: float
    segments: tuple[MeshSegment, ...]


def read_mesh_body(path: str | Path, unit: str, where: str = "mesh") -> MeshBody:
    """The body of the mesh file at ``path`` whose lengths are in ``unit``; every problem is an
    :class:`InvalidDesignError` naming ``where``'s key (``mesh.file``, ``mesh.unit``)."""
    if unit not in UNITS:
        raise out_of_range(f"{where}.unit", unit, " | ".join(UNITS), error=InvalidDesignError)
    key = f"{where}.file"

    def sliced() -> list[Row]:
        return [s.row() for s in _slices(read_mesh(path, UNITS[unit], key), key)]

    rows = cached_rows(Path(path), unit, SLICE_FIELDS, sliced)
    return _segments([Slice.of_row(row) for row in rows], key, unit)


def _slices(mesh: TriangleMesh, key: str) -> list[Slice]:
    """One slice between each two consecutive vertex heights of ``mesh`` (m), base to tip: each
    plane meets only the faces spanning its slab, each of them along the segment between its
    two edges that cross the plane."""
    heights = np.unique(mesh.vertices[:, 2])
    keep = np.concatenate([[True], np.diff(heights) > Z_MERGE_M])
    heights = heights[keep]
    length = float(heights[-1] - heights[0])
    if abs(float(heights[0])) > Z_MERGE_M + 1e-9 * length:
        raise InvalidDesignError(
            f"{key}: the body starts at z = {heights[0]:.6g} m; allowed: z = 0 at the base, "
            "the body along +z", parameter=key, value=float(heights[0]),
            allowed="the base at z = 0, the axis +z")
    corners = mesh.corners()
    normals = mesh.normals()
    face_z = corners[:, :, 2]
    low, high = face_z.min(axis=1), face_z.max(axis=1)
    out = []
    for k, z in enumerate(0.5 * (heights[1:] + heights[:-1])):
        spanning = np.flatnonzero((low < z) & (high > z))
        if spanning.size == 0:
            raise InvalidDesignError(
                f"{key}: no material at z = {z:.6g} m (the body comes apart there)",
                parameter=key, value=float(z), allowed="material at every height")
        span = (float(heights[k]), float(z), float(heights[k + 1]))
        at = np.array([z if node == 0.5 else span[0] + node * (span[2] - span[0])
                       for node in SLAB_NODES])
        out.append(_slice(span, _plane_segments(corners[spanning], at), normals[spanning]))
    return out


def _plane_segments(corners: Array, heights: Array) -> Array:
    """Where the planes at ``heights`` (h,) (m) cut each triangle of ``corners`` (k, 3, 3),
    each of which has corners on both sides of every one of them: segments (h, k, 2, 2) of
    ``(x, y)`` ends (m). A corner on a plane counts as below it, so each triangle has exactly
    two edges that cross."""
    start, end = corners, np.roll(corners, -1, axis=1)  # edges 0-1, 1-2, 2-0
    z = heights[:, None, None]
    crosses = (start[:, :, 2] > z) != (end[:, :, 2] > z)
    along = (z - start[:, :, 2]) / np.where(crosses, end[:, :, 2] - start[:, :, 2], 1.0)
    points = start[:, :, :2] + along[..., None] * (end[:, :, :2] - start[:, :, :2])
    first_two = np.argsort(~crosses, axis=-1, kind="stable")[..., :2]
    return np.take_along_axis(points, first_two[..., None], axis=-2)


def _slice(span: tuple[float, float, float], segments: Array, normals: Array) -> Slice:
    """The :class:`Slice` of the slab ``span`` (its low, middle and high z, m) from its planes'
    edge segments ((h, k, 2, 2): the planes at :data:`SLAB_NODES`, ends, (x, y), m), each
    oriented with the material on its left by its face's normal (k, 3)."""
    start, end = segments[..., 0, :], segments[..., 1, :]
    direction = end - start
    left_is_outside = direction[..., 1] * normals[:, 0] - direction[..., 0] * normals[:, 1] < 0.0
    start, end = (np.where(left_is_outside[..., None], end, start),
                  np.where(left_is_outside[..., None], start, end))
    area, first, second, first_y = edge_moments(start, end)
    points = np.concatenate([start, end], axis=-2)
    x_low, x_high = points[..., 0].min(axis=-1), points[..., 0].max(axis=-1)
    middle = SLAB_NODES.index(0.5)
    radius = np.hypot(points[middle, :, 0], points[middle, :, 1])
    facing_axis = np.sum(0.5 * (start[middle] + end[middle]) * normals[:, :2], axis=1) < 0.0
    inner = float(np.max(np.hypot(start[middle, facing_axis, 0], start[middle, facing_axis, 1]),
                         initial=0.0))
    samples = tuple(float(v) for v in np.concatenate([area, first, second, x_low, x_high]))
    return Slice(span[1], span[0], span[2], float(area[middle]), float(first[middle]),
                 float(second[middle]), float(first_y[middle]), float(x_low[middle]),
                 float(x_high[middle]), float(radius.max()), inner, samples)


def _tube(slices: list[Slice]) -> Slice:
    """The tube's slice: of the sections, the one the most length of the body has (areas equal
    to :data:`SECTION_TOL` of the largest count as one)."""
    areas = np.array([s.area for s in slices])
    lengths = np.array([s.z_high - s.z_low for s in slices])
    same = np.abs(areas[:, None] - areas[None, :]) <= SECTION_TOL * areas.max()
    return slices[int(np.argmax(same @ lengths))]


def _segments(slices: list[Slice], key: str, unit: str) -> MeshBody:
    """Tube and notch segments of ``slices`` (see the module docstring)."""
    tube = _tube(slices)
    _check_axis(tube, key)
    scale = UNITS[unit]
    wider = next((s for s in slices if s.area > (1.0 + SECTION_TOL) * tube.area), None)
    if wider is not None:
        raise InvalidDesignError(
            f"{key}: z = {wider.z_low / scale:.6g}..{wider.z_high / scale:.6g} {unit} has more "
            f"material than the tube ({wider.area:.6g} m^2 against the tube's {tube.area:.6g} "
            "m^2, the section most of the body has): a flange, cap or boss, which a body of "
            "tubes and notches does not have; allowed: the tube and its notches only (trim the "
            "mesh to them)", parameter=key, value=wider.area,
            allowed=f"a section of at most the tube's area, {tube.area:.6g} m^2")
    is_tube = [s.area >= (1.0 - SECTION_TOL) * tube.area for s in slices]
    out: list[MeshSegment] = []
    k = 0
    while k < len(slices):
        run = k
        while run + 1 < len(slices) and is_tube[run + 1] == is_tube[k]:
            run += 1
        start, stop = slices[k].z_low, slices[run].z_high
        here = f"{key}: z = {start / scale:.6g}..{stop / scale:.6g} {unit}"
        if is_tube[k]:
            out.append(MeshSegment(stop - start, None, here))
        else:
            notch = 1 + sum(1 for s in out if s.section is not None)
            run_slices = slices[k:run + 1]
            prismatic = all(other.same_as(slices[k], tube) for other in run_slices)
            section = slices[k].profile() if prismatic else _sliced(run_slices, start)
            out.append(MeshSegment(stop - start, section, f"{here} (notch {notch})"))
        k = run + 1
    r_outer, r_inner = tube.outer, tube.inner
    ring = math.pi / 4.0 * (r_outer**4 - r_inner**4)
    if abs(tube.second - ring) > COARSE_TOL * ring:
        LOG.warning("%s: the faceted tube's second moment is %.3g %% off the circles through its "
                    "vertices (R_outer %.6g m, r_inner %.6g m), which the tubes are taken as: "
                    "the mesh is coarse around (use more facets for a closer tube)", key,
                    100.0 * (tube.second - ring) / ring, r_outer, r_inner)
    return MeshBody(R_outer=r_outer, r_inner=r_inner, segments=tuple(out))


def _sliced(run: list[Slice], start: float) -> SlicedProfile:
    """The notch of the slabs ``run``, which starts at height ``start`` (m), whose section
    changes along it."""
    bounds = (0.0, *(s.z_high - start for s in run[:-1]), run[-1].z_high - start)
    return SlicedProfile(bounds=bounds, samples=tuple(s.samples for s in run))


def _check_axis(tube: Slice, key: str) -> None:
    """Refuse a mesh whose tube is not centred on the z axis (:data:`AXIS_TOL`)."""
    centre = (tube.first / tube.area, tube.first_y / tube.area)
    if math.hypot(*centre) > AXIS_TOL * tube.outer:
        raise InvalidDesignError(
            f"{key}: the tube's section is centred at (x, y) = ({centre[0]:.6g}, "
            f"{centre[1]:.6g}) m; allowed: on the z axis (the body along +z from the origin)",
            parameter=key, value=list(centre), allowed="the tube centred on the z axis")
