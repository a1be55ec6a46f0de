"""The threaded twin on a loaded machine: a turn its thread missed is a pause of the simulation.

Issue 24: under CPU load the demo's device tripped WATCHDOG although the driver kept writing.
The twin's thread had not run for 0.36 s (measured in a loaded run; the driver stepped every
<= 0.11 s meanwhile) and then caught the whole gap up in one go, with the host's bytes of the gap
delivered at its start: the simulated device saw the gap without a host byte. Past 0.5 s it
trips. Here the twin's clock is injected and :meth:`PtyTwin.turn` is called by the test (what
its thread does in a loop), so a missed 0.8 s is exact and nothing depends on the scheduler.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Iterator

import pytest

from tdcm_ros.device.core import Fault
from tdcm_ros.device.protocol import (
    Command,
    Heartbeat,
    Mode,
    SetMode,
    SetSetpoint,
    encode,
)
from tdcm_ros.device.twin import MAX_GAP, DeviceTwin, PtyTwin
from test.support.waiting import eventually

EPOCH_NS = 1_800_000_000_000_000_000  #: host time (ns since the epoch) at clock 0


class Host:
    """A host on the twin's pty, and the host clock both share (ms, exact)."""

    def __init__(self, *, max_gap: float = MAX_GAP) -> None:
        self.ms = 0
        self.pty = PtyTwin(DeviceTwin(), clock=self.clock, epoch_ns=self.epoch_ns,
                           max_gap=max_gap)
        self.fd = os.open(self.pty.pty_path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        self.faults: list[tuple[int, Fault]] = []  # (host ms, faults) at each turn with faults

    def clock(self) -> float:
        return self.ms / 1000

    def epoch_ns(self) -> int:
        return EPOCH_NS + self.ms * 1_000_000

    def write(self, *commands: Command) -> None:
        for command in commands:
            os.write(self.fd, encode(command))

    def drain(self) -> None:
        try:
            while os.read(self.fd, 65536):
                pass
        except BlockingIOError:
            pass

    def run(self, ms: int, *, turns: bool = True, heartbeats: bool = True) -> None:
        """``ms`` of host time in 10 ms steps: a heartbeat every 100 ms (as the driver sends),
        a turn of the twin after each step unless ``turns`` is False (its thread not run)."""
        for _ in range(ms // 10):
            self.ms += 10
            if heartbeats and self.ms % 100 == 0:
                self.write(Heartbeat())
            if turns:
                self.turn()

    def turn(self) -> None:
        self.pty.turn()
        self.drain()
        if self.pty.twin.core.faults:
            self.faults.append((self.ms, self.pty.twin.core.faults))

    def close(self) -> None:
        os.close(self.fd)
        self.pty.stop()


@pytest.fixture
def host() -> Iterator[Host]:
    bench = Host()
    yield bench
    bench.close()


def armed(bench: Host) -> None:
    """Tension mode at 2 N for 1 s of host time, the twin turning every 10 ms: no fault."""
    bench.write(SetSetpoint(2.0), SetMode(Mode.TENSION))
    bench.run(1000)
    core = bench.pty.twin.core
    assert core.mode is Mode.TENSION and not bench.faults, bench.faults


def test_a_gap_the_twin_missed_while_the_host_wrote_is_a_pause_not_a_watchdog_trip(
        host: Host) -> None:
    armed(host)
    host.run(800, turns=False)  # the twin's thread is not scheduled; the host writes on
    host.turn()  # 0.8 s after the last turn
    host.run(1000)
    twin = host.pty.twin
    assert twin.core.mode is Mode.TENSION and not host.faults, host.faults
    assert host.pty.pauses == 1
    assert host.pty.paused_s == pytest.approx(0.8 - MAX_GAP)
    # the simulation lags the host by the pause: 2.8 s of host time, 2.1 s simulated
    assert twin.now_ms == host.ms - round((0.8 - MAX_GAP) * 1000) == 2100


def test_caught_up_in_one_go_the_same_gap_trips_the_watchdog() -> None:
    """The artefact itself (the twin before the fix, ``max_gap`` unbounded): the host's bytes
    of the 0.8 s all arrive at the start of the catch-up, the device then runs 0.8 s without one.
    """
    bench = Host(max_gap=math.inf)
    try:
        armed(bench)
        bench.run(800, turns=False)
        bench.turn()
        assert bench.faults and bench.faults[0][1] & Fault.WATCHDOG, bench.faults
        assert bench.pty.twin.core.mode is Mode.RELEASE and bench.pty.pauses == 0
    finally:
        bench.close()


def test_a_host_silent_for_the_watchdog_time_still_trips_the_device(host: Host) -> None:
    """The device's safety is untouched: the twin turning on time, a host that stops writing
    for 0.5 s is released by the watchdog (0.5 s after its last byte, to the 20 ms tick)."""
    armed(host)
    last_byte_ms = host.ms  # the heartbeat at 1.0 s
    host.run(700, heartbeats=False)
    assert host.faults and host.faults[0][1] & Fault.WATCHDOG, host.faults
    assert last_byte_ms + 500 <= host.faults[0][0] <= last_byte_ms + 520
    assert host.pty.twin.core.mode is Mode.RELEASE and host.pty.pauses == 0


def test_truth_keeps_its_host_times_across_a_pause(host: Host) -> None:
    armed(host)
    host.pty.take_truth()
    host.run(100)
    before_ms = host.ms
    host.run(800, turns=False)
    host.turn()  # catches up MAX_GAP, pauses for the rest
    host.run(500)
    truth = host.pty.take_truth()
    stamps = [stamp for stamp, _ in truth]
    period_ns = round(host.pty.twin.plant.config.sample_period * 1e9)
    assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)
    assert EPOCH_NS + host.ms * 1_000_000 - period_ns <= stamps[-1] <= EPOCH_NS + host.ms * 1_000_000
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    # one gap is the pause; every other one is a sample period (to the simulated ms)
    pause_ns = round((0.8 - MAX_GAP) * 1e9)
    assert max(gaps) == pytest.approx(pause_ns + period_ns, abs=1_000_000)
    assert all(abs(gap - period_ns) <= 1_000_000 for gap in gaps if gap != max(gaps))
    paused_at = stamps[gaps.index(max(gaps))]
    assert EPOCH_NS + before_ms * 1_000_000 - period_ns <= paused_at \
        <= EPOCH_NS + before_ms * 1_000_000
    assert host.pty.host_time_ns(host.pty.twin.time) == EPOCH_NS + host.ms * 1_000_000


def test_the_threaded_twin_pauses_through_a_frozen_block(host: Host) -> None:
    """Its own thread, on the injected clock: held for 0.8 s of host time (:meth:`frozen`) while
    the host writes heartbeats, it pauses, then follows the host clock again without a trip."""
    armed(host)
    pty = host.pty
    start_ms = pty.twin.now_ms
    pty.start()  # simulated time now is host time now
    with pty.frozen():
        host.run(800, turns=False)
    resumed_ms = host.ms
    eventually(lambda: pty.twin.now_ms == start_ms + 100, 5.0,
               "the thread's first turn after the block: 0.1 s caught up, the rest paused")
    for _ in range(50):  # 0.5 s more, the thread following the host clock 10 ms at a time
        host.run(10, turns=False)
        due = start_ms + 100 + host.ms - resumed_ms
        eventually(lambda due=due: pty.twin.now_ms == due, 5.0, f"the twin at {due} ms")
    assert pty.pauses == 1 and not pty.twin.core.faults and pty.twin.core.mode is Mode.TENSION
