"""tension_driver in its own process, over a real pty to the device twin running in this process.

The twin (firmware logic on a simulated bench) runs at real time in a thread, so the test can
look inside the device (mode, faults, setpoint, true tension) while the node talks to it through
the pty like it would to a UNO. Every node test runs on the embedded runtime and on rclpy (the
``runtime`` fixture, conftest.py); the probe is the test's peer on that runtime. Timeouts are
generous; the assertions are about behaviour.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.device import constants as c
from tdcm_ros.device.plant import PlantConfig
from tdcm_ros.device.protocol import Fault, Mode
from tdcm_ros.device.twin import DeviceTwin, PtyTwin
from test.nodes.tension_probe import (
    DRIVER,
    REPO,
    Probe,
    driver_params,
    level,
    stamp_ns,
    values,
)
from test.support.processes import stop

Spawn = Callable[..., subprocess.Popen[bytes]]
BAND = 0.25      #: N, settling band around the setpoint
SETTLE = 3.0     #: s from the setpoint message to the last sample outside the band


@pytest.fixture
def twin(tmp_path: Path) -> Iterator[PtyTwin]:
    server = PtyTwin(DeviceTwin(PlantConfig(seed=5)), link=str(tmp_path / "tdcm_port")).start()
    yield server
    server.stop()


@pytest.fixture
def probe(context: Any) -> Probe:
    """The test's peer on the test's runtime (zenoh for tests without ``runtime``)."""
    return Probe(context)


def start_driver(spawn: Spawn, tmp_path: Path, twin: PtyTwin, **params: Any
                 ) -> subprocess.Popen[bytes]:
    """The driver node on the twin's port (unless ``port`` is given), ``/diagnostics`` at 5 Hz."""
    path = driver_params(tmp_path / "driver.yaml", **{"port": twin.port,
                                                      "diagnostics_period_s": 0.2, **params})
    return spawn("tdcm_ros.runtime.run_node", DRIVER, "--name", "tension_driver",
                 "--params", path)


def stop_driver(process: subprocess.Popen[bytes], twin: PtyTwin) -> str:
    """SIGINT the node and wait; checks it released the tendon on the way out (on the device
    and in its log, which on rclpy must still be written before the context shuts down);
    returns what it logged."""
    assert stop(process, 20.0) == 0
    assert process.stderr is not None
    log = process.stderr.read().decode()
    assert "tension_driver]: tendon released, port closed" in log
    deadline = time.monotonic() + 5.0
    while twin.twin.core.mode is not Mode.RELEASE:
        assert time.monotonic() < deadline, f"device still in {twin.twin.core.mode} after close"
        time.sleep(0.02)
    return log


def watch_release(core: Any) -> list[tuple[float, int, int]]:
    """Hook the device's control tick; the list gets ``(host monotonic s, device ms, device ms
    of the host's last byte)`` at the first tick that finds the device released (1 ms ticks)."""
    released: list[tuple[float, int, int]] = []
    tick = core.tick

    def watch(now_ms: int) -> None:
        tick(now_ms)
        if not released and core.mode is Mode.RELEASE:
            released.append((time.monotonic(), now_ms, core.last_rx_ms))

    core.tick = watch
    return released


def test_step_0_to_20_n_settles_within_the_band(runtime, spawn, probe, twin,
                                               tmp_path) -> None:
    """Enters +-0.25 N of 20 N within 3 s of the setpoint message and stays there for 2 s;
    stopping the node releases the held tendon."""
    node = start_driver(spawn, tmp_path, twin)
    probe.connected()
    assert abs(float(probe.state()["tension"])) < 0.1
    t0 = time.time_ns()
    probe.until(lambda: probe.state().get("target") == "20.000", 10.0, "target 20 N",
                action=lambda: probe.setpoint(20.0))
    probe.until(lambda: probe.tension and stamp_ns(probe.tension[-1]) > t0 + 5.5e9, 30.0,
                "5.5 s of telemetry after the step")
    after = [(stamp_ns(m) - t0) / 1e9 for m in probe.tension if stamp_ns(m) > t0]
    forces = [m.wrench.force.z for m in probe.tension if stamp_ns(m) > t0]
    settle = max(t for t, f in zip(after, forces, strict=True) if abs(f - 20.0) > BAND)
    print(f"\nnode 0->20 N step: settled into +-{BAND} N {settle:.2f} s after the setpoint "
          f"message, peak {max(forces):.3f} N, {len(forces)} frames in {after[-1]:.1f} s")
    assert settle <= SETTLE
    assert after[-1] - settle >= 2.0
    assert max(forces) < 20.0 + BAND
    assert all(m.header.frame_id == "tdcm_tendon" for m in probe.tension)
    assert twin.twin.plant.tension == pytest.approx(20.0, abs=BAND)
    assert level(probe.states[-1]) == 0 and probe.state()["faults"] == ""
    stop_driver(node, twin)


