"""Points on the body surface (tdcm_ros.model.surface)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdcm_ros.model import preset, solve, surface_points

DESIGN = preset("paper-experiment")
ARCS = np.array([0.0, 0.015, DESIGN.length])


@pytest.mark.parametrize("tension", [0.0, 15.0])
@pytest.mark.parametrize("side_rad", [0.0, math.pi / 2, math.pi])
def test_surface_points_sit_radius_off_the_midline_square_to_the_tangent(
        tension: float, side_rad: float) -> None:
    result = solve(DESIGN, tension)
    points, quats = surface_points(result, ARCS, 0.004, side_rad)
    midline, _ = result.pose_at(ARCS)
    offsets = points - midline
    assert np.allclose(np.linalg.norm(offsets, axis=1), 0.004)
    theta = 2.0 * np.arctan2(quats[:, 1], quats[:, 3])
    tangents = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=1)
    assert np.allclose(np.einsum("ij,ij->i", offsets, tangents), 0.0, atol=1e-12)


def test_side_zero_is_the_tendon_side_at_rest() -> None:
    points, _ = surface_points(solve(DESIGN, 0.0), ARCS, 0.004, 0.0)
    assert np.allclose(points, np.column_stack([np.full(3, 0.004), np.zeros(3), ARCS]))
