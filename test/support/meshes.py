"""Triangle meshes of notched tubes for the mesh-body tests and bench, built with manifold3d
(extrusions of each segment's section, united into one watertight solid) and written with
trimesh. Lengths in mm, as a CAD export's."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient
from shapely.ops import unary_union

#: A segment: ``("tube", length)``, ``("notch", length, material)``, ``material`` a shapely
#: geometry of what the notch leaves (mm), clipped to the tube's outer surface here (not to its
#: lumen: material across the lumen, a printed web, is the body's), or ``("solid", length,
#: material)``, the material as given (a flange wider than the tube).
Segment = tuple[Any, ...]


def ngon(radius: float, sides: int) -> Polygon:
    """A regular polygon of ``sides`` inscribed in the circle of ``radius`` (mm), a vertex at +x."""
    angle = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    return Polygon(np.c_[radius * np.cos(angle), radius * np.sin(angle)])


def annulus(r_outer: float, r_inner: float, sides: int) -> Any:
    """The faceted tube's section (mm): the ``sides``-gon of ``r_outer`` less that of
    ``r_inner`` (none if 0)."""
    outer = ngon(r_outer, sides)
    return outer.difference(ngon(r_inner, sides)) if r_inner > 0.0 else outer


def rings(geometry: Any) -> list[np.ndarray]:
    """The contours of a (multi)polygon for manifold3d: outer rings counter-clockwise, holes
    clockwise, not closed."""
    out = []
    for part in getattr(geometry, "geoms", [geometry]):
        part = orient(part, 1.0)
        out.append(np.asarray(part.exterior.coords)[:-1])
        out += [np.asarray(hole.coords)[:-1] for hole in part.interiors]
    return out


def cross_section(segment: Segment, tube: Any) -> Any:
    """A segment's section as manifold3d holds it (its coordinates rounded to 1e-8 mm by
    Clipper2): the tube's, or the notch's material within the tube's outer surface."""
    import manifold3d

    if segment[0] == "solid":
        return manifold3d.CrossSection(rings(segment[2]))
    outer = Polygon(tube.exterior) if hasattr(tube, "exterior") else tube
    return manifold3d.CrossSection(rings(tube if segment[0] == "tube"
                                         else segment[2].intersection(outer)))


def as_shapely(section: Any) -> Any:
    """A manifold3d cross-section as the shapely geometry of its material: its
    counter-clockwise contours less its clockwise ones."""
    outer, holes = [], []
    for contour in section.to_polygons():
        ring = Polygon(np.asarray(contour))
        (outer if ring.exterior.is_ccw else holes).append(ring)
    material = unary_union(outer)
    return material.difference(unary_union(holes)) if holes else material


def body_mesh(segments: Sequence[Segment], r_outer: float, r_inner: float, sides: int = 256
              ) -> Any:
    """The body of ``segments`` base to tip along +z from z = 0 as a watertight
    ``trimesh.Trimesh`` (mm): each tube the faceted annulus, each notch its material within
    it (:func:`cross_section`)."""
    import manifold3d
    import trimesh

    tube = annulus(r_outer, r_inner, sides)
    parts = []
    z = 0.0
    for segment in segments:
        section = cross_section(segment, tube)
        if not section.is_empty():  # a notch with no material: a gap in the body
            solid = manifold3d.Manifold.extrude(section, segment[1])
            parts.append(solid.translate((0.0, 0.0, z)))
        z += segment[1]
    mesh = manifold3d.Manifold.batch_boolean(parts, manifold3d.OpType.Add).to_mesh64()
    return trimesh.Trimesh(np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts),
                           process=False)


def write_mesh(mesh: Any, path: Path) -> Path:
    """Write ``mesh`` to ``path`` (its format from the suffix, e.g. a binary STL)."""
    mesh.export(str(path))
    return path


def slanted_cut_mesh(r_outer: float, r_inner: float, length: float,
                     cuts: Sequence[tuple[tuple[float, float], tuple[float, float]]],
                     sides: int = 256) -> Any:
    """A tube of ``length`` (mm) along +z with slanted cuts from +x: each ``((z0, z1), (x0,
    x1))`` removes, between ``z0`` and ``z1``, the material with ``x >= x0`` at ``z0`` and
    ``x >= x1`` at ``z1`` (linear between: a plane), so the notch's section changes all along
    it. The material at height ``z`` in a cut is the faceted annulus with ``x`` at most the
    plane's. A watertight ``trimesh.Trimesh`` (mm)."""
    import manifold3d
    import trimesh

    body = manifold3d.Manifold.extrude(manifold3d.CrossSection(rings(annulus(
        r_outer, r_inner, sides))), length)
    far = 2.0 * r_outer
    for (z0, z1), (x0, x1) in cuts:
        corners = [(x, y, z) for (x, z) in ((x0, z0), (far, z0), (x1, z1), (far, z1))
                   for y in (-far, far)]
        body = body - manifold3d.Manifold.hull_points(np.array(corners, dtype=float))
    mesh = body.to_mesh64()
    return trimesh.Trimesh(np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts),
                           process=False)
