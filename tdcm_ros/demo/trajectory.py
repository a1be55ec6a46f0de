"""Tip targets in 3D from a scene's circle (:class:`~tdcm_ros.scenes.CircleTrajectory`).

The circle gives each target's ``(x, y)`` in ``tdcm_base`` (m); its height ``z`` is the one the
estimator's model puts the tip at for the deflection ``hypot(x, y)`` (the inverse model's
``tip_deflection`` target), so each target is a roll ``atan2(y, x)`` plus a bend the model
reaches. The heights come from a table of :data:`TABLE_POINTS` inverse solves over the
circle's deflection range, interpolated linearly: the tip path ``z(d)`` is smooth, and on the
paper's design the interpolation is within 1e-7 m of an exact solve (test/demo/test_trajectory.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model import Design, solve_inverse
from tdcm_ros.scenes import CircleTrajectory

Array = NDArray[np.float64]
#: Inverse solves in the height table (evenly spaced deflections over the circle's range).
TABLE_POINTS = 65


@dataclass(frozen=True)
class TipTrajectory:
    """The circle's targets as 3D points (m, ``tdcm_base``) over time (s from the approach's
    start); build with :func:`tip_trajectory`."""

    circle: CircleTrajectory
    deflections: Array   #: table of tip deflections (m), increasing
    heights: Array       #: the model's tip z (m) at each deflection

    def point(self, t: float) -> tuple[float, float, float]:
        """The target ``(x, y, z)`` (m) at ``t`` (s)."""
        x, y = self.circle.xy(t)
        z = float(np.interp(math.hypot(x, y), self.deflections, self.heights))
        return x, y, z

    def points(self, times: Array) -> Array:
        """Targets (n, 3) m at ``times`` (s)."""
        return np.array([self.point(float(t)) for t in times], dtype=float).reshape(-1, 3)


def tip_trajectory(circle: CircleTrajectory, design: Design, *,
                   tension_max: float) -> TipTrajectory:
    """The 3D targets of ``circle`` on ``design`` (the estimator's); every target must be
    reached within ``[0, tension_max]`` N, else the model's ``UnreachableTargetError`` (which
    names the reachable range) is raised."""
    low, high = circle.deflection_range()
    deflections = np.linspace(low, high, TABLE_POINTS)
    heights = np.empty_like(deflections)
    for index, deflection in enumerate(deflections):
        inverse = solve_inverse(design, tip_deflection=float(deflection),
                                tension_max=tension_max)
        heights[index] = inverse.tip_point_m[1]
    return TipTrajectory(circle, deflections, heights)
