"""Designs exported as triangle meshes: the body as one watertight solid (an STL for a printer
or CAD) that the package's mesh path (:mod:`tdcm_ros.model.mesh_body`) reads back to the same
shape.

The mesh is in the body file's frame: the axis +z from ``z = 0`` at the base, cuts and the
tendon on +x. manifold3d (a maintained mesh-boolean library: the ``export`` extra) builds it,
trimesh writes it:

- the tube: the annulus between regular ``sides``-gons (``sides`` even, a vertex at +x) whose
  vertices lie on the ``R_outer`` and ``r_inner`` circles, so the circles the mesh reader takes
  the tube as (through the outermost vertices and the lumen's) are the design's; a disc where
  ``r_inner = 0``; extruded over the body's length;
- a band or cut notch leaves the tube where ``low <= x <= high``: what lies outside is removed
  (one staircase in the (x, z) plane, extruded across the tube and subtracted: the cuts'
  faces cross the tube's, so no two faces lie on one another and the STL's float32
  coordinates keep the mesh closed). ``low, high = w_o -+ h``: ``h = w_d/2`` for a rectangular
  profile; a circular notch (eq. 13, ``h1`` varying along it) or a custom one is a staircase of
  ``slabs`` prismatic slabs of equal length, each ``h`` giving the slab the true profile's
  bending compliance ``int ds / I`` over it (:func:`band_slabs`). Each band's edges are then
  moved (by ~1e-5 of ``R_outer``) so that the faceted section's second moment is the one
  aimed at: the reader slices the faceted notch as it is, so the notches bend as the design's
  whatever ``sides``;
- a polygon notch: the tube removed there and the polygon (shell less holes) extruded in its
  place, exactly the section the design integrates;
- a section given by its numbers or by a mesh's slices has no shape: refused.

A round trip through an STL in mm gives the design's tip to ~1e-5 of its displacement
(``test/model/test_mesh_export.py``); ~1e-4 for a circular one-sided cut, whose centroid moves
along the notch (the slabs match its compliance, not the tendon's arm to the centroid).

The mesh is geometry only: the body file that names it (:func:`mesh_body_file_text`) carries
the material and the tendons. The mesh path takes a linear material only (a non-linear law is
integrated over a section's widths, which a mesh's slices do not give). It takes as the tube
the section most of the body's length has, so a body of more notch than tube does not read
back (:func:`.design_mesh` warns).
"""

from __future__ import annotations

import json
import logging
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.model.design import MIN_SEGMENT_M, Design
from tdcm_ros.model.errors import InvalidDesignError, ModelError
from tdcm_ros.model.mesh_body import SECTION_TOL, UNITS
from tdcm_ros.model.profiles import (
    CircularProfile,
    CustomProfile,
    NotchProfile,
    PolygonProfile,
    RectangularProfile,
    SectionProfile,
)

if TYPE_CHECKING:
    import trimesh

Array = NDArray[np.float64]
LOG = logging.getLogger(__name__)

#: Sides of the regular polygons of the tube's circles: the reader's tube is their circles
#: either way, and the band edges are fitted to the faceted sections; more sides only follow
#: the circles closer (the notches' areas and centroids, ~(pi/sides)^2 of the wall).
DEFAULT_SIDES = 512
#: Slabs per circular or custom notch: the round trip's error from the staircase falls as
#: ``1/slabs^2``, of the tip's displacement ~5e-5 / slabs^2 for the paper's notch, ~0.03 /
#: slabs^2 for a circular one-sided cut (its centroid moves along the notch).
DEFAULT_SLABS = 16
#: Allowed ``sides`` (even: the polygon symmetric about both axes) and ``slabs``. Below 128
#: sides the faceted tube's second moment is more than the reader's COARSE_TOL off its circles.
SIDES_RANGE = (128, 8192)
SLABS_RANGE = (1, 512)
#: How to get manifold3d: the package's ``export`` extra.
INSTALL_HINT = "pip install 'tdcm_ros[export]'"
#: A band edge within this fraction of ``R_outer`` of a polygon vertex's x is moved this far
#: from it, and one within it of the tube's extent cuts nothing: no sliver thinner than the
#: STL's float32 coordinates resolve.
EDGE_CLEARANCE = 1e-6
#: Gauss-Legendre points of each piece of a slab's compliance integral.
QUADRATURE_POINTS = 64
#: Bisection steps of a slab's half-width on the circles (the bracket is ``2 R_outer`` wide),
#: then Newton steps on the faceted section.
BISECTIONS = 60
NEWTON_STEPS = 3
#: Profiles exported as bands (slabs of the tube where ``low <= x <= high``).
BAND_PROFILES = (RectangularProfile, CircularProfile, CustomProfile)


