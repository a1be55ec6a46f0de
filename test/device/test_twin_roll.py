"""The twin's roll servo: the plant turns toward the angle its pulse commands at no more than
``roll_speed``; the twin drives it from the firmware core and samples its true angle."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.device import constants as c
from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.device.plant import Plant, PlantConfig
from tdcm_ros.device.protocol import EStop, SetRoll, encode
from tdcm_ros.device.twin import DeviceTwin


@given(st.lists(st.integers(c.ROLL_PULSE_MIN_US, c.ROLL_PULSE_MAX_US), min_size=1, max_size=5),
       st.floats(0.5, 20.0), st.floats(1e-4, 0.02))
def test_plant_roll_is_rate_limited_toward_the_pulse_angle(pulses: list[int], speed: float,
                                                            dt: float) -> None:
    plant = Plant(PlantConfig(), roll_speed=speed)
    for pulse in pulses:
        target = Plant.roll_target(pulse)
        for _ in range(50):
            before = plant.roll
            plant.step(c.PULSE_RELEASE_US, dt, pulse)
            assert abs(plant.roll - before) <= speed * dt + 1e-12
            assert abs(plant.roll - target) <= abs(before - target) + 1e-12
        if 50 * dt * speed >= math.pi:
            assert plant.roll == pytest.approx(target, abs=1e-12)


def test_roll_target_of_the_pulse_ends() -> None:
    assert Plant.roll_target(c.ROLL_PULSE_CENTER_US) == 0.0
    assert Plant.roll_target(c.ROLL_PULSE_MAX_US) == pytest.approx(math.pi / 2, abs=2e-3)
    assert Plant.roll_target(c.ROLL_PULSE_MIN_US) == pytest.approx(-math.pi / 2, abs=2e-3)


@pytest.mark.parametrize("speed", [0.0, -1.0, math.inf, math.nan])
def test_roll_speed_must_be_positive_and_finite(speed: float) -> None:
    with pytest.raises(DeviceInputError, match=r"roll_speed = .* rad/s"):
        Plant(PlantConfig(), roll_speed=speed)


def test_twin_turns_the_servo_at_the_device_slew_and_samples_it() -> None:
    twin = DeviceTwin(PlantConfig(noise=0.0))
    twin.advance(0.1)
    assert {roll for _, roll in twin.take_roll_truth()} == {0.0}
    twin.receive(encode(SetRoll(1.0)))
    twin.advance(1.0)
    samples = twin.take_roll_truth()
    assert len(samples) == 80  # one per load-cell sample (12.5 ms)
    device_rate = c.ROLL_SLEW_MRAD_PER_TICK / c.CONTROL_PERIOD_MS  # rad/s
    step = c.ROLL_SLEW_MRAD_PER_TICK / 1000  # rad: one tick's step, turned within a few ms
    for (t0, roll0), (t1, roll1) in itertools.combinations(samples, 2):
        assert roll1 - roll0 <= device_rate * (t1 - t0) + step + 1e-9
    assert samples[20][1] > 0.5  # it does turn: 0.25 s in
    assert samples[-1][1] == pytest.approx(Plant.roll_target(twin.core.roll_pulse_us), abs=1e-9)
    assert samples[-1][1] == pytest.approx(1.0, abs=2e-3)  # pulse quantisation (1 us)


def test_estop_holds_the_servo_where_it_is() -> None:
    twin = DeviceTwin(PlantConfig(noise=0.0))
    twin.receive(encode(SetRoll(-1.5)))
    twin.advance(0.3)
    twin.receive(encode(EStop()))
    twin.advance(0.05)
    held = twin.plant.roll
    assert -1.0 < held < -0.3
    twin.receive(encode(SetRoll(0.5)))  # refused FAULT
    twin.advance(1.0)
    assert twin.plant.roll == pytest.approx(held, abs=1e-9)
    assert b"$1,N,R,FAULT" in twin.take_output()


def test_a_hung_firmware_holds_the_roll_pulse() -> None:
    twin = DeviceTwin(PlantConfig(noise=0.0))
    twin.receive(encode(SetRoll(1.0)))
    twin.advance(0.2)
    twin.hung = True
    twin.advance(0.5)
    pulse_angle = Plant.roll_target(twin.core.roll_pulse_us)
    assert twin.plant.roll == pytest.approx(pulse_angle, abs=1e-9) and pulse_angle < 0.5