def test_setpoint_above_the_maximum_is_clamped_with_a_warning(runtime, spawn, probe, twin,
                                                              tmp_path, params) -> None:
    """With the opt-in to writable safety limits, a lower ``tension_max`` re-clamps the target
    and out-of-range values are still refused."""
    node = start_driver(spawn, tmp_path, twin, tension_max=12.0,
                        **{"safety.limits_writable": True})
    probe.connected()
    probe.until(lambda: probe.state().get("target") == "12.000", 10.0, "target clamped to 12 N",
                action=lambda: probe.setpoint(35.0))
    probe.until(lambda: any(level(d) == 1 and int(values(d)["clamped_setpoints"]) >= 1
                            for d in probe.diagnostics), 10.0, "a WARN on /diagnostics")
    warned = next(d for d in probe.diagnostics if level(d) == 1)
    assert "clamped to 12 N" in values(warned)["last_warning"]
    assert "clamped to [0, 12] N" in warned.message
    probe.until(lambda: abs(twin.twin.plant.tension - 12.0) < BAND, 15.0, "12 N on the tendon")
    assert twin.twin.core.setpoint_mn == 12000

    driver = params("/tension_driver")
    assert driver.set("tension_max", 10.0)["successful"]  # a lower maximum re-clamps the target
    assert driver.get("tension_max") == 10.0
    probe.until(lambda: probe.state().get("target") == "10.000", 10.0, "target re-clamped")
    refused = driver.set("tension_max", 25.0)
    assert not refused["successful"] and "tension_max" in refused["reason"], refused
    refused = driver.set("backoff_max", 0.02)  # below backoff_initial: the node's own check
    assert not refused["successful"] and "backoff_initial" in refused["reason"], refused
    refused = driver.set("port", "/dev/null")
    assert not refused["successful"] and "read-only" in refused["reason"], refused
    assert driver.get("tension_max") == 10.0 and driver.get("port") == twin.port
    log = stop_driver(node, twin)
    assert "setpoint = 35 N is out of range [0, 12] N; clamped to 12 N" in log


def test_safety_limits_are_read_only_at_run_time_by_default(runtime, spawn, probe, twin,
                                                            tmp_path, params) -> None:
    """Without ``safety.limits_writable`` (itself read-only) no peer can raise the force limits;
    the refusal names the parameter and the opt-in. Link parameters stay writable."""
    start_driver(spawn, tmp_path, twin)
    probe.connected()
    driver = params("/tension_driver")
    for name, value in (("tension_max", 22.0), ("setpoint_rate", 1000.0)):
        refused = driver.set(name, value)
        assert not refused["successful"], refused
        assert f"{name} = {value}" in refused["reason"], refused
        assert "safety.limits_writable: true" in refused["reason"], refused
    assert driver.get("tension_max") == 20.0 and driver.get("setpoint_rate") == 40.0
    refused = driver.set("safety.limits_writable", True)
    assert not refused["successful"] and "read-only" in refused["reason"], refused
    assert driver.set("heartbeat_period", 0.05)["successful"]
    probe.until(lambda: probe.state().get("target") == "20.000", 10.0, "target clamped to 20 N",
                action=lambda: probe.setpoint(22.0))