class InvalidExportError(ModelError, InputError):
    """An export argument (``unit``, ``sides``, ``slabs``, ``path``) is outside its range, or
    manifold3d (the ``export`` extra) is missing."""

    kind = "invalid_export"


def design_mesh(design: Design, *, unit: str = "m", sides: int = DEFAULT_SIDES,
                slabs: int = DEFAULT_SLABS) -> trimesh.Trimesh:
    """``design`` as a watertight ``trimesh.Trimesh`` with outward normals, lengths in ``unit``
    (``m`` or ``mm``), in the body file's frame (module docstring). Logs a warning where the
    mesh path will not read it back as ``design`` (:func:`_warn_unreadable`)."""
    scale = _unit(unit)
    _check_args(design, sides, slabs)
    for i, profile in enumerate(design.notch_profiles()):
        if not isinstance(profile, (PolygonProfile, *BAND_PROFILES)):
            raise _no_bands(design, i, profile)
    manifold3d = _manifold3d()
    import trimesh
    from shapely.affinity import scale as scaled
    from shapely.geometry import Polygon

    removed, polygons = _plan(design, sides, slabs)
    size = design.R_outer  # manifold3d rounds 2D coordinates to ~1e-8: work in R_outer
    length = design.length / size
    boxes = [_box(a / size, b / size, c / size, d / size, length) for a, b, c, d in removed]
    inner = [_ring(design.r_inner / size, sides)] if design.r_inner > 0.0 else []
    body = manifold3d.Manifold.extrude(_cross_section(manifold3d, Polygon(
        _ring(1.0, sides), inner)), length)
    if boxes:
        body = body - _across(manifold3d, boxes)
    # a polygon notch: its polygon along the whole body cut to the notch by the box of the
    # (x, z) plane that removed the tube there, so the two meet at the same heights to the bit
    prisms = [manifold3d.Manifold.extrude(_cross_section(manifold3d, scaled(
        material, 1.0 / size, 1.0 / size, origin=(0.0, 0.0))), length)
        ^ _across(manifold3d, [_box(-2.0, low / size, 2.0, high / size, length)])
        for low, high, material in polygons]
    solid = manifold3d.Manifold.batch_boolean([body, *prisms], manifold3d.OpType.Add)
    mesh = solid.to_mesh64()
    return trimesh.Trimesh(np.asarray(mesh.vert_properties)[:, :3] * (size / scale),
                           np.asarray(mesh.tri_verts), process=False)


