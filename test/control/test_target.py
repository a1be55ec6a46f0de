"""Tip targets in tdcm_base resolved to a roll and an in-plane target."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.control import (
    PlaneTarget,
    TargetRefusedError,
    angle_target,
    in_plane,
    point_target,
    rotate_z,
)

ROLL_MAX = math.pi / 2


@given(st.floats(0.0005, 0.02), st.floats(-1.5, 1.5), st.floats(0.03, 0.06))
def test_a_rolled_planar_point_resolves_to_its_roll_and_plane_point(radial: float, roll: float,
                                                                   z: float) -> None:
    point = rotate_z((radial, 0.0, z), roll)
    target = point_target(point, 0.3, ROLL_MAX)
    assert target.roll_rad == pytest.approx(roll, abs=1e-12)
    assert target.tip_point == pytest.approx((radial, z), abs=1e-15)
    assert in_plane(point, target.roll_rad) == pytest.approx((radial, z), abs=1e-15)


def test_a_point_on_the_axis_keeps_the_current_roll() -> None:
    assert point_target((0.0, 0.0, 0.053), 0.7, ROLL_MAX) == PlaneTarget(
        0.7, tip_point=(0.0, 0.053))


def test_a_point_behind_the_body_is_refused_naming_the_roll_range() -> None:
    with pytest.raises(TargetRefusedError, match=r"target roll = 3\.14.* allowed: \[-1\.5708, "
                       r"1\.5708\] rad") as caught:
        point_target((-0.003, 0.0, 0.05), 0.0, ROLL_MAX)
    assert caught.value.parameter == "target roll"


@pytest.mark.parametrize("point", [(math.nan, 0.0, 0.05), (0.0, math.inf, 0.05)])
def test_a_non_finite_point_is_refused(point: tuple[float, float, float]) -> None:
    with pytest.raises(TargetRefusedError, match="target [xy] = (nan|inf)"):
        point_target(point, 0.0, ROLL_MAX)


def test_an_angle_keeps_the_roll_and_a_non_finite_one_is_refused() -> None:
    assert angle_target(0.2, -0.4) == PlaneTarget(-0.4, tip_angle=0.2)
    with pytest.raises(TargetRefusedError, match="target angle = nan"):
        angle_target(math.nan, 0.0)