def released_until_armed(probe: Probe, twin: PtyTwin, reason: str) -> None:
    """The driver reports itself disarmed for ``reason``; the device stays released with a slack
    tendon and a setpoint is refused; ``clear_faults`` arms it at 0 N (mode T, tendon still
    slack for 1 s) and only a new setpoint tensions it again."""
    core, plant = twin.twin.core, twin.twin.plant
    probe.until(lambda: probe.state().get("armed") == "false"
                and reason in probe.state().get("disarm_reason", "")
                and probe.state().get("link") == "connected", 20.0, f"disarmed ({reason})")
    probe.until(lambda: core.mode is Mode.RELEASE and plant.tension == 0.0, 5.0, "released")
    probe.setpoint(10.0)  # refused while disarmed
    probe.until(lambda: any(int(values(d)["rejected_setpoints"]) >= 1 for d in probe.diagnostics),
                10.0, "the setpoint refused")
    end = time.monotonic() + 1.5
    while time.monotonic() < end:
        assert core.mode is Mode.RELEASE and plant.tension == 0.0, "re-tensioned while disarmed"
        probe.ctx.spin_for(0.05)
    state = probe.state()
    assert state["target"] == "0.000" and state["armed"] == "false" and level(probe.states[-1]) \
        in (1, 2), state
    probe.until(lambda: probe.state().get("armed") == "true" and probe.state().get("mode")
                == "tension", 10.0, "armed by clear_faults", action=probe.clear_faults)
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        assert core.setpoint_mn == 0 and plant.tension < 0.3, "armed at the old setpoint"
        probe.ctx.spin_for(0.05)
    probe.until(lambda: abs(plant.tension - 4.0) < BAND, 15.0, "4 N after a new setpoint",
                action=lambda: probe.setpoint(4.0))


def test_a_device_rebooted_on_reopen_stays_released_until_armed(runtime, spawn, probe, twin,
                                                                tmp_path) -> None:
    """Holding 10 N, the port closes and the device comes back freshly booted, with no latched
    fault (a UNO resets when its port is opened): the driver never re-tensions it by itself."""
    node = start_driver(spawn, tmp_path, twin)
    probe.connected()
    probe.until(lambda: abs(twin.twin.plant.tension - 10.0) < BAND, 15.0, "10 N on the tendon",
                action=lambda: probe.setpoint(10.0))
    twin.reopen(reboot=True)
    released_until_armed(probe, twin, "link lost")
    log = stop_driver(node, twin)
    assert "device rebooted" in log and "disarmed: link lost" in log


def test_a_frozen_device_stays_released_until_armed_and_is_not_a_reboot(runtime, spawn, probe,
                                                                        twin, tmp_path) -> None:
    """The device's loop hangs for 1 s holding 8 N, then resumes with the host's heartbeats
    buffered (so its own watchdog does not trip): the driver releases it and says it froze."""
    node = start_driver(spawn, tmp_path, twin)
    probe.connected()
    probe.until(lambda: abs(twin.twin.plant.tension - 8.0) < BAND, 15.0, "8 N on the tendon",
                action=lambda: probe.setpoint(8.0))
    with twin.hung():
        probe.ctx.spin_for(1.0)
    released_until_armed(probe, twin, "frozen")
    log = stop_driver(node, twin)
    assert "disarmed: device silent for" in log and "reboot" not in log


def test_estop_releases_at_once_and_stays_released_until_cleared(runtime, spawn, probe, twin,
                                                                 tmp_path) -> None:
    start_driver(spawn, tmp_path, twin)
    probe.connected()
    probe.until(lambda: twin.twin.plant.tension > 7.5, 15.0, "8 N on the tendon",
                action=lambda: probe.setpoint(8.0))
    core = twin.twin.core
    released = watch_release(core)
    sent = time.monotonic()
    probe.until(lambda: bool(released), 10.0, "the device released",
                action=probe.estop)  # repeated until released: one message may precede matching
    latency = released[0][0] - sent
    print(f"\ne-stop: device released {latency:.3f} s after the first message")
    assert latency < 0.5  # at once: not at the next heartbeat or state period
    assert core.faults & Fault.ESTOP and core.pulse_us == c.PULSE_RELEASE_US
    probe.until(lambda: twin.twin.plant.tension == 0.0, 5.0, "a slack tendon")
    probe.until(lambda: "ESTOP" in probe.state().get("faults", ""), 5.0, "ESTOP in device_state")
    assert level(probe.states[-1]) == 2 and probe.state()["target"] == "0.000"
    time.sleep(0.5)
    assert core.mode is Mode.RELEASE  # latched: no automatic recovery
    probe.until(lambda: probe.state().get("faults") == "" and probe.state().get("mode")
                == "tension", 10.0, "faults cleared, holding 0 N again",
                action=probe.clear_faults)


