"""The measured tip from motion capture: the tip marker in ``tdcm_base`` moved by the model's
vector from that marker to the midline tip, rotated by the measured roll.

The markers go from their frame to ``tdcm_base`` through the registration (the
``mocap -> tdcm_base`` transform of ``/tf_static``, as the metrics use). The tip marker (the
layout's last) sits ``radial_offset`` off the midline at arc length ``s_k <= L``; the model at
the current (effective) tension gives the vector from that marker to the midline tip in the
bending plane, which the roll turns about the base z axis. Its error is second order: the
offset (a few mm) times the model's error in the tip direction.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.control.target import rotate_z
from tdcm_ros.model import MarkerLayout, SolveResult, surface_points

Array = NDArray[np.float64]


def marker_to_tip(result: SolveResult, layout: MarkerLayout) -> Array:
    """The model's vector (3,) m from the tip marker to the midline tip, planar (roll 0)."""
    radius = layout.radius(result.design.R_outer)
    marker = surface_points(result, layout.s[-1:], radius, layout.side_rad)[0][0]
    return np.asarray(result.tip_position - marker, dtype=float)


def measured_tip(markers_base: ArrayLike, result: SolveResult, layout: MarkerLayout,
                 roll_rad: float) -> tuple[float, float, float] | None:
    """The midline tip (m, ``tdcm_base``) from marker rows (k, 3) already in ``tdcm_base``
    (NaN rows not visible), the model's solve near the current tension and the measured roll
    (rad); ``None`` if the tip marker is not visible."""
    tip_marker = np.asarray(markers_base, dtype=float)[-1]
    if not np.all(np.isfinite(tip_marker)):
        return None
    offset = rotate_z(tuple(marker_to_tip(result, layout)), roll_rad)
    x, y, z = (float(a + b) for a, b in zip(tip_marker, offset, strict=True))
    return (x, y, z)
