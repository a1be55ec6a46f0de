"""The controller core's targets: resolved with the inverse model, refused with the reason."""

from __future__ import annotations

import math

import pytest

from tdcm_ros.control import (
    DriverLimits,
    PlaneTarget,
    ShapeController,
    TargetRefusedError,
    angle_target,
)
from tdcm_ros.model import MarkerLayout, UnreachableTargetError, preset, solve

DESIGN = preset("paper-experiment")
LIMITS = DriverLimits(tension_max=20.0, setpoint_rate=40.0, roll_max=math.pi / 2, roll_rate=1.0)


def test_the_command_is_the_model_tension_over_the_gain_within_the_limits() -> None:
    controller = ShapeController(DESIGN, MarkerLayout())
    x, _, z = solve(DESIGN, 12.0).tip_position
    resolved = controller.resolve(PlaneTarget(0.3, tip_point=(x, z)), LIMITS)
    assert resolved.model_tension_n == pytest.approx(12.0, abs=1e-6)
    assert resolved.tip_base == pytest.approx((x * math.cos(0.3), x * math.sin(0.3), z))
    controller.estimator.gain = 1.5
    assert controller.goal(LIMITS) == pytest.approx((8.0, 0.3), abs=1e-6)
    controller.estimator.gain = 0.5
    assert controller.goal(LIMITS) == pytest.approx((20.0, 0.3))  # clamped to tension_max


def test_an_angle_target_resolves_to_the_tip_at_that_angle() -> None:
    controller = ShapeController(DESIGN, MarkerLayout())
    angle = solve(DESIGN, 7.0).tip_angle_rad
    assert controller.resolve(angle_target(angle, 0.0), LIMITS).model_tension_n == pytest.approx(
        7.0, abs=1e-6)


def test_a_point_off_the_path_is_refused_with_its_distance_and_the_tolerance() -> None:
    controller = ShapeController(DESIGN, MarkerLayout(), tolerance_m=5e-4)
    x, _, z = solve(DESIGN, 12.0).tip_position
    with pytest.raises(TargetRefusedError, match=r"target distance from the reachable path = "
                       r"0\.00[12]\d* m .*allowed: \[0, 0\.0005\] m"):
        controller.resolve(PlaneTarget(0.0, tip_point=(x, z + 0.002)), LIMITS)
    assert controller.target is None


def test_a_point_past_the_tension_limit_names_the_reachable_range() -> None:
    controller = ShapeController(DESIGN, MarkerLayout())
    x, _, z = solve(DESIGN, 30.0).tip_position
    with pytest.raises(UnreachableTargetError, match="reach"):
        controller.resolve(PlaneTarget(0.0, tip_point=(x, z)), LIMITS)
