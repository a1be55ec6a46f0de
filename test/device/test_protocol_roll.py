"""The roll extension of protocol v1 (command R, device frame J) and the core's roll servo:
round trips, strict rejects, the slew limit, the pulse map, and the hold on a trip fault."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.device import constants as c
from tdcm_ros.device.core import TensionCore, pack_calibration
from tdcm_ros.device.errors import DeviceInputError, FrameError
from tdcm_ros.device.protocol import (
    COMMAND_TYPES,
    Ack,
    ClearFaults,
    EStop,
    Fault,
    LineDecoder,
    Mode,
    Nack,
    Reject,
    RollState,
    SetMode,
    SetRoll,
    SetSetpoint,
    Telemetry,
    checksum,
    decode,
    encode,
)

mrad = st.integers(-c.ROLL_MAX_MRAD, c.ROLL_MAX_MRAD)
roll_messages = st.one_of(
    st.builds(lambda v: SetRoll(v / 1000), mrad),
    st.builds(lambda t, g, p, u: RollState(t / 1000, g / 1000, p / 1000, u),
              st.integers(0, 2**32 - 1), mrad, mrad, st.integers(0, 9999)),
    st.just(Ack("R")), st.builds(Nack, st.just("R"), st.sampled_from(Reject)))


def frame(body: str) -> bytes:
    return f"${body}*{checksum(body.encode()):02X}".encode()


@given(roll_messages)
def test_roll_round_trip(message: object) -> None:
    line = encode(message)  # type: ignore[arg-type]
    assert line.endswith(b"\n") and len(line) - 1 <= c.MAX_LINE
    assert decode(line[:-1]) == message
    assert encode(decode(line[:-1])) == line


def test_known_roll_frames() -> None:
    assert encode(SetRoll(-1.571)) == b"$1,R,-1.571*62\n"
    assert encode(RollState(0.04, 0.1, 0.04, 1525)) == b"$1,J,40,0.100,0.040,1525*55\n"


@given(st.integers(c.ROLL_MAX_MRAD + 1, 10**6) | st.integers(-10**6, -c.ROLL_MAX_MRAD - 1))
def test_roll_beyond_the_limit_is_rejected_range(milli: int) -> None:
    text = f"{'-' if milli < 0 else ''}{abs(milli) // 1000}.{abs(milli) % 1000:03d}"
    if abs(milli) >= 1_000_000:
        return  # four integer digits are a syntax error, tested below
    with pytest.raises(FrameError, match=r"roll = .* rad is out of range") as caught:
        decode(frame(f"1,R,{text}"))
    assert caught.value.reason is Reject.RANGE and caught.value.command == "R"


@pytest.mark.parametrize("field", ["1.57", "-0.000", "1e0", "nan", "1000.000", "+0.100", "0.1000"])
def test_roll_syntax_is_strict(field: str) -> None:
    with pytest.raises(FrameError) as caught:
        decode(frame(f"1,R,{field}"))
    assert caught.value.reason is Reject.FIELDS and caught.value.command == "R"


@pytest.mark.parametrize("radians", [1.5715, -1.572, float("nan"), float("inf")])
def test_encode_refuses_a_roll_out_of_range(radians: float) -> None:
    with pytest.raises(DeviceInputError, match=r"roll = .* is out of range; allowed: "
                                               r"\[-1.571, 1.571\]"):
        encode(SetRoll(radians))


def test_roll_is_a_command_and_j_a_device_frame() -> None:
    with pytest.raises(FrameError) as caught:
        decode(encode(RollState(0.02, 0.0, 0.0, 1500))[:-1], accept=COMMAND_TYPES)
    assert caught.value.reason is Reject.TYPE


# --- the core's roll servo ----------------------------------------------------------------

class Bench:
    """A calibrated core at 0 N, its output decoded."""

    def __init__(self) -> None:
        self.out = bytearray()
        self.core = TensionCore(bytearray(pack_calibration(8000, 1_000_000)), cell="T",
                                send=self.out.extend)
        self.now = 0
        self.core.boot(0)
        self.take()  # the banner

    def send(self, *messages: object) -> list[object]:
        for message in messages:
            self.core.receive(encode(message), self.now)  # type: ignore[arg-type]
        return self.take()

    def run(self, ms: int, *, heartbeat: bool = False) -> list[object]:
        for _ in range(ms):
            self.now += 1
            self.core.sample(8000, self.now)
            if heartbeat and self.now % 100 == 0:
                self.core.receive(b"$1,H*79\n", self.now)
            self.core.tick(self.now)
        return self.take()

    def take(self) -> list[object]:
        decoded = LineDecoder().feed(bytes(self.out))
        self.out.clear()
        return decoded


def rolls(messages: list[object]) -> list[RollState]:
    return [m for m in messages if isinstance(m, RollState)]


@given(st.lists(mrad, min_size=1, max_size=6), st.lists(st.integers(1, 15), min_size=6,
                                                       max_size=6))
def test_roll_slews_at_most_the_limit_per_tick_and_reaches_the_target(
        targets: list[int], ticks: list[int]) -> None:
    bench = Bench()
    previous = 0.0
    for target, count in zip(targets, ticks, strict=False):
        assert bench.send(SetRoll(target / 1000)) == [Ack("R")]
        states = rolls(bench.run(20 * count))
        assert len(states) == count and all(s.target == target / 1000 for s in states)
        for state in states:
            assert abs(state.position - previous) <= c.ROLL_SLEW_MRAD_PER_TICK / 1000 + 1e-12
            assert abs(state.position - state.target) <= abs(previous - state.target)
            previous = state.position
    settle = abs(targets[-1] / 1000 - previous) * 1000 // c.ROLL_SLEW_MRAD_PER_TICK + 1
    assert rolls(bench.run(20 * int(settle)))[-1].position == targets[-1] / 1000


def test_no_j_frame_before_the_first_roll_command() -> None:
    bench = Bench()
    out = bench.run(100)
    assert len([m for m in out if isinstance(m, Telemetry)]) == 5 and not rolls(out)
    assert bench.core.roll_pulse_us == c.ROLL_PULSE_CENTER_US


@pytest.mark.parametrize(("radians", "pulse"), [(1.571, 2500), (-1.571, 500), (0.0, 1500),
                                                (0.5, 1818), (-0.5, 1182)])
def test_roll_pulse_map(radians: float, pulse: int) -> None:
    bench = Bench()
    bench.send(SetRoll(radians))
    assert rolls(bench.run(20 * 60))[-1] == RollState(bench.now / 1000, radians, radians, pulse)


@pytest.mark.parametrize("trip", ["watchdog", "estop", "sensor"])
def test_a_trip_fault_holds_the_roll_and_refuses_r_until_c(trip: str) -> None:
    bench = Bench()
    bench.send(SetRoll(1.0), SetSetpoint(2.0), SetMode(Mode.TENSION))
    bench.run(200, heartbeat=True)
    if trip == "estop":
        bench.send(EStop())
    elif trip == "watchdog":
        bench.run(c.WATCHDOG_MS)
    else:
        for _ in range(c.SENSOR_TIMEOUT_MS + 20):  # the load cell goes silent
            bench.now += 1
            bench.core.tick(bench.now)
        bench.take()
    held = bench.core.roll_mrad
    assert 0 < held < 1000
    states = rolls(bench.run(200))
    assert {s.position for s in states} == {held / 1000} and states[-1].target == held / 1000
    assert bench.send(SetRoll(-0.5)) == [Nack("R", Reject.FAULT)]
    assert bench.core.faults & ~Fault.CALIBRATION
    assert bench.send(ClearFaults(), SetRoll(-0.5)) == [Ack("C"), Ack("R")]
    assert rolls(bench.run(20))[-1].position == (held - c.ROLL_SLEW_MRAD_PER_TICK) / 1000


def test_a_calibration_fault_does_not_block_the_roll() -> None:
    out = bytearray()
    core = TensionCore(bytearray(b"\xff" * c.EEPROM_RECORD_SIZE), cell="T", send=out.extend)
    core.boot(0)
    core.receive(encode(SetRoll(0.2)), 0)
    assert core.faults == Fault.CALIBRATION
    assert LineDecoder().feed(bytes(out))[1:] == [Ack("R")]
