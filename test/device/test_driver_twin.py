"""The driver core against the device twin on the in-process cable (:class:`Loopback`), in
lock-step simulated time (the twin advances, then the driver steps; no sleeping). The serial
path itself (a pty, the reader thread) is tested in test_transport.py and, with the threaded twin,
in test/nodes/test_tension_driver_node.py."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from tdcm_ros.device import constants as c
from tdcm_ros.device.driver import (
    DriverConfig,
    Level,
    LinkState,
    StepResult,
    TensionDriver,
)
from tdcm_ros.device.loopback import Loopback
from tdcm_ros.device.protocol import Fault, Mode, Telemetry
from tdcm_ros.device.schedule import StepSchedule
from tdcm_ros.device.twin import DeviceTwin

DT = 0.005  # s of simulated time per exchange


class Bench:
    """Twin on the in-process cable plus a driver reading its simulated clock."""

    def __init__(self, tmp_path: Path, *, rx_buffer: int = 64, **config: float) -> None:
        self.twin = DeviceTwin(rx_buffer=rx_buffer)
        self.cable = Loopback(self.twin)
        self.warnings: list[str] = []
        self.stalled = 0.0  # s the whole host stood still (the host clock runs ahead of the twin's)
        self.driver = TensionDriver(DriverConfig(port=str(tmp_path / "tdcm_port"), **config),
                                    clock=lambda: self.twin.time + self.stalled,
                                    open_port=self.cable.open, warn=self.warnings.append)
        self.telemetry: list[Telemetry] = []
        self.last: StepResult | None = None

    def run(self, seconds: float, *, host: bool = True) -> None:
        """Advance ``seconds``; with ``host=False`` the driver is silent (a crashed host)."""
        end = self.twin.time + seconds
        while self.twin.time < end - 1e-9:
            self.cable.pump(DT)
            if host:
                self.last = self.driver.step()
                self.telemetry.extend(self.last.telemetry)

    def run_until_connected(self) -> None:
        for _ in range(1000):  # 5 s
            self.run(DT)
            if self.last is not None and self.last.status.link is LinkState.CONNECTED:
                return
        raise AssertionError(f"no handshake: {self.last}")

    def hold(self, newtons: float) -> None:
        """Connect, enable and hold ``newtons`` on the tendon."""
        self.run_until_connected()
        self.driver.enable()
        self.driver.set_setpoint(newtons)
        self.run(3.0)
        assert self.twin.core.mode is Mode.TENSION
        assert self.twin.plant.tension == pytest.approx(newtons, abs=0.3)

    def assert_released_until_cleared(self, seconds: float, reason: str) -> None:
        """Once connected, the device is released within 0.5 s, then for ``seconds`` stays
        released with a slack tendon while the driver reports itself disarmed for ``reason``; a
        setpoint is refused; ``clear_faults`` arms it at 0 N (mode T, tendon still slack) and only
        a new setpoint tensions it again."""
        self.run_until_connected()
        self.run(0.5)
        end = self.twin.time + seconds
        while self.twin.time < end:
            self.run(0.1)
            assert self.twin.core.mode is Mode.RELEASE, f"re-tensioned at {self.twin.time:.2f} s"
            assert self.twin.plant.tension == 0.0
        status = self.driver.step().status
        assert not status.armed and reason in status.disarm_reason, status
        assert status.target == 0.0 and status.level is Level.WARN or status.level is Level.ERROR
        assert self.driver.set_setpoint(10.0) == 0.0
        assert any("refused: disarmed" in w for w in self.warnings)
        self.run(1.0)
        assert self.twin.core.setpoint_mn == 0 and self.twin.core.mode is Mode.RELEASE
        assert self.driver.clear_faults()
        self.run(1.5)
        assert self.twin.core.mode is Mode.TENSION and self.twin.core.setpoint_mn == 0
        assert self.twin.plant.tension < 0.3  # armed at 0 N, not at the old 10 N
        assert self.driver.step().status.armed
        self.driver.set_setpoint(4.0)
        self.run(3.0)
        assert self.twin.plant.tension == pytest.approx(4.0, abs=0.3)


@pytest.fixture
def bench(tmp_path: Path) -> Iterator[Bench]:
    made = Bench(tmp_path)
    yield made
    made.driver.close()


def test_handshake_reads_the_banner(bench: Bench) -> None:
    bench.run_until_connected()
    status = bench.driver.step().status
    assert status.banner is not None and status.banner.cell == "TWIN"
    assert status.banner.watchdog == c.WATCHDOG_MS / 1000


def test_step_0_to_20_n_settles(bench: Bench) -> None:
    """Band +-0.25 N, entered within 2.0 s of the step command and kept for 2 s."""
    bench.run_until_connected()
    bench.driver.enable()
    bench.run(0.5)
    assert bench.telemetry[-1].mode is Mode.TENSION and abs(bench.telemetry[-1].tension) < 0.1
    start = bench.twin.time
    bench.driver.set_setpoint(20.0)
    bench.run(4.5)
    after = [t for t in bench.telemetry if t.time > start]
    outside = [t.time - start for t in after if abs(t.tension - 20.0) > 0.25]
    settle = max(outside)
    print(f"\n0->20 N step: settled into +-0.25 N after {settle:.2f} s, "
          f"peak {max(t.tension for t in after):.3f} N")
    assert settle <= 2.0
    assert after[-1].time - start - settle >= 2.0
    assert max(t.tension for t in after) < 20.25
    assert bench.last is not None and bench.last.status.level is Level.OK


def test_setpoint_above_max_is_clamped_with_a_warning(bench: Bench) -> None:
    bench.run_until_connected()
    bench.driver.enable()
    assert bench.driver.set_setpoint(35.0) == 20.0
    assert any("setpoint = 35 N" in w and "clamped to 20 N" in w for w in bench.warnings)
    bench.run(3.0)
    assert bench.twin.core.setpoint_mn == 20000
    assert abs(bench.telemetry[-1].tension - 20.0) < 0.25
    assert bench.driver.set_setpoint(-1.0) == 0.0


def test_estop_releases_at_once(bench: Bench) -> None:
    bench.run_until_connected()
    bench.driver.enable()
    bench.driver.set_setpoint(8.0)
    bench.run(2.0)
    assert bench.twin.plant.tension > 7.0
    bench.driver.estop()
    bench.cable.pump(0.001)  # the E frame is handled as soon as it arrives
    assert bench.twin.core.pulse_us == c.PULSE_RELEASE_US
    assert bench.twin.core.mode is Mode.RELEASE
    bench.run(0.3)
    assert bench.twin.plant.tension == 0.0
    assert bench.telemetry[-1].faults & Fault.ESTOP
    assert bench.last is not None and bench.last.status.level is Level.ERROR
    bench.driver.clear_faults()
    bench.run(0.1)
    assert not bench.telemetry[-1].faults
    assert bench.telemetry[-1].mode is Mode.RELEASE  # e-stop also disabled the driver


def test_a_reopened_port_triggers_a_reconnect(bench: Bench) -> None:
    bench.run_until_connected()
    assert bench.cable.opens == 1
    bench.cable.reopen()
    bench.run(0.05)
    assert bench.last is not None and bench.last.status.link is LinkState.DISCONNECTED
    assert any("link lost" in w for w in bench.warnings)
    bench.run_until_connected()
    count = len(bench.telemetry)
    bench.run(0.2)
    assert len(bench.telemetry) > count
    assert bench.last.status.reconnects == 1


def test_silent_host_releases_within_the_watchdog(bench: Bench) -> None:
    """Released at the first control tick at least WATCHDOG_MS after the host's last byte."""
    bench.run_until_connected()
    bench.driver.enable()
    bench.driver.set_setpoint(8.0)
    bench.run(1.5)
    core = bench.twin.core
    assert core.mode is Mode.TENSION
    while core.mode is Mode.TENSION and bench.twin.time < 5.0:
        bench.cable.pump(0.001)  # the device runs on; the host says nothing
    delay = (bench.twin.now_ms - core.last_rx_ms) / 1000
    print(f"\nwatchdog: released {delay:.3f} s after the last host byte")
    assert c.WATCHDOG_MS / 1000 <= delay <= (c.WATCHDOG_MS + c.CONTROL_PERIOD_MS) / 1000
    assert core.faults & Fault.WATCHDOG and core.pulse_us == c.PULSE_RELEASE_US
    bench.run(0.3, host=False)
    assert bench.twin.plant.tension == 0.0