def _plan(design: Design, sides: int, slabs: int
          ) -> tuple[list[tuple[float, float, float, float]], list[tuple[float, float, Any]]]:
    """What the notches remove from the tube, as boxes ``(x_low, z_low, x_high, z_high)`` of
    the (x, z) plane (m), and each polygon notch's ``(z_low, z_high, polygon)`` (m); warns
    where the mesh path will not read the body back (:func:`_warn_unreadable`)."""
    from shapely.geometry import Polygon

    rings = _rings_of(design, sides)
    tube_area = float(_faceted_moments(rings, np.array([-np.inf]), np.array([np.inf]))[0][0])
    far = 2.0 * design.R_outer
    removed, polygons = [], []
    pieces = [(design.length - float(np.sum(design.per_notch("w_n"))), tube_area)]
    bands: dict[tuple[Any, ...], tuple[Array, Array, Array]] = {}  # by notch shape
    starts, ends = design.notch_bounds()
    for i, profile in enumerate(design.notch_profiles()):
        start, end = float(starts[i]), float(ends[i])
        if isinstance(profile, PolygonProfile):
            material = Polygon(profile.shell, profile.holes)
            polygons.append((start, end, material))
            removed.append((-far, start, far, end))
            pieces.append((end - start, material.area))
            continue
        key = (profile, *(float(design.per_notch(name)[i]) for name in ("w_n", "w_d", "w_o")))
        if key not in bands:
            bands[key] = band_slabs(design, i, sides=sides, slabs=slabs)
        bounds, low, high = bands[key]
        pieces += zip(np.diff(bounds).tolist(), _faceted_moments(rings, low, high)[0].tolist())
        for z_low, z_high, x_low, x_high in zip(start + bounds[:-1], start + bounds[1:], low,
                                                high, strict=True):
            if np.isfinite(x_high):
                removed.append((x_high, z_low, far, z_high))
            if np.isfinite(x_low):
                removed.append((-far, z_low, x_low, z_high))
    _warn_unreadable(pieces, tube_area)
    return removed, polygons


def _warn_unreadable(pieces: list[tuple[float, float]], tube_area: float) -> None:
    """Log a warning where the mesh path will not read the body of ``pieces`` (the tube's total
    length first, then each slab's; m, and area, m^2) back: it takes as the tube the section
    most of the body's length has (areas equal to its SECTION_TOL) and refuses one with more
    material than the tube's."""
    lengths, areas = np.array(pieces).T
    same = np.abs(areas[:, None] - areas[None, :]) <= SECTION_TOL * areas.max()
    most = int(np.argmax(same @ lengths))
    if not same[most, 0]:
        LOG.warning("the mesh path will not read this body's mesh back as the design: it takes "
                    "the section most of the body's length has as the tube, here a notch's "
                    "(%.6g m^2 over %.6g m, the tube's %.6g m^2 over %.6g m); give the body "
                    "more plain tube (w_base, w_t, w_tip)", areas[most],
                    float(same[most] @ lengths), tube_area, float(same[0] @ lengths))
    if areas.max() > (1.0 + SECTION_TOL) * tube_area:
        LOG.warning("the mesh path will not read this body's mesh back as the design: a "
                    "polygon notch has more material than the tube (%.6g m^2 against %.6g "
                    "m^2), which it refuses as a flange", areas.max(), tube_area)


def write_body_stl(design: Design, path: str | Path, *, unit: str = "mm",
                   sides: int = DEFAULT_SIDES, slabs: int = DEFAULT_SLABS) -> Path:
    """Write ``design``'s mesh (:func:`.design_mesh`) to ``path`` (``.stl``, in an existing
    folder) as a binary STL in ``unit``; returns the path. The body file naming it
    (:func:`mesh_body_file_text`) carries the material and the tendons."""
    target = Path(path)
    if target.suffix.lower() != ".stl" or not target.parent.is_dir():
        allowed = "a file name ending in .stl in an existing folder"
        raise InvalidExportError(f"path = {str(path)!r} is out of range; allowed: {allowed}",
                                 parameter="path", value=str(path), allowed=allowed)  # whole
    from trimesh.exchange.stl import export_stl

    data = export_stl(design_mesh(design, unit=unit, sides=sides, slabs=slabs))
    try:
        target.write_bytes(data)
    except OSError as error:
        raise InvalidExportError(f"path = {str(path)!r} cannot be written: {error}",
                                 parameter="path", value=str(path),
                                 allowed="a writable .stl file") from error
    return target


