"""Marker geometry in ``tdcm_base``: tip deflection and the measured midline.

Contract conventions: markers sit where the model's :class:`~tdcm_ros.model.MarkerLayout` puts
them (``radius = R_outer + ball_radius`` off the midline, at ``side_rad`` around the body z axis
from the body x axis; 0 = tendon side). The body bends in the x-z plane, so the body y axis stays
+y.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model import MarkerLayout

Array = NDArray[np.float64]
DEFLECTION_AXES = ("marker", "body")
_OFFSET_PASSES = 4


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
    # scipy.interpolate on use only: the metrics face imports this module, and the
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
