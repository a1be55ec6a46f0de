"""The driver's limits and the slew toward a command."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.control import DriverLimits, slew
from tdcm_ros.errors import InputError


def test_limits_come_from_the_driver_parameters_and_must_be_positive() -> None:
    values = {"tension_max": 20, "setpoint_rate": 40.0, "roll_max": 1.5, "roll_rate": 1.0}
    assert DriverLimits.from_values(values) == DriverLimits(20.0, 40.0, 1.5, 1.0)
    with pytest.raises(InputError, match=r"driver roll_rate = nan .*allowed: \(0, inf\) rad/s"):
        DriverLimits(20.0, 40.0, 1.5, math.nan)


@given(st.floats(-50, 50), st.floats(-50, 50), st.floats(0.1, 100), st.floats(0.0, 1.0))
def test_a_slew_moves_toward_the_goal_no_faster_than_the_rate(current: float, goal: float,
                                                              rate: float, dt: float) -> None:
    step = slew(current, goal, rate, dt)
    assert abs(step - current) <= rate * dt + 1e-12
    assert abs(goal - step) <= abs(goal - current) + 1e-12
    if abs(goal - current) <= rate * dt:
        assert step == pytest.approx(goal)