def mesh_body_file_text(design: Design, mesh_file: str, unit: str = "mm") -> str:
    """A body file naming the mesh ``mesh_file`` (lengths in ``unit``; a path relative to the
    body file's folder) with ``design``'s material and tendons, which a mesh does not hold. The
    mesh path takes a linear material only: a non-linear law raises
    :class:`InvalidExportError`."""
    from tdcm_ros.model.body_file import body_file_text

    _unit(unit)
    if not design.material.is_linear:
        raise out_of_range("material.law", design.material.law, "linear (the mesh path "
                           "integrates no material law over a mesh's slices)",
                           error=InvalidExportError)
    lines = body_file_text(design).splitlines()
    carried = lines[1:lines.index("segments:")]  # material and tendons: not tube, not segments
    return "\n".join([*carried, f"mesh: {{file: {json.dumps(mesh_file)}, unit: {unit}}}"]) + "\n"


def band_slabs(design: Design, notch: int, *, sides: int = DEFAULT_SIDES,
               slabs: int = DEFAULT_SLABS) -> tuple[Array, Array, Array]:
    """Notch ``notch`` (0-based; a band or cut) as the mesh has it: the slabs' bounds (m from
    the notch's start; one slab for a rectangular profile, ``slabs`` of equal length for a
    circular or custom one) and each slab's material ``low <= x <= high`` (m; -inf, inf where
    nothing is cut on that side).

    Each slab aims at the design's compliance ``int ds / I`` over it: ``I`` of the annulus of
    the circles in closed form, ``h1`` of eq. 13 in its angle (or the custom function) by
    Gauss-Legendre quadrature, not the solver's code. The half-width ``h`` about ``w_o`` that
    gives it is bisected on the circles, then Newton steps move the edges that cut the tube so
    that the faceted annulus of ``sides`` (the section the mesh reader slices) gives it."""
    _check_args(design, sides, slabs)
    profile = design.notch_profiles()[notch]
    if not isinstance(profile, BAND_PROFILES):
        raise _no_bands(design, notch, profile)
    w_n, w_d, w_o = (float(design.per_notch(name)[notch]) for name in ("w_n", "w_d", "w_o"))
    r_outer, r_inner = design.R_outer, design.r_inner
    if isinstance(profile, RectangularProfile):
        bounds, half = np.array([0.0, w_n]), np.array([0.5 * w_d])
        aim = _band_moment(half, w_o, r_outer, r_inner)
    else:
        bounds = np.linspace(0.0, w_n, slabs + 1)
        aim = np.diff(bounds) / _compliance(profile, bounds, w_n, w_d, w_o, r_outer, r_inner)
        low, high = np.zeros(slabs), np.full(slabs, r_outer + abs(w_o))
        for _ in range(BISECTIONS):
            half = 0.5 * (low + high)
            below = _band_moment(half, w_o, r_outer, r_inner) < aim
            low, high = np.where(below, half, low), np.where(below, high, half)
        half = 0.5 * (low + high)
    rings = _rings_of(design, sides)
    inside = (1.0 - EDGE_CLEARANCE) * r_outer
    cuts_low, cuts_high = w_o - half > -inside, w_o + half < inside
    step = EDGE_CLEARANCE * r_outer
    for _ in range(NEWTON_STEPS):
        low = np.where(cuts_low, w_o - half, -np.inf)
        high = np.where(cuts_high, w_o + half, np.inf)
        error = aim - _centroidal(_faceted_moments(rings, low, high))
        slope = (_band_moment(half + step, w_o, r_outer, r_inner)
                 - _band_moment(half - step, w_o, r_outer, r_inner)) / (2.0 * step)
        half = half + np.where(cuts_low | cuts_high, error / slope, 0.0)
    return (bounds, _edges(np.where(cuts_low, w_o - half, -np.inf), rings),
            _edges(np.where(cuts_high, w_o + half, np.inf), rings))


