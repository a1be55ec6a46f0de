"""Actuation effects of the plant (deadband, load-cell bias and drift) and the twin's ground truth."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.device.plant import Plant, PlantConfig
from tdcm_ros.device.protocol import (
    Heartbeat,
    LineDecoder,
    Mode,
    SetMode,
    SetSetpoint,
    Telemetry,
    encode,
)
from tdcm_ros.device.twin import DeviceTwin


def hold(twin: DeviceTwin, setpoint: float, seconds: float) -> list[Telemetry]:
    """Closed loop at ``setpoint`` N for ``seconds`` with a heartbeat every 0.1 s."""
    twin.receive(encode(SetSetpoint(setpoint)) + encode(SetMode(Mode.TENSION)))
    for _ in range(round(seconds / 0.1)):
        twin.receive(encode(Heartbeat()))
        twin.advance(0.1)
    return [m for m in LineDecoder().feed(twin.take_output()) if isinstance(m, Telemetry)]


def test_deadband_stops_the_actuator_short_of_the_command() -> None:
    plant = Plant(PlantConfig(stroke=0.02, lag=0.01, rate=0.05, deadband=0.001))
    small = 1000 + round(1000 * 0.0008 / 0.02)  # 0.8 mm: inside the deadband
    for _ in range(500):
        plant.step(small, 0.001)
    assert plant.position == 0.0
    for _ in range(2000):
        plant.step(1500, 0.001)  # 10 mm
    assert plant.position == pytest.approx(0.009, abs=1e-9)
    for _ in range(2000):
        plant.step(1000, 0.001)  # back to 0: stops 1 mm above it
    assert plant.position == pytest.approx(0.001, abs=1e-9)


@pytest.mark.parametrize(("name", "value", "allowed"), [
    ("deadband", -0.001, ">= 0"), ("deadband", 0.02, "< stroke"),
    ("bias", float("nan"), "finite"), ("drift", float("inf"), "finite")])
def test_effect_errors_name_the_parameter(name: str, value: float, allowed: str) -> None:
    with pytest.raises(DeviceInputError, match=f"{name} = .*allowed: .*{allowed}"):
        PlantConfig(**{name: value})


@given(bias=st.floats(-5.0, 5.0), drift=st.floats(-0.5, 0.5), seconds=st.floats(0.0, 20.0))
def test_bias_and_drift_shift_the_reading_not_the_tension(bias: float, drift: float,
                                                           seconds: float) -> None:
    plant = Plant(PlantConfig(noise=0.0, bias=bias, drift=drift, slack=0.0))
    steps = round(seconds / 0.01)
    for _ in range(steps):
        plant.step(1200, 0.01)
    clean = Plant(PlantConfig(noise=0.0, slack=0.0))
    for _ in range(steps):
        clean.step(1200, 0.01)
    assert plant.tension == clean.tension
    expected = 8000 + 1000.0 * (plant.tension + bias + drift * plant.time)
    assert plant.read_counts() == round(expected)
    assert plant.time == pytest.approx(steps * 0.01)


def test_closed_loop_holds_the_measured_tension_so_a_bias_offsets_the_truth() -> None:
    """The device regulates what the load cell reads: with +1 N bias the tendon carries 1 N less."""
    biased = DeviceTwin(PlantConfig(noise=0.0, bias=1.0))
    frames = hold(biased, 8.0, 4.0)
    assert frames[-1].mode is Mode.TENSION
    assert frames[-1].tension == pytest.approx(8.0, abs=0.05)
    assert biased.plant.tension == pytest.approx(7.0, abs=0.05)


def test_closed_loop_settles_despite_a_deadband() -> None:
    twin = DeviceTwin(PlantConfig(noise=0.0, deadband=0.0005))
    frames = hold(twin, 12.0, 6.0)
    assert frames[-1].tension == pytest.approx(12.0, abs=0.1)
    assert twin.plant.tension == pytest.approx(12.0, abs=0.1)


def test_twin_records_the_true_tension_at_every_load_cell_sample() -> None:
    twin = DeviceTwin(PlantConfig(noise=0.2, bias=0.5))
    hold(twin, 4.0, 2.0)
    truth = twin.take_truth()
    times = [t for t, _ in truth]
    assert len(truth) == pytest.approx(2.0 / twin.plant.config.sample_period, abs=1)
    gaps = [b - a for a, b in itertools.pairwise(times)]
    assert all(0.0115 < gap < 0.0135 for gap in gaps)  # 12.5 ms on a 1 ms simulation grid
    assert sum(gaps) / len(gaps) == pytest.approx(0.0125, abs=2e-4)
    assert truth[-1][1] == twin.plant.tension  # the true value: no noise, no bias
    assert truth[-1][1] == pytest.approx(3.5, abs=0.2)
    assert twin.take_truth() == []
