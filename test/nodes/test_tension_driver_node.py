"""tension_driver in its own process, over a real pty to the device twin running in this process:
only what a process shows (the serial port end to end, SIGINT, a stopped process, the exit status
of a bad parameter file, the ``tdcm service`` CLI on the graph). The driver's behaviour (safety,
watchdog, reconnect, schedule, commands, diagnostics, the roll) is tested in-process on simulated
time with exact times: test_tension_driver_logic.py.

The twin (firmware logic on a simulated bench) runs at real time in a thread, so the test can
look inside the device (mode, faults, true tension) while the node talks to it through the pty
like it would to a UNO. Every node test runs on the embedded runtime and on rclpy (the
``runtime`` fixture, conftest.py); the probe is the test's peer on that runtime. Tests wait for
exact conditions (:func:`eventually`, generous timeouts) and never assert after a fixed sleep.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
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
)
from test.support.processes import stop
from test.support.waiting import eventually

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
    eventually(lambda: twin.twin.core.mode is Mode.RELEASE, 5.0, "the device released",
               detail=lambda: f"device in {twin.twin.core.mode} after close")
    return log


def watch_release(core: Any) -> list[tuple[int, int]]:
    """Hook the device's tick; the list gets ``(device ms, device ms of the host's last byte)``
    at the first tick that finds the device released (1 ms ticks)."""
    released: list[tuple[int, int]] = []
    tick = core.tick

    def watch(now_ms: int) -> None:
        tick(now_ms)
        if not released and core.mode is Mode.RELEASE:
            released.append((now_ms, core.last_rx_ms))

    core.tick = watch
    return released


def test_a_setpoint_reaches_the_tendon_and_sigint_releases_it(runtime, spawn, probe, twin,
                                                             tmp_path) -> None:
    """End to end over the pty: the node connects, a setpoint published on the graph reaches the
    tendon (telemetry on ``tension``, stamped and framed), SIGINT releases it and says so."""
    node = start_driver(spawn, tmp_path, twin)
    probe.connected()
    assert abs(float(probe.state()["tension"])) < 0.1
    probe.hold(lambda: abs(twin.twin.plant.tension - 8.0) < BAND, 8.0)
    probe.until(lambda: probe.tension and abs(probe.tension[-1].wrench.force.z - 8.0) < BAND,
                10.0, "8 N on the tension topic")
    assert all(m.header.frame_id == "tdcm_tendon" for m in probe.tension)
    stamps = [stamp_ns(m) for m in probe.tension]
    assert stamps == sorted(stamps)
    assert level(probe.states[-1]) == 0 and probe.state()["faults"] == ""
    stop_driver(node, twin)
    eventually(lambda: twin.twin.plant.tension == 0.0, 5.0, "a slack tendon")


def test_joint_commands_drive_the_tendon_and_joint_states_report_it(runtime, spawn, probe,
                                                                  twin, tmp_path) -> None:
    """As a ros2_control topic-based hardware interface drives it, over the wire: a JointState
    on ``joint_commands`` (tendon effort 6 N) reaches the tendon, and ``joint_states`` carries
    the tendon joint with the measured tension as its effort."""
    start_driver(spawn, tmp_path, twin)
    probe.connected()
    port = probe.ctx.create_port("ros2_control")
    commands = port.create_publisher("joint_commands", "sensor_msgs/msg/JointState")
    states: list[Any] = []
    port.create_subscription("joint_states", "sensor_msgs/msg/JointState", states.append)
    command = from_dict("sensor_msgs/msg/JointState", {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "name": ["tendon"],
        "position": [], "velocity": [], "effort": [6.0]})

    def tendon_at_6_n() -> bool:
        tendon = [m for m in states if list(m.name) == ["tendon"]]
        return bool(tendon) and abs(float(tendon[-1].effort[0]) - 6.0) < BAND

    def command_6_n() -> None:  # clearing a watchdog trip first, as Probe.hold does
        if probe.state().get("faults"):
            probe.clear_faults()
        commands.publish(command)

    probe.until(tendon_at_6_n, 20.0, "6 N as the tendon joint's effort on joint_states",
                action=command_6_n)
    probe.until(lambda: abs(twin.twin.plant.tension - 6.0) < BAND, 10.0, "6 N on the tendon")


def test_a_managed_driver_goes_through_its_lifecycle_over_the_wire(runtime, spawn, probe, twin,
                                                                  tmp_path) -> None:
    """``managed: true``, driven through lifecycle_msgs services as ``ros2 lifecycle set`` or a
    lifecycle manager drives it: unconfigured the port stays closed; configure brings the link
    up with the tendon slack; activate arms (a setpoint reaches the tendon); deactivate
    releases it. (That the port stays closed until configure: test_tension_driver_lifecycle.)"""
    start_driver(spawn, tmp_path, twin, managed=True)

    def change(label: str) -> bool:
        request = from_dict("lifecycle_msgs/srv/ChangeState_Request",
                            {"transition": {"id": 0, "label": label}})
        return bool(probe.ctx.call_service("/tension_driver/change_state",
                                           "lifecycle_msgs/srv/ChangeState", request,
                                           timeout=20.0).success)

    def state() -> str:
        return str(probe.ctx.call_service("/tension_driver/get_state",
                                          "lifecycle_msgs/srv/GetState",
                                          timeout=20.0).current_state.label)

    assert state() == "unconfigured"
    assert change("configure") and state() == "inactive"
    probe.connected(mode="release")
    assert change("activate") and state() == "active"
    probe.hold(lambda: abs(twin.twin.plant.tension - 5.0) < BAND, 5.0)
    assert change("deactivate") and state() == "inactive"
    eventually(lambda: twin.twin.core.mode is Mode.RELEASE and twin.twin.plant.tension == 0.0,
               5.0, "the tendon released on deactivate")


def test_device_releases_within_its_watchdog_when_heartbeats_stop(runtime, spawn, probe, twin,
                                                                  tmp_path) -> None:
    """The driver process is frozen (SIGSTOP: a hung host); the device releases by itself."""
    node = start_driver(spawn, tmp_path, twin)
    probe.connected()
    probe.hold(lambda: twin.twin.plant.tension > 7.5, 8.0)
    core = twin.twin.core
    released = watch_release(core)
    os.kill(node.pid, signal.SIGSTOP)
    try:
        probe.until(lambda: bool(released), 10.0, "the watchdog release")
        eventually(lambda: twin.twin.plant.tension == 0.0, 5.0, "a slack tendon")
    finally:
        os.kill(node.pid, signal.SIGCONT)
    at_ms, last_rx_ms = released[0]
    delay = (at_ms - last_rx_ms) / 1000
    print(f"\nwatchdog: released {delay:.3f} s (device time) after the host's last byte")
    assert c.WATCHDOG_MS / 1000 <= delay <= (c.WATCHDOG_MS + c.CONTROL_PERIOD_MS) / 1000
    assert core.faults & Fault.WATCHDOG
    probe.until(lambda: "WATCHDOG" in probe.state().get("faults", ""), 15.0,
                "WATCHDOG reported once the host is back")
    assert core.mode is Mode.RELEASE


def test_a_bad_parameter_file_exits_with_status_2(runtime, spawn, tmp_path) -> None:
    node = spawn("tdcm_ros.runtime.run_node", DRIVER, "--params",
                 driver_params(tmp_path / "bad.yaml", tension_max=30.0))
    assert node.wait(30) == 2
    assert node.stderr is not None
    assert "tension_max = 30.0 is out of range" in node.stderr.read().decode()


COMMANDS = ("start_schedule", "clear_faults", "release", "estop")


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
    listings: list[subprocess.CompletedProcess[str]] = []

    def listed() -> bool:
        listings.append(tdcm("list", "-t", "--timeout", "2"))
        assert listings[-1].returncode == 0, listings[-1].stderr
        return all(line in listings[-1].stdout for line in wanted)

    eventually(listed, 30.0, "the driver's commands in `tdcm service list -t`",
               detail=lambda: listings[-1].stdout)
    estop = tdcm("call", "/tension_driver/estop", "std_srvs/srv/Trigger", "--timeout", "20")
    assert estop.returncode == 0, estop.stderr
    assert "success: true" in estop.stdout and "ESTOP latched" in estop.stdout
    refused = tdcm("call", "/tension_driver/start_schedule", "--timeout", "20")
    assert refused.returncode == 1, refused.stderr
    assert "success: false" in refused.stdout and "call clear_faults first" in refused.stdout
    missing = tdcm("call", "/tension_driver/no_such_command", "--timeout", "1")
    assert missing.returncode != 0 and "no server" in missing.stderr, missing.stderr
