"""Marker geometry in ``tdcm_base``: the marker layout, tip deflection and the measured midline.

Contract conventions: markers sit on the body surface at arc lengths ``arc_lengths`` (m),
``radius = R_outer + ball_radius`` off the midline, at ``side_rad`` around the body z axis from
the body x axis (0 = tendon side; the default 180 deg is opposite the tendon). The body bends in
the x-z plane, so the body y axis stays +y.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.spec import check_fields, spec_field, specs_of

Array = NDArray[np.float64]
DEFLECTION_AXES = ("marker", "body")
_OFFSET_PASSES = 4


@dataclass(frozen=True)
class MarkerLayout:
    """Where the markers sit: ``labels`` (last = tip marker), ``arc_lengths`` (m, increasing),
    ``ball_radius`` (m) and ``side_deg`` (deg from the tendon side)."""

    labels: tuple[str, ...] = spec_field(("m1", "m2", "m3"), description=(
        "marker labels, base to tip (the last is the tip marker)"))
    arc_lengths: tuple[float, ...] = spec_field((0.015, 0.033, 0.053), unit="m", low=0.0,
                                                low_open=True, description=(
                                                    "marker arc lengths from the base, increasing"))
    ball_radius: float = spec_field(0.001, unit="m", low=0.0, high=0.05,
                                    description="marker ball radius")
    side_deg: float = spec_field(180.0, unit="deg", low=-360.0, high=360.0, description=(
        "marker side around the body z axis from the tendon side"))

    def __post_init__(self) -> None:
        check_fields(self, MARKER_SPECS, prefix="markers.")
        if len(self.labels) != len(self.arc_lengths):
            raise out_of_range("markers.labels", list(self.labels),
                               f"{len(self.arc_lengths)} distinct labels, one per arc length")
        if any(b <= a for a, b in zip(self.arc_lengths, self.arc_lengths[1:], strict=False)):
            raise out_of_range("markers.arc_lengths", list(self.arc_lengths),
                               "increasing values > 0", unit="m")

    @property
    def side_rad(self) -> float:
        """Marker side around the body z axis (rad)."""
        return math.radians(self.side_deg)

    @property
    def s(self) -> Array:
        """Arc lengths (k,) m."""
        return np.asarray(self.arc_lengths)

    def radius(self, r_outer: float) -> float:
        """Distance of the marker centres from the midline (m) for a body of radius ``r_outer``."""
        return r_outer + self.ball_radius

    def rest_offset(self, r_outer: float) -> Array:
        """Offset (3,) m of every marker from the midline at zero tension (straight body)."""
        r = self.radius(r_outer)
        return np.array([r * math.cos(self.side_rad), r * math.sin(self.side_rad), 0.0])

    def check_within(self, length: float) -> None:
        """Every marker must lie on a body of ``length`` (m)."""
        if self.arc_lengths[-1] > length + 1e-12:
            raise out_of_range("markers.arc_lengths", list(self.arc_lengths),
                               f"values in (0, L = {length:g}] m")


#: Specs of the marker layout, by field name.
MARKER_SPECS = specs_of(MarkerLayout)


def deflection(points_base: ArrayLike, rest_offset: Sequence[float] | Array, axis: str = "marker"
               ) -> Array:
    """Deflection (m) of marker points (..., 3) in ``tdcm_base``.

    ``axis="marker"``: distance from the line parallel to +z through the marker's rest position
    (``rest_offset``), so it is 0 at zero tension. ``axis="body"``: distance from the body axis
    (+z) itself, which is the marker radius at zero tension.
    """
    if axis not in DEFLECTION_AXES:
        raise out_of_range("deflection_axis", axis, " | ".join(DEFLECTION_AXES))
    p = np.asarray(points_base, dtype=float)
    ox, oy = (float(rest_offset[0]), float(rest_offset[1])) if axis == "marker" else (0.0, 0.0)
    return np.hypot(p[..., 0] - ox, p[..., 1] - oy)


def _body_offsets(tangents: Array, radius: float, side_rad: float) -> Array:
    """Marker offsets (k, 3) for midline tangents (k, 3): body x = y x t, body y = +y (planar)."""
    t = tangents / np.linalg.norm(tangents, axis=1, keepdims=True)
    body_x = np.cross(np.array([0.0, 1.0, 0.0]), t)
    body_x /= np.linalg.norm(body_x, axis=1, keepdims=True)
    body_y = np.cross(t, body_x)
    return radius * (math.cos(side_rad) * body_x + math.sin(side_rad) * body_y)


def measured_midline(markers_base: ArrayLike, layout: MarkerLayout, radius: float,
                     stations: Array) -> Array | None:
    """Midline points (m, 3) at arc lengths ``stations`` (m) from markers (k, 3) in ``tdcm_base``.

    A cubic spline in arc length through the base point (clamped along +z, the fixed base) and
    the markers' midline points; each marker is moved back by its offset from the midline, with
    the body frame taken from the spline's tangent there (repeated until it settles). ``None``
    when the tip marker or every other marker is missing (NaN).
    """
    # scipy.interpolate on use only: model_node imports this module for MARKER_SPECS, and the
    # import alone costs it about a second of start-up
    from scipy.interpolate import CubicSpline

    p = np.asarray(markers_base, dtype=float)
    seen = ~np.isnan(p[:, 0])
    if not seen[-1] or seen.sum() < 2:
        return None
    s = np.concatenate([[0.0], layout.s[seen]])
    tangents = np.tile([0.0, 0.0, 1.0], (int(seen.sum()), 1))
    spline = None
    for _ in range(_OFFSET_PASSES):
        mid = p[seen] - _body_offsets(tangents, radius, layout.side_rad)
        spline = CubicSpline(s, np.vstack([np.zeros(3), mid]),
                             bc_type=((1, np.array([0.0, 0.0, 1.0])), "not-a-knot"))
        tangents = spline(s[1:], 1)
    assert spline is not None
    return np.asarray(spline(stations))


def station_distance(a: Array, b: Array) -> float:
    """Mean Euclidean distance (m) between two midlines sampled at the same stations."""
    return float(np.mean(np.linalg.norm(np.asarray(a) - np.asarray(b), axis=1)))