def test_closing_and_reopening_the_pty_triggers_a_reconnect(runtime, spawn, probe, twin,
                                                            tmp_path) -> None:
    """A pulled cable: the link drops, the device's watchdog releases the tendon during the
    outage (backoff 1 s > watchdog 0.5 s), the driver reconnects, reports the latched fault and
    holds again once the fault is cleared."""
    node = start_driver(spawn, tmp_path, twin, backoff_initial=1.0)
    probe.connected()
    old = twin.pty_path
    twin.reopen()
    assert twin.pty_path != old and os.path.realpath(twin.port) == twin.pty_path
    probe.until(lambda: any(values(d)["reconnects"] == "1" for d in probe.diagnostics), 20.0,
                "reconnects = 1 on /diagnostics")
    probe.until(lambda: probe.state().get("link") == "connected"
                and "WATCHDOG" in probe.state().get("faults", ""), 20.0,
                "connected again, with the watchdog release of the outage reported")
    assert twin.twin.core.mode is Mode.RELEASE
    probe.connected(action=probe.clear_faults)
    count = len(probe.tension)
    probe.until(lambda: len(probe.tension) > count + 10, 10.0, "telemetry after the reconnect")
    assert "device link lost" in stop_driver(node, twin)


def test_a_silent_device_is_reported_stale_then_fresh_again(runtime, spawn, probe, twin,
                                                            tmp_path) -> None:
    start_driver(spawn, tmp_path, twin)
    probe.connected()
    with twin.frozen():  # no telemetry for longer than stale_timeout, shorter than link_timeout
        probe.until(lambda: level(probe.states[-1]) == 3, 10.0, "STALE in device_state")
        assert "no telemetry for" in probe.states[-1].message
        probe.until(lambda: any(level(d) == 3 for d in probe.diagnostics), 10.0,
                    "STALE on /diagnostics")
    probe.until(lambda: level(probe.states[-1]) != 3 and probe.state()["link"] == "connected",
                20.0, "fresh telemetry again")


def test_device_releases_within_its_watchdog_when_heartbeats_stop(runtime, spawn, probe, twin,
                                                                  tmp_path) -> None:
    """The driver process is frozen (SIGSTOP: a hung host); the device releases by itself."""
    node = start_driver(spawn, tmp_path, twin)
    probe.connected()
    probe.until(lambda: twin.twin.plant.tension > 7.5, 15.0, "8 N on the tendon",
                action=lambda: probe.setpoint(8.0))
    core = twin.twin.core
    released = watch_release(core)
    os.kill(node.pid, signal.SIGSTOP)
    try:
        probe.until(lambda: bool(released), 10.0, "the watchdog release")
        time.sleep(1.0)
        assert twin.twin.plant.tension == 0.0
    finally:
        os.kill(node.pid, signal.SIGCONT)
    _, at_ms, last_rx_ms = released[0]
    delay = (at_ms - last_rx_ms) / 1000
    print(f"\nwatchdog: released {delay:.3f} s (device time) after the host's last byte")
    assert c.WATCHDOG_MS / 1000 <= delay <= (c.WATCHDOG_MS + c.CONTROL_PERIOD_MS) / 1000
    assert core.faults & Fault.WATCHDOG
    probe.until(lambda: "WATCHDOG" in probe.state().get("faults", ""), 15.0,
                "WATCHDOG reported once the host is back")
    assert core.mode is Mode.RELEASE


