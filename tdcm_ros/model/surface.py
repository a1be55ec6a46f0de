"""Points on the body surface: markers (or any point) a fixed distance off the midline.

Frame ``tdcm_base`` (see doc/explanation/frames.md), SI units. A point sits ``radius`` (m) from the midline
at ``side_rad`` (rad) around the body z axis, measured from the body x axis (0 = tendon side).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.result import SolveResult

Array = NDArray[np.float64]


def offset_points(positions: Array, quats: Array, radius: float, side_rad: float) -> Array:
    """Points ``radius`` (m) off midline poses (positions (k, 3) m, quaternions (k, 4) xyzw)
    at ``side_rad`` (rad) around the body z axis; bending is in the x-z plane."""
    theta = 2.0 * np.arctan2(quats[:, 1], quats[:, 3])
    body_x = np.stack([np.cos(theta), np.zeros_like(theta), -np.sin(theta)], axis=1)
    body_y = np.array([0.0, 1.0, 0.0])
    return positions + radius * (np.cos(side_rad) * body_x + np.sin(side_rad) * body_y)


def surface_points(result: SolveResult, s: Array, radius: float, side_rad: float
                   ) -> tuple[Array, Array]:
    """Points at arc lengths ``s`` (m), ``radius`` (m) off the midline at angle ``side_rad``
    around the body z axis from the body x axis (0 = tendon side); with their orientations."""
    positions, quats = result.pose_at(s)
    return offset_points(positions, quats, radius, side_rad), quats