def _edges(x: Array, rings: list[Array]) -> Array:
    """Band edges ``x`` (m; +-inf: none) kept :data:`EDGE_CLEARANCE` clear of the rings'
    vertices; +-inf where they cut no more than that of the tube."""
    xs = np.unique(np.concatenate([ring[:, 0] for ring in rings]))
    extent, clearance = xs[-1], EDGE_CLEARANCE * xs[-1]
    finite = np.where(np.isfinite(x), x, 0.0)
    nearest = xs[np.argmin(np.abs(finite[:, None] - xs[None, :]), axis=1)]
    away = np.where(finite >= nearest, 1.0, -1.0)
    x = np.where(np.isfinite(x) & (np.abs(finite - nearest) < clearance),
                 nearest + away * clearance, x)
    return np.where(np.abs(x) < extent - clearance, x, np.copysign(np.inf, x))


def _compliance(profile: NotchProfile, bounds: Array, w_n: float, w_d: float, w_o: float,
                r_outer: float, r_inner: float) -> Array:
    """``int ds / I`` (1/m^3) of the true profile over each slab between ``bounds`` (m), in
    pieces between the slabs' bounds and, for eq. 13, where a band edge passes a circle (there
    ``1/I`` has a kink)."""
    if isinstance(profile, CircularProfile):
        # eq. 13 in its angle: sigma = (w_n/2)(1 - cos(pi tau)),
        # h1 = (w_n + w_d)/2 - (w_n/2) sin(pi tau)
        ends = np.arccos(np.clip(1.0 - 2.0 * bounds / w_n, -1.0, 1.0)) / np.pi
        circles = np.array([-r_outer, -r_inner, r_inner, r_outer])
        reach = np.concatenate([circles - w_o, w_o - circles])  # h1 putting an edge on one
        sine = (w_n + w_d - 2.0 * reach) / w_n
        kinks = np.arcsin(sine[(sine > 0.0) & (sine < 1.0)]) / np.pi

        def path(tau: Array) -> tuple[Array, Array]:
            return (0.5 * (w_n + w_d) - 0.5 * w_n * np.sin(np.pi * tau),
                    0.5 * np.pi * w_n * np.sin(np.pi * tau))
    else:
        ends, kinks = bounds / w_n, np.zeros(0)

        def path(tau: Array) -> tuple[Array, Array]:
            return profile.h1(tau, w_n, w_d), np.full(np.shape(tau), w_n)
    pieces = np.unique(np.concatenate([ends, kinks, 1.0 - kinks]))
    nodes, weights = _gauss()
    spans = np.diff(pieces)[:, None]
    h1, rate = path(pieces[:-1, None] + spans * nodes)
    parts = np.sum(weights * spans * rate / _band_moment(h1, w_o, r_outer, r_inner), axis=1)
    slab = np.clip(np.searchsorted(ends, pieces[:-1], side="right") - 1, 0, len(ends) - 2)
    return np.bincount(slab, weights=parts, minlength=len(ends) - 1).astype(np.float64)


@lru_cache(maxsize=1)
def _gauss() -> tuple[Array, Array]:
    """:data:`QUADRATURE_POINTS` Gauss-Legendre nodes and weights on [0, 1] (taken once)."""
    nodes, weights = np.polynomial.legendre.leggauss(QUADRATURE_POINTS)
    return 0.5 * (nodes + 1.0), 0.5 * weights


def _band_moment(half: Array, offset: float, r_outer: float, r_inner: float) -> Array:
    """Second moment (m^4) about its centroid of the annulus of the circles ``r_inner`` and
    ``r_outer`` (m) where ``|x - offset| <= half`` (m): disc-strip integrals in closed form."""
    low, high = offset - half, offset + half
    outer, lumen = _strip(low, high, r_outer), _strip(low, high, r_inner)
    return _centroidal((outer[0] - lumen[0], outer[1] - lumen[1], outer[2] - lumen[2]))