def test_schedule_runs_the_staircase_and_reports_done(runtime, spawn, probe, twin,
                                                     tmp_path) -> None:
    """Autostart waits for the device: the port appears only once the probe hears the node
    (on rclpy discovery of a new publisher takes a while), so the probe sees every step."""
    late = tmp_path / "late_port"
    start_driver(spawn, tmp_path, twin, port=str(late), backoff_max=0.5,
                 **{"schedule.levels": [0.0, 4.0, 8.0], "schedule.hold_s": 1.0,
                    "schedule.trials": 2, "schedule.autostart": True})
    probe.until(lambda: probe.state().get("schedule") == "waiting", 30.0,
                "the schedule waiting for the device")
    assert probe.state()["link"] != "connected"
    late.symlink_to(twin.port)
    probe.until(lambda: probe.state().get("schedule_done") == "true", 40.0, "schedule_done")
    targets = [float(values(s)["target"]) for s in probe.states
               if values(s)["schedule"] == "running"]
    steps = [t for i, t in enumerate(targets) if i == 0 or t != targets[i - 1]]
    assert steps == [0.0, 4.0, 8.0, 0.0, 4.0, 8.0]
    assert max(m.wrench.force.z for m in probe.tension) == pytest.approx(8.0, abs=0.3)
    probe.until(lambda: probe.state().get("target") == "0.000", 5.0, "0 N after the schedule")


@pytest.mark.parametrize(("name", "value", "message"), [
    ("tension_max", 30.0, "tension_max = 30.0 is out of range; allowed: [0.001, 22.0]"),
    ("heartbeat_period", 0.3, "heartbeat_period = 0.3 is out of range"),
    ("backoff_max", 0.1, "backoff_max = 0.1 s is out of range; allowed: >= backoff_initial"),
    ("schedule.levels", [0.0, -4.0], "schedule.levels: levels = -4.0 N is out of range"),
    ("schedule.trials", 0, "schedule.trials = 0 is out of range"),
    ("port", " ", "port = ' ' is invalid"),
])
def test_bad_parameters_are_refused_naming_the_parameter(probe, name, value, message) -> None:
    """Node logic, not the runtime: ports built in-process on a ZenohContext, so zenoh only
    (the rclpy path of a bad file is the exit-status test below)."""
    from tdcm_ros.errors import InputError
    from tdcm_ros.nodes.tension_driver import TensionDriverNode

    port = probe.ctx.create_port("bad_driver", overrides={name: value})
    with pytest.raises(InputError) as caught:
        TensionDriverNode(port)
    assert message in str(caught.value)


def test_a_bad_parameter_file_exits_with_status_2(runtime, spawn, tmp_path) -> None:
    node = spawn("tdcm_ros.runtime.run_node", DRIVER, "--params",
                 driver_params(tmp_path / "bad.yaml", tension_max=30.0))
    assert node.wait(30) == 2
    assert node.stderr is not None
    assert "tension_max = 30.0 is out of range" in node.stderr.read().decode()


COMMANDS = ("start_schedule", "clear_faults", "release", "estop")


def test_commands_are_trigger_services_that_answer_why(runtime, spawn, probe, twin,
                                                      tmp_path) -> None:
    """Each command is a ``std_srvs/srv/Trigger`` service whose response says whether it was
    carried out and why not; after an e-stop (a fault) the tendon stays released and the
    schedule is refused until ``clear_faults``; ``release`` slackens and cancels the schedule."""
    start_driver(spawn, tmp_path, twin, **{"schedule.levels": [0.0, 3.0],
                                           "schedule.hold_s": 1.0, "schedule.trials": 5})
    probe.connected()
    core = twin.twin.core
    served = dict(probe.ctx.service_names(2.0))
    for command in COMMANDS:
        assert served.get(f"/tension_driver/{command}") == "std_srvs/srv/Trigger", served
    stopped = probe.call("estop")
    assert stopped.success and "ESTOP latched" in stopped.message, stopped
    probe.until(lambda: core.mode is Mode.RELEASE and bool(core.faults & Fault.ESTOP), 2.0,
                "the device released with ESTOP latched")  # E was sent before the answer
    refused = probe.call("start_schedule")
    assert not refused.success, refused
    assert "refused: disarmed (e-stop)" in refused.message, refused
    assert "call clear_faults first" in refused.message, refused
    time.sleep(0.5)
    assert core.mode is Mode.RELEASE and core.setpoint_mn == 0  # nothing started
    cleared = probe.call("clear_faults")
    assert cleared.success and "armed at target 0 N" in cleared.message, cleared
    probe.until(lambda: core.mode is Mode.TENSION, 10.0, "holding 0 N after clear_faults")
    started = probe.call("start_schedule")
    assert started.success and "schedule started: [0.0, 3.0] N" in started.message, started
    probe.until(lambda: probe.state().get("schedule") == "running"
                and probe.state().get("target") == "3.000", 10.0, "the schedule at 3 N")
    released = probe.call("release")
    assert released.success and "clear_faults" in released.message, released
    probe.until(lambda: core.mode is Mode.RELEASE and probe.state().get("schedule")
                == "cancelled", 10.0, "released, schedule cancelled")