def test_schedule_runs_the_staircase(bench: Bench) -> None:
    bench.run_until_connected()
    bench.driver.enable()
    bench.driver.run_schedule(StepSchedule(hold=1.5, trials=2))
    targets: list[float] = []
    for _ in range(int(18.5 / 0.25)):
        bench.run(0.25)
        assert bench.last is not None
        targets.append(bench.last.status.target)
    assert [t for i, t in enumerate(targets) if i == 0 or t != targets[i - 1]] \
        == [0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 0.0]
    assert not bench.driver.schedule_running


@pytest.mark.parametrize(("reboot", "outage"), [(False, 0.05), (True, 3.0)],
                         ids=["unplug_replug", "reboot_on_open"])
def test_a_reconnect_never_re_tensions(tmp_path: Path, reboot: bool, outage: float) -> None:
    """Holding 10 N, the link drops and the device comes back on the same port: within the
    device watchdog still tensioning (unplug_replug), or after 3 s freshly booted with no latched
    fault (reboot_on_open, as a UNO does when its port is opened). Either way the driver holds
    it released until clear_faults, then at 0 N until a new setpoint."""
    bench = Bench(tmp_path, backoff_initial=outage)
    try:
        bench.hold(10.0)
        bench.run(2.0)  # device clock past the outage: the reboot shows as the clock running back
        bench.cable.reopen(reboot=reboot)
        bench.run(0.05)
        assert bench.last is not None and bench.last.status.link is LinkState.DISCONNECTED
        bench.assert_released_until_cleared(2.0, "link lost")
        assert any("device rebooted" in w for w in bench.warnings) is reboot
    finally:
        bench.driver.close()