def _strip(low: Array, high: Array, radius: float) -> tuple[Array, Array, Array]:
    """Area (m^2), ``int x dA`` (m^3) and ``int x^2 dA`` (m^4) of the disc of ``radius`` (m)
    about the origin where ``low <= x <= high`` (m); zeros for no disc."""
    def integrals(x: Array) -> tuple[Array, Array, Array]:
        x = np.clip(x, -radius, radius)
        root = np.sqrt(np.maximum(radius * radius - x * x, 0.0))
        angle = np.arcsin(x / radius) if radius > 0.0 else np.zeros_like(x)
        return (x * root + radius**2 * angle, -2.0 / 3.0 * root**3,
                0.25 * x * (2.0 * x * x - radius**2) * root + 0.25 * radius**4 * angle)

    (a0, a1, a2), (b0, b1, b2) = integrals(low), integrals(high)
    return b0 - a0, b1 - a1, b2 - a2


def _faceted_moments(rings: list[Array], low: Array, high: Array
                      ) -> tuple[Array, Array, Array]:
    """Area (m^2), ``int x dA`` (m^3) and ``int x^2 dA`` (m^4) of the region the ``rings``
    ((n, 2) m: the outline counter-clockwise, holes clockwise) bound where ``low <= x <=
    high`` (m; one section per pair; +-inf: no edge). Green's theorem: ``int x^k dA`` is the
    sum over the edges of ``int F dy``, ``F = clip(x, low, high)^(k+1) / (k+1)`` (its
    x-derivative is ``x^k`` inside the band, 0 outside), exact by 2-point Gauss-Legendre on
    each edge's pieces between the band's edges (``F`` a cubic in the edge's parameter
    there)."""
    start = np.concatenate(rings)
    end = np.concatenate([np.roll(ring, -1, axis=0) for ring in rings])
    x0, dx, rise = start[:, 0], end[:, 0] - start[:, 0], end[:, 1] - start[:, 1]
    lo, hi = low[:, None], high[:, None]  # (pairs, 1) against the edges
    with np.errstate(divide="ignore", invalid="ignore"):
        crossings = [np.nan_to_num(np.clip((edge - x0) / dx, 0.0, 1.0)) for edge in (lo, hi)]
    breaks = np.sort(np.stack([np.zeros_like(crossings[0]), *crossings,
                               np.ones_like(crossings[0])], axis=-1), axis=-1)
    pieces = np.diff(breaks, axis=-1)  # (pairs, edges, 3)
    t = breaks[..., :-1, None] + pieces[..., None] * (0.5 + np.array([-0.5, 0.5]) / np.sqrt(3.0))
    x = np.clip(x0[:, None, None] + t * dx[:, None, None], lo[..., None, None],
                hi[..., None, None])
    dy = 0.5 * pieces[..., None] * rise[:, None, None]
    x_dy = x * dy
    area = np.sum(x_dy, axis=(1, 2, 3))
    x_dy *= x
    first = 0.5 * np.sum(x_dy, axis=(1, 2, 3))
    second = np.sum(x_dy * x, axis=(1, 2, 3)) / 3.0
    return area, first, second


def _centroidal(moments: tuple[Array, Array, Array]) -> Array:
    """The second moment about the centroid (m^4) of area, ``int x dA``, ``int x^2 dA``."""
    area, first, second = moments
    return second - first * first / area


def _rings_of(design: Design, sides: int) -> list[Array]:
    """The faceted tube's rings (m): the outline counter-clockwise, the lumen clockwise."""
    lumen = [_ring(design.r_inner, sides)[::-1]] if design.r_inner > 0.0 else []
    return [_ring(design.R_outer, sides), *lumen]


def _ring(radius: float, sides: int) -> Array:
    """The regular ``sides``-gon on the circle of ``radius`` (m), counter-clockwise from a
    vertex at +x, (sides, 2)."""
    angle = 2.0 * np.pi * np.arange(sides) / sides
    return np.c_[radius * np.cos(angle), radius * np.sin(angle)]


def _cross_section(manifold3d: Any, material: Any) -> Any:
    """A shapely (multi)polygon as a manifold3d cross-section: outlines counter-clockwise,
    holes clockwise."""
    from shapely.geometry.polygon import orient

    contours = []
    for part in getattr(material, "geoms", [material]):
        part = orient(part, 1.0)
        contours.append(np.asarray(part.exterior.coords)[:-1])
        contours += [np.asarray(hole.coords)[:-1] for hole in part.interiors]
    return manifold3d.CrossSection(contours)