def test_service_cli_lists_and_calls_the_driver_commands(runtime, spawn, probe, twin,
                                                         tmp_path) -> None:
    """``tdcm service list -t`` shows the commands; ``tdcm service call`` prints the response
    and exits 1 when the command was refused, 0 when carried out."""
    start_driver(spawn, tmp_path, twin)
    probe.connected()

    def tdcm(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "service", *args,
                               "--runtime", runtime], check=False, capture_output=True,
                              text=True, timeout=60, cwd=REPO)

    # A listing is a snapshot of what a new process discovered in --timeout; a DDS participant
    # can take longer than that on a loaded machine (CI saw a listing with only its own
    # services), so list again until the driver's services are discovered, as a user would.
    wanted = [f"/tension_driver/{command} [std_srvs/srv/Trigger]" for command in COMMANDS]
    deadline = time.monotonic() + 30.0
    while True:
        listing = tdcm("list", "-t", "--timeout", "2")
        assert listing.returncode == 0, listing.stderr
        if all(line in listing.stdout for line in wanted) or time.monotonic() > deadline:
            break
    for command in COMMANDS:
        assert f"/tension_driver/{command} [std_srvs/srv/Trigger]" in listing.stdout
    estop = tdcm("call", "/tension_driver/estop", "std_srvs/srv/Trigger", "--timeout", "20")
    assert estop.returncode == 0, estop.stderr
    assert "success: true" in estop.stdout and "ESTOP latched" in estop.stdout
    refused = tdcm("call", "/tension_driver/start_schedule", "--timeout", "20")
    assert refused.returncode == 1, refused.stderr
    assert "success: false" in refused.stdout and "call clear_faults first" in refused.stdout
    missing = tdcm("call", "/tension_driver/no_such_command", "--timeout", "1")
    assert missing.returncode != 0 and "no server" in missing.stderr, missing.stderr


def test_diagnostics_report_each_component_and_recover(runtime, spawn, probe, twin,
                                                       tmp_path) -> None:
    """/diagnostics carries one status per hardware component (serial link, load cell,
    actuator; hardware_id the port) whose level follows the component: an e-stop makes the
    actuator ERROR until clear_faults, silence makes the load cell STALE until readings flow,
    a clamped setpoint warns for the window only."""
    start_driver(spawn, tmp_path, twin)
    probe.connected()
    names = ("serial link", "load cell", "actuator")
    probe.until(lambda: all(probe.component_level(n) == 0 for n in names), 10.0,
                "every component OK")
    assert sorted(probe.components[-1]) == sorted(f"tension_driver: {n}" for n in names)
    assert {s.hardware_id for s in probe.components[-1].values()} == {twin.port}
    assert probe.call("estop").success
    probe.until(lambda: probe.component_level("actuator") == 2, 10.0, "actuator ERROR")
    assert "ESTOP" in probe.component("actuator").message
    assert probe.component_level("serial link") == 0 and probe.component_level("load cell") == 0
    probe.until(lambda: probe.component_level("actuator") == 0, 10.0, "actuator OK again",
                action=probe.clear_faults)
    probe.setpoint(30.0)  # above tension_max 20 N: clamped
    probe.until(lambda: probe.component_level("actuator") == 1, 10.0, "actuator WARN")
    assert "setpoint clamped to [0, 20] N" in probe.component("actuator").message
    probe.until(lambda: probe.component_level("actuator") == 0, 10.0,
                "actuator OK once the clamp left the window")
    with twin.frozen():
        probe.until(lambda: probe.component_level("load cell") == 3, 10.0, "load cell STALE")
        assert "no telemetry for" in probe.component("load cell").message
    probe.until(lambda: probe.component_level("load cell") == 0, 20.0, "load cell OK again")
