"""The driver's roll: clamp (with a warning), slew at ``roll_rate``, refusal while disarmed or
with a trip fault, the e-stop with the servo holding where it is, and one roll sample per
telemetry tick (lock-step against the twin on the in-process cable, and with a fake port)."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.device import constants as c
from tdcm_ros.device.driver import DriverConfig, LinkState, StepResult, TensionDriver
from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.device.loopback import Loopback
from tdcm_ros.device.protocol import (
    Ack,
    Banner,
    Fault,
    Mode,
    RollState,
    SetRoll,
    Telemetry,
    decode,
    encode,
)
from tdcm_ros.device.twin import DeviceTwin
from test.device.test_driver_unit import FakePort

DT = 0.005  # s of simulated time per exchange


class Bench:
    """Twin on the in-process cable plus a driver on its simulated clock; collects what the
    driver returns."""

    def __init__(self, tmp_path: Path, **config: float) -> None:
        self.twin = DeviceTwin()
        self.cable = Loopback(self.twin)
        self.warnings: list[str] = []
        self.driver = TensionDriver(DriverConfig(port=str(tmp_path / "tdcm_port"), **config),
                                    clock=lambda: self.twin.time, open_port=self.cable.open,
                                    warn=self.warnings.append)
        self.telemetry: list[Telemetry] = []
        self.joints: list[RollState] = []
        self.last: StepResult | None = None

    def run(self, seconds: float) -> None:
        end = self.twin.time + seconds
        while self.twin.time < end - 1e-9:
            self.cable.pump(DT)
            self.last = self.driver.step()
            self.telemetry.extend(self.last.telemetry)
            self.joints.extend(self.last.joints)

    def connect(self) -> None:
        for _ in range(1000):
            self.run(DT)
            if self.last is not None and self.last.status.link is LinkState.CONNECTED:
                self.run(0.1)
                return
        raise AssertionError(f"no handshake: {self.last}")


@pytest.fixture
def bench(tmp_path: Path) -> Bench:
    return Bench(tmp_path)


def test_roll_is_slewed_at_roll_rate_and_reaches_the_target(tmp_path: Path) -> None:
    bench = Bench(tmp_path, roll_rate=0.5)
    bench.connect()
    assert bench.twin.core.roll_engaged is False  # nothing sent before a request
    assert bench.driver.set_roll(0.6) == 0.6
    start = bench.twin.time
    sent: list[tuple[float, int]] = []
    while bench.twin.time - start < 1.6:
        bench.run(DT)
        sent.append((bench.twin.time, bench.twin.core.roll_target_mrad))
    for (t0, a), (t1, b) in itertools.pairwise(sent):
        assert abs(b - a) / 1000 <= 0.5 * (t1 - t0) + 0.5 * 0.02 + 1e-3  # one send per 20 ms
    assert sent[len(sent) // 2][1] / 1000 == pytest.approx(0.4, abs=0.03)  # 0.8 s at 0.5 rad/s
    assert sent[-1][1] == 600 and bench.twin.core.roll_mrad == 600
    assert bench.joints[-1].position == 0.6
    assert bench.twin.plant.roll == pytest.approx(0.6, abs=2e-3)


@settings(max_examples=30)
@given(st.floats(-10.0, 10.0, allow_nan=False), st.floats(0.1, c.ROLL_MAX_MRAD / 1000))
def test_roll_targets_are_clamped_with_a_warning(radians: float, roll_max: float) -> None:
    warnings: list[str] = []
    driver = TensionDriver(DriverConfig(port="none", roll_max=roll_max), clock=lambda: 0.0,
                           warn=warnings.append)
    held = driver.set_roll(radians)
    assert held == min(max(radians, -roll_max), roll_max)
    assert bool(warnings) == (abs(radians) > roll_max)
    if warnings:
        assert f"roll = {radians:g} rad is out of range [{-roll_max:g}, {roll_max:g}] rad" \
            in warnings[0]


def test_a_non_finite_roll_raises_a_typed_error() -> None:
    driver = TensionDriver(DriverConfig(port="none"), clock=lambda: 0.0)
    with pytest.raises(DeviceInputError, match=r"roll = nan rad is out of range"):
        driver.set_roll(math.nan)


@pytest.mark.parametrize(("name", "value"), [("roll_max", 1.6), ("roll_max", -0.1),
                                             ("roll_rate", 2.5), ("roll_rate", 0.0)])
def test_roll_limits_are_range_checked(name: str, value: float) -> None:
    with pytest.raises(DeviceInputError, match=f"{name} = "):
        DriverConfig(**{name: value})


def test_estop_holds_the_servo_and_roll_is_refused_until_clear_faults(bench: Bench) -> None:
    bench.connect()
    bench.driver.set_roll(-1.2)
    bench.run(0.5)
    bench.driver.estop()
    bench.run(0.1)
    held = bench.twin.core.roll_mrad
    assert -1000 < held < -100 and bench.twin.core.roll_target_mrad == held
    true_roll = bench.twin.plant.roll
    assert bench.driver.set_roll(0.5) is None
    assert "roll = 0.5 rad refused: disarmed (e-stop); the roll holds" in bench.warnings[-1]
    bench.run(1.0)
    assert bench.twin.core.roll_mrad == held and bench.twin.plant.roll == true_roll
    assert bench.joints[-1].position == held / 1000
    assert bench.driver.clear_faults()
    bench.run(0.1)
    assert bench.twin.core.roll_mrad == held  # arming alone does not move it
    assert bench.driver.set_roll(0.0) == 0.0
    bench.run(2.0)
    assert bench.twin.core.roll_mrad == 0


def test_a_silent_host_watchdog_holds_the_roll_and_it_is_refused(bench: Bench) -> None:
    bench.connect()
    bench.driver.enable()
    bench.driver.set_setpoint(2.0)
    bench.driver.set_roll(1.0)
    bench.run(0.4)
    bench.twin.receive(b"")  # the host goes silent: only the twin runs
    bench.twin.advance(0.6)
    assert bench.twin.core.faults & Fault.WATCHDOG
    held = bench.twin.core.roll_mrad
    bench.run(0.1)
    assert bench.driver.set_roll(-1.0) is None and "refused" in bench.warnings[-1]
    bench.run(0.5)
    assert bench.twin.core.roll_mrad == held and bench.twin.core.roll_target_mrad == held


def test_one_roll_sample_per_tick_boot_position_until_engaged(bench: Bench) -> None:
    bench.connect()
    assert bench.joints and {j.position for j in bench.joints} == {0.0}
    bench.driver.set_roll(0.3)
    bench.run(1.0)
    times = [j.time for j in bench.joints]
    assert len(times) == len(set(times))  # never two samples for one tick
    covered = {t.time for t in bench.telemetry} - set(times)
    assert len(covered) <= 1  # all ticks but the first after the banner
    assert bench.joints[-1].position == pytest.approx(0.3)


def test_roll_is_forgotten_on_a_device_reboot(bench: Bench) -> None:
    bench.connect()
    bench.driver.set_roll(0.4)
    bench.run(1.0)
    bench.twin.reboot()
    bench.run(0.5)
    assert not bench.driver.armed
    assert bench.joints[-1].position == 0.0 and bench.twin.core.roll_engaged is False


BANNER = encode(Banner("0.1.0", "FAKE", 0.02, 0.5, 22.0, 25.0))
NO_FAULT = Fault(0)


def tick(time: float, faults: Fault = NO_FAULT) -> bytes:
    return encode(Telemetry(time, 8000, 0.0, 1000, Mode.RELEASE, faults))


def fake_driver(replies: bytes) -> tuple[TensionDriver, FakePort, list[str]]:
    port, warnings = FakePort(replies), []
    driver = TensionDriver(DriverConfig(port="fake"), clock=lambda: 100.0,
                           open_port=lambda url: port, warn=warnings.append)
    return driver, port, warnings


def test_a_t_and_its_j_in_different_steps_give_one_sample_each_tick() -> None:
    driver, port, _ = fake_driver(BANNER + tick(1.0))
    assert driver.step().joints == ()  # one T after the banner: engaged or not is unknown
    j1, j2 = RollState(1.0, 0.5, 0.48, 1805), RollState(1.02, 0.5, 0.5, 1818)
    for chunk, expected in [(encode(j1), (j1,)), (tick(1.02), ()), (encode(j2), (j2,)),
                            (tick(1.04) + encode(RollState(1.04, 0.5, 0.5, 1818)),
                             (RollState(1.04, 0.5, 0.5, 1818),))]:
        port.incoming.extend(chunk)
        result = driver.step()
        assert result.joints == expected
    assert result.status.roll == RollState(1.04, 0.5, 0.5, 1818)


def test_two_ts_in_a_row_mean_the_boot_position() -> None:
    driver, port, _ = fake_driver(BANNER + tick(1.0) + tick(1.02))
    assert driver.step().joints == (RollState(1.02, 0.0, 0.0, c.ROLL_PULSE_CENTER_US),)
    port.incoming.extend(tick(1.04) + encode(Ack("R")) + tick(1.06) + encode(
        RollState(1.06, 0.1, 0.04, 1525)))
    assert [j.time for j in driver.step().joints] == [1.04, 1.06]  # no boot sample after A,R


def test_a_trip_fault_on_the_device_drops_the_roll_target_and_refuses_new_ones() -> None:
    driver, port, warnings = fake_driver(BANNER + tick(1.0) + tick(1.02))
    driver.step()
    assert driver.set_roll(0.5) == 0.5
    port.incoming.extend(tick(1.04, Fault.SENSOR))
    status = driver.step().status
    assert status.roll_target is None and status.armed
    assert driver.set_roll(-0.5) is None
    assert "roll = -0.5 rad refused: device fault SENSOR; the roll holds" in warnings[-1]
    sent = [decode(line) for line in bytes(port.written).splitlines()]
    assert not any(isinstance(m, SetRoll) and m.radians < 0 for m in sent)


def test_a_roll_request_waits_for_the_device_roll_and_slews_from_it() -> None:
    """Connected to a device already rolled to 0.8 rad, a request for 1.0 rad starts there."""
    now = [100.0]
    port = FakePort(BANNER + tick(1.0))
    driver = TensionDriver(DriverConfig(port="fake", roll_rate=1.0), clock=lambda: now[0],
                           open_port=lambda url: port)
    driver.step()
    assert driver.set_roll(1.0) == 1.0
    for _ in range(5):
        now[0] += 0.02
        driver.step()
    assert not any(isinstance(m, SetRoll) for m in port.sent())  # the device's roll unknown
    port.incoming.extend(encode(RollState(1.0, 0.8, 0.8, 2009)) + tick(1.02))
    rolls: list[float] = []
    for _ in range(20):
        now[0] += 0.02
        driver.step()
        rolls = [m.radians for m in port.sent() if isinstance(m, SetRoll)]
    assert rolls[0] == pytest.approx(0.8, abs=0.021)  # one 20 ms step of 1 rad/s from 0.8
    assert rolls[-1] == pytest.approx(1.0) and rolls == sorted(rolls)
    sends = len(rolls) - 1  # at most 2 steps (40 ms) apart: never a jump
    assert all(b - a <= 0.04 + 1e-9 for a, b in itertools.pairwise(rolls)) and sends >= 4