def _box(x_low: float, z_low: float, x_high: float, z_high: float, length: float
         ) -> tuple[float, float, float, float]:
    """A box of the (x, z) plane, reaching past the body (``z`` in [0, ``length``]) where it
    starts at its base or ends at its tip, so no face of a cut lies on the body's end."""
    return (x_low, -1.0 if z_low <= 0.0 else z_low, x_high,
            length + 1.0 if z_high >= length else z_high)


def _across(manifold3d: Any, boxes: list[tuple[float, float, float, float]]) -> Any:
    """The union of ``boxes`` of the (x, z) plane extruded across the tube (y in [-2, 2])."""
    from shapely.geometry import box
    from shapely.ops import unary_union

    plane = manifold3d.Manifold.extrude(_cross_section(
        manifold3d, unary_union([box(*row) for row in boxes])), 4.0)
    # (x, z, e) -> (x, 2 - e, z): a rotation, exact in floating point
    return plane.transform([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 2.0], [0.0, 1.0, 0.0, 0.0]])


def _no_bands(design: Design, notch: int, profile: NotchProfile) -> InvalidDesignError:
    """The error of notch ``notch``, whose ``profile`` is not a band (nor, where ``design_mesh``
    asks, a polygon), naming it and why."""
    where = f"profile[{notch}]" if isinstance(design.profile, tuple) else "profile"
    if isinstance(profile, PolygonProfile):
        why = "a polygon notch is extruded whole, not cut in band slabs"
    elif isinstance(profile, SectionProfile):
        why = "a section given by its numbers (area, moments, extent) has no shape to export"
    else:
        why = "a mesh's slices give its section's numbers, not a shape to export"
    return InvalidDesignError(f"{where} = {profile.name!r} (notch {notch}): {why}; allowed: "
                              "band, cut, polygon or custom notches", parameter=where,
                              value=profile.name, allowed="circular | rectangular | custom | "
                              "polygon")


def _check_args(design: Design, sides: Any, slabs: Any) -> None:
    """``sides``: an even integer in :data:`SIDES_RANGE`; ``slabs``: an integer in
    :data:`SLABS_RANGE` that leaves every circular or custom notch's slabs at least
    ``MIN_SEGMENT_M`` long."""
    for name, value, (low, high), what in (
            ("sides", sides, SIDES_RANGE, "an even integer"),
            ("slabs", slabs, SLABS_RANGE, "an integer")):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not (
                low <= value <= high) or (name == "sides" and value % 2):
            raise out_of_range(name, value, f"{what} in [{low}, {high}]",
                               error=InvalidExportError)
    varying = [w for w, p in zip(design.per_notch("w_n").tolist(), design.notch_profiles(),
                                 strict=True) if isinstance(p, (CircularProfile, CustomProfile))]
    if varying and min(varying) / slabs < MIN_SEGMENT_M:
        most = int(min(varying) / MIN_SEGMENT_M)
        raise out_of_range("slabs", slabs, f"[1, {most}] (slabs of the narrowest circular or "
                           f"custom notch, {min(varying):g} m, at least {MIN_SEGMENT_M:g} m "
                           "long)",
                           error=InvalidExportError)


def _unit(unit: Any) -> float:
    """Metres per ``unit`` (``m`` or ``mm``)."""
    if unit not in UNITS:
        raise out_of_range("unit", unit, " | ".join(UNITS), error=InvalidExportError)
    return UNITS[unit]


def _manifold3d() -> Any:
    """The manifold3d module, or :class:`InvalidExportError` naming the extra to install."""
    try:
        import manifold3d  # type: ignore[import-not-found]  # ships no py.typed marker
    except ImportError as missing:
        raise InvalidExportError(f"exporting a mesh needs manifold3d: {INSTALL_HINT}",
                                 parameter="manifold3d", value=None,
                                 allowed="manifold3d installed") from missing
    return manifold3d