def test_a_reboot_on_an_open_port_is_seen_and_never_re_tensions(bench: Bench) -> None:
    """A reset with the port still open (brown-out): the boot banner disarms the driver."""
    bench.hold(10.0)
    bench.twin.reboot()
    bench.run(0.05)
    assert any("device rebooted: it sent a boot banner and its clock went back" in w
               for w in bench.warnings), bench.warnings
    bench.assert_released_until_cleared(2.0, "device rebooted")
    assert bench.driver.step().status.reconnects == 0


@pytest.mark.parametrize(("seconds", "rx_buffer", "reason"),
                         [(1.0, 64, "device silent for 1."), (4.0, 4096, "link lost")],
                         ids=["shorter_than_link_timeout", "longer_with_queued_requests"])
def test_a_freeze_is_not_a_reboot_and_never_re_tensions(tmp_path: Path, seconds: float,
                                                        rx_buffer: int, reason: str) -> None:
    """The device's loop hangs holding 10 N, then resumes with the host's buffered bytes (no
    watchdog trip): the driver releases it, reports a freeze (not a reboot, even when the late
    answers to its banner requests arrive together) and waits for clear_faults."""
    bench = Bench(tmp_path, rx_buffer=rx_buffer)
    try:
        bench.hold(10.0)
        with bench.cable.hung():
            bench.run(seconds)
        bench.run(0.5)
        assert not bench.twin.core.faults  # the device itself saw nothing wrong
        bench.assert_released_until_cleared(2.0, reason)
        assert not any("reboot" in w for w in bench.warnings), bench.warnings
    finally:
        bench.driver.close()


