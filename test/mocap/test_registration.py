"""Registration: a random rigid transform is recovered from simulated markers; bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tdcm_ros.mocap.registration import (
    Registration,
    RegistrationError,
    estimate_registration,
)
from tdcm_ros.model import preset, solve, surface_points

DESIGN = preset("paper-experiment")
ARCS = np.array([0.015, 0.033, 0.053])
RADIUS = DESIGN.R_outer + 0.001
SIDE = math.pi


def markers_base(tension: float, side: float = SIDE) -> np.ndarray:
    return surface_points(solve(DESIGN, tension), ARCS, RADIUS, side)[0]


ZERO_BASE = markers_base(0.0)
BENT_BASE = markers_base(20.0)


@settings(max_examples=40)
@given(quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
           lambda q: np.linalg.norm(q) > 0.1),
       shift=st.lists(st.floats(-2, 2), min_size=3, max_size=3))
def test_random_rigid_transform_is_recovered(quat: list[float], shift: list[float]) -> None:
    truth = Registration(tuple(shift), tuple(quat))
    estimate = estimate_registration(truth.to_mocap(ZERO_BASE), ARCS, radius=RADIUS,
                                     side_rad=SIDE, bent_markers=truth.to_mocap(BENT_BASE))
    assert estimate.method == "estimated"
    assert estimate.residual_m < 1e-9
    np.testing.assert_allclose(estimate.rotation, truth.rotation, atol=1e-9)
    np.testing.assert_allclose(estimate.translation, truth.translation, atol=1e-9)
    np.testing.assert_allclose(estimate.to_base(truth.to_mocap(BENT_BASE)), BENT_BASE, atol=1e-9)


def test_side_off_the_bending_plane_and_an_occluded_marker() -> None:
    side = math.radians(120.0)
    truth = Registration((0.1, -0.3, 0.7), tuple(Rotation.from_euler("xyz", [10, 50, -20],
                                                                     degrees=True).as_quat()))
    zero = truth.to_mocap(markers_base(0.0, side))
    zero[1] = np.nan
    estimate = estimate_registration(zero, ARCS, radius=RADIUS, side_rad=side,
                                     bent_markers=truth.to_mocap(markers_base(16.0, side)))
    np.testing.assert_allclose(estimate.translation, truth.translation, atol=1e-9)
    np.testing.assert_allclose(estimate.rotation, truth.rotation, atol=1e-9)


def test_x_hint_fixes_the_roll_without_a_bent_frame() -> None:
    truth = Registration((0.0, 0.2, 0.0), tuple(Rotation.from_euler("z", 30, degrees=True)
                                                .as_quat()))
    hint = truth.rotation[:, 0] + 0.3 * truth.rotation[:, 2]  # +x plus some axial component
    estimate = estimate_registration(truth.to_mocap(ZERO_BASE), ARCS, radius=RADIUS,
                                     side_rad=SIDE, x_hint=hint)
    np.testing.assert_allclose(estimate.rotation, truth.rotation, atol=1e-9)


def test_noise_gives_a_residual_and_a_close_estimate() -> None:
    rng = np.random.default_rng(3)
    truth = Registration((0.5, 0.5, 0.1), (0.0, 0.0, 0.0, 1.0))
    noise = rng.normal(0.0, 5e-5, size=(2, 3, 3))
    estimate = estimate_registration(truth.to_mocap(ZERO_BASE) + noise[0], ARCS, radius=RADIUS,
                                     side_rad=SIDE, bent_markers=truth.to_mocap(BENT_BASE)
                                     + noise[1])
    assert 0.0 < estimate.residual_m < 2e-4
    np.testing.assert_allclose(estimate.translation, truth.translation, atol=5e-4)


def test_collinear_markers_alone_cannot_fix_the_roll() -> None:
    with pytest.raises(RegistrationError, match="roll"):
        estimate_registration(ZERO_BASE, ARCS, radius=RADIUS, side_rad=SIDE)


def test_too_small_a_bend_is_rejected() -> None:
    with pytest.raises(RegistrationError, match="min_bend_m"):
        estimate_registration(ZERO_BASE, ARCS, radius=RADIUS, side_rad=SIDE,
                              bent_markers=markers_base(0.05))


def test_one_visible_marker_is_rejected() -> None:
    zero = ZERO_BASE.copy()
    zero[:2] = np.nan
    with pytest.raises(RegistrationError, match="at least 2"):
        estimate_registration(zero, ARCS, radius=RADIUS, side_rad=SIDE, bent_markers=BENT_BASE)


def test_invalid_transform_values_are_rejected() -> None:
    with pytest.raises(RegistrationError, match="quaternion"):
        Registration((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))
    with pytest.raises(RegistrationError, match="translation"):
        Registration((0.0, float("nan"), 0.0), (0.0, 0.0, 0.0, 1.0))
