"""Driver core with fake transports and a fake clock: handshake errors, backoff, staleness."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.device.driver import DriverConfig, Level, LinkState, TensionDriver
from tdcm_ros.device.errors import DeviceError, PortError, ProtocolVersionError
from tdcm_ros.device.protocol import (
    Banner,
    EStop,
    Fault,
    Info,
    Mode,
    SetMode,
    Telemetry,
    decode,
    encode,
)
from tdcm_ros.device.schedule import StepSchedule
from tdcm_ros.errors import InputError

BANNER = Banner("0.1.0", "FAKE", 0.02, 0.5, 22.0, 25.0)


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class FakePort:
    """Records what the driver writes; replies with queued bytes."""

    def __init__(self, replies: bytes = b"") -> None:
        self.incoming = bytearray(replies)
        self.written = bytearray()
        self.closed = False

    def read(self) -> bytes:
        data = bytes(self.incoming)
        self.incoming.clear()
        return data

    def write(self, data: bytes) -> None:
        self.written.extend(data)

    def close(self) -> None:
        self.closed = True

    def sent(self) -> list[object]:
        return [decode(line) for line in bytes(self.written).splitlines()]


def make(replies: bytes = b"", warnings: list[str] | None = None,
         **config: float) -> tuple[TensionDriver, FakePort, Clock]:
    port, clock = FakePort(replies), Clock()
    driver = TensionDriver(DriverConfig(port="fake", **config), clock=clock,
                           open_port=lambda url: port,
                           warn=(lambda text: None) if warnings is None else warnings.append)
    return driver, port, clock


def test_version_mismatch_raises_a_typed_error() -> None:
    line = encode(BANNER, version=2)
    driver, port, _ = make(line)
    with pytest.raises(ProtocolVersionError, match=r"protocol_version = 2 .*allowed: 1") as caught:
        driver.step()
    assert isinstance(caught.value, InputError) and isinstance(caught.value, DeviceError)
    assert port.closed


def test_handshake_asks_for_the_banner_then_times_out_and_backs_off() -> None:
    driver, port, clock = make(handshake_timeout=1.0, backoff_initial=0.5)
    driver.step()
    assert port.sent() == [Info()]
    clock.now += 0.6
    driver.step()
    assert port.sent() == [Info(), Info()]
    clock.now += 0.5
    status = driver.step().status
    assert status.link is LinkState.DISCONNECTED and "no banner" in status.message
    assert port.closed


def test_backoff_doubles_up_to_the_maximum() -> None:
    attempts: list[float] = []
    clock = Clock()

    def refuse(url: str) -> FakePort:
        attempts.append(clock.now)
        raise PortError(f"port {url!r}: cannot open")

    driver = TensionDriver(DriverConfig(port="gone", backoff_initial=0.5, backoff_max=4.0),
                           clock=clock, open_port=refuse)
    for _ in range(3000):
        driver.step()
        clock.now += 0.01
    gaps = [round(b - a, 2) for a, b in itertools.pairwise(attempts)]
    assert gaps[:5] == [0.5, 1.0, 2.0, 4.0, 4.0]
    assert driver.step().status.level is Level.ERROR


def test_stale_then_lost_link() -> None:
    telemetry = encode(Telemetry(1.0, 8000, 0.0, 1000, Mode.RELEASE, Fault(0)))
    driver, port, clock = make(encode(BANNER) + telemetry, stale_timeout=0.25, link_timeout=2.0)
    result = driver.step()
    assert result.status.link is LinkState.CONNECTED and len(result.telemetry) == 1
    assert result.status.level is Level.OK
    clock.now += 0.3
    assert driver.step().status.level is Level.STALE
    clock.now += 1.8
    status = driver.step().status
    assert status.link is LinkState.DISCONNECTED and port.closed
    assert status.reconnects == 1


def test_estop_and_enable_send_the_right_commands() -> None:
    telemetry = encode(Telemetry(1.0, 8000, 0.0, 1000, Mode.RELEASE, Fault(0)))
    driver, port, clock = make(encode(BANNER) + telemetry)
    driver.enable()
    driver.step()
    clock.now += 0.3
    driver.step()
    assert SetMode(Mode.TENSION) in port.sent()
    driver.estop()
    assert port.sent()[-1] == EStop()
    assert driver.step().status.target == 0.0


def test_setpoint_is_rate_limited() -> None:
    driver, port, clock = make(encode(BANNER), setpoint_rate=10.0)
    driver.step()
    driver.set_setpoint(20.0)
    clock.now += 0.5
    assert driver.step().status.setpoint == pytest.approx(5.0)
    clock.now += 2.0
    port.incoming.extend(encode(Telemetry(3.0, 8000, 0.0, 1000, Mode.RELEASE, Fault(0))))
    assert driver.step().status.setpoint == pytest.approx(20.0)


@pytest.mark.parametrize(("name", "value"), [("tension_max", 30.0), ("heartbeat_period", 0.3),
                                             ("stale_timeout", 0.0), ("backoff_max", 0.1)])
def test_config_errors_name_the_parameter(name: str, value: float) -> None:
    with pytest.raises(InputError, match=f"{name} = {value}"):
        DriverConfig(**{name: value})


def test_non_finite_setpoint_is_refused() -> None:
    driver, _, _ = make()
    with pytest.raises(InputError, match="setpoint = nan"):
        driver.set_setpoint(float("nan"))


def test_schedule_levels() -> None:
    schedule = StepSchedule(hold=2.0, trials=2)
    assert schedule.duration == 24.0
    assert [schedule.setpoint(t) for t in (0, 1.9, 2.0, 10.5, 12.0, 23.9)] \
        == [0.0, 0.0, 4.0, 20.0, 0.0, 20.0]
    assert schedule.setpoint(24.0) is None
    with pytest.raises(InputError, match="trials = 0"):
        StepSchedule(trials=0)
    with pytest.raises(InputError, match="levels = -1"):
        StepSchedule(levels=(0.0, -1.0))


def test_rejected_device_lines_are_counted_and_warned_about_once_a_second() -> None:
    telemetry = encode(Telemetry(1.0, 8000, 0.0, 1000, Mode.RELEASE, Fault(0)))
    warnings: list[str] = []
    driver, port, clock = make(encode(BANNER) + telemetry, warnings)
    driver.step()
    for _ in range(30):
        port.incoming.extend(b"$1,T,garbage*00\n" + telemetry)
        clock.now += 0.1
        status = driver.step().status
    assert status.rejected_lines == 30 and status.link is LinkState.CONNECTED
    rejected = [w for w in warnings if "line(s) from the device" in w]
    assert 3 <= len(rejected) <= 4, rejected  # 3 s of garbage, at most one warning per second
    assert "rejected 1 line(s) from the device (1 in all)" in rejected[0] and "CKSUM" in rejected[0]
    assert sum(int(w.split()[1]) for w in rejected) <= 30


@settings(max_examples=300)
@given(st.lists(st.binary(max_size=120), max_size=10))
def test_no_device_bytes_make_the_driver_raise(chunks: list[bytes]) -> None:
    """Whatever the device sends, a step returns a result or raises the typed version error."""
    driver, port, clock = make(encode(BANNER))
    driver.step()
    for chunk in chunks:
        port.incoming.extend(chunk)
        clock.now += 0.05
        try:
            result = driver.step()
        except ProtocolVersionError:
            continue
        assert result.status.rejected_lines >= 0