@pytest.mark.parametrize("seconds", [0.6, 1.5])
def test_a_stall_of_the_whole_host_is_not_a_freeze(bench: Bench, seconds: float) -> None:
    """The machine running the driver and a twin stops for ``seconds`` (seen on a loaded CI
    machine: 0.68 s), and the driver steps before the twin has sent the frames of the gap: the
    silence was this host's, so the driver stays armed and holds its setpoint."""
    bench.hold(10.0)
    bench.stalled += seconds
    bench.driver.step()  # the first step after the stall reads nothing yet
    bench.run(1.0)
    status = bench.driver.step().status
    assert status.armed and status.disarms == 0, status
    assert not any("silent" in w for w in bench.warnings), bench.warnings
    assert bench.twin.plant.tension == pytest.approx(10.0, abs=0.3)


def test_a_freeze_is_seen_by_a_host_stepping_slower_than_its_heartbeat(tmp_path: Path) -> None:
    """A host stepping every 0.15 s counts 0.1 s (its heartbeat period) of each gap as silence:
    a 1.5 s freeze of the device still disarms it."""
    bench = Bench(tmp_path)
    try:
        bench.hold(10.0)
        with bench.cable.hung():
            for _ in range(10):
                bench.cable.pump(0.15)
                bench.driver.step()
        bench.run(0.5)
        status = bench.driver.step().status
        assert not status.armed and "device silent for" in status.disarm_reason, status
    finally:
        bench.driver.close()


def assert_still_armed_and_tensions(bench: Bench) -> None:
    """After a handshake the driver did not take for a reboot: armed, no reboot warned of, and
    8 N on request."""
    bench.run(0.5)
    status = bench.driver.step().status
    assert status.armed and not any("reboot" in w for w in bench.warnings), bench.warnings
    bench.driver.enable()
    assert bench.driver.set_setpoint(8.0) == 8.0
    bench.run(3.0)
    assert bench.twin.plant.tension == pytest.approx(8.0, abs=0.3)


def test_a_boot_banner_when_the_port_opens_is_not_a_reboot(bench: Bench) -> None:
    """A UNO resets when its port is opened: its boot banner can arrive after the host flushed
    the port and asked for the banner, so two banners answer one request. Nothing was tensioned
    on this connection yet, so this is the handshake, not a reboot: the driver stays armed."""
    bench.driver.step()  # opens the port, flushes it and asks for the banner
    bench.twin.reboot()  # the reset's boot banner comes before the answer to the request
    bench.run_until_connected()
    assert_still_armed_and_tensions(bench)


def test_a_boot_banner_and_frames_ahead_of_the_answer_are_not_a_reboot(tmp_path: Path) -> None:
    """The race a device twin showed on a loaded machine: the host opened the port, and the
    device's boot banner and first frames reached it before its banner request reached the
    device; the answer then came behind telemetry. The device's clock runs on, so it is the
    handshake, not a reboot: the driver stays armed and tensions on request."""
    bench = Bench(tmp_path)
    held: list[bytes] = []
    links: list[object] = []

    def slow_open(url: str) -> object:  # the host's bytes wait in `held` until released
        link = bench.cable.open(url)
        link.write = held.append  # type: ignore[method-assign]
        links.append(link)
        return link

    bench.driver._open_port = slow_open  # the port opener is the seam under test
    bench.driver.step()  # opens the port and asks for the banner: the request is held
    assert held, "the driver asked for the banner"
    bench.twin.reboot()  # the reset of the open: boot banner, then frames
    bench.run(0.05)
    assert bench.last is not None and bench.last.status.link is LinkState.CONNECTED
    for data in held:  # the request reaches the device now: its answer follows the frames
        bench.twin.receive(data)
    held.clear()
    link = links[-1]
    link.write = lambda data: bench.twin.receive(data)  # type: ignore[attr-defined]
    assert_still_armed_and_tensions(bench)
