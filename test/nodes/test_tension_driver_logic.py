"""tension_driver's behaviour in-process and on simulated time: the node on a MemoryPort, joined by
an in-process cable (device.loopback) to the device twin, advanced in 1 ms lock steps
(test/nodes/driver_bench.py). Times are exact: the device's ms tick, the host's 5 ms step. The
same node in its own process over a real pty, on both runtimes: test_tension_driver_node.py."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.device import constants as c
from tdcm_ros.device.protocol import Fault, Mode
from tdcm_ros.errors import InputError
from tdcm_ros.nodes.tension_driver import TensionDriverNode
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.throttle import PERIOD_S
from test.nodes.driver_bench import COMPONENTS, URL, DriverBench
from test.nodes.tension_probe import level, stamp_ns, values

BAND = 0.25      #: N, settling band around the setpoint
SETTLE = 3.0     #: s from the setpoint message to the last sample outside the band
COMMANDS = ("start_schedule", "clear_faults", "release", "estop")


@pytest.fixture
def bench() -> Iterator[DriverBench]:
    made = DriverBench()
    yield made
    made.close()


@pytest.fixture
def make() -> Iterator[Callable[..., DriverBench]]:
    """Benches with parameter overrides, closed after the test."""
    made: list[DriverBench] = []

    def build(**overrides: object) -> DriverBench:
        made.append(DriverBench(dict(overrides)))
        return made[-1]

    yield build
    for bench in made:
        bench.close()


def test_step_0_to_20_n_settles_within_the_band_and_closing_releases(bench) -> None:
    """Enters +-0.25 N of 20 N within 3 s of the setpoint message and stays there for 2 s;
    closing the node releases the held tendon."""
    bench.connected()
    assert abs(float(bench.state()["tension"])) < 0.1
    t0 = bench.port.clock_ns
    bench.setpoint(20.0)
    bench.advance(0.005)  # the status is the driver's at its last step
    assert bench.state()["target"] == "20.000"
    bench.advance(5.5)
    frames = [m for m in bench.port.messages("tension") if stamp_ns(m) > t0]
    after = [(stamp_ns(m) - t0) / 1e9 for m in frames]
    forces = [m.wrench.force.z for m in frames]
    settle = max(t for t, f in zip(after, forces, strict=True) if abs(f - 20.0) > BAND)
    assert settle <= SETTLE
    assert after[-1] - settle >= 2.0
    assert max(forces) < 20.0 + BAND
    assert len(frames) == 275  # every 20 ms device frame of the 5.5 s, none lost
    assert all(m.header.frame_id == "tdcm_tendon" for m in bench.port.messages("tension"))
    assert bench.twin.plant.tension == pytest.approx(20.0, abs=BAND)
    assert level(bench.states()[-1]) == 0 and values(bench.states()[-1])["faults"] == ""
    bench.node.close()
    assert bench.twin.core.mode is Mode.RELEASE  # the R was handed over before the port closed
    assert "tendon released, port closed" in bench.log.text


def test_frames_arriving_in_a_burst_are_stamped_in_order(bench) -> None:
    """A burst (0.2 s of device frames read 5 ms after the last read: a device or serial line
    that caught up) must not be stamped before frames already published: seen on rclpy under
    load as a tension stamp 52 ms before its predecessor."""
    bench.connected()
    bench.roll(0.3)
    bench.advance(0.5)
    before = len(bench.port.messages("tension"))
    bench.twin.advance(0.2)  # the device runs 0.2 s while no host time passes
    bench.advance(0.005)
    for topic in ("tension", "joint_states"):
        stamps = [stamp_ns(m) for m in bench.port.messages(topic)]
        assert stamps == sorted(stamps), topic
    assert len(bench.port.messages("tension")) - before == 10  # every frame of the burst kept


def test_a_burst_read_in_two_parts_keeps_the_times_its_frames_were_taken(bench) -> None:
    """A device that stalled for 0.4 s (a device twin not scheduled) catches up and its frames
    reach the driver in two reads: each keeps the host time it was taken at, every 20 ms, as
    before the stall. Stamped relative to each read's newest frame, the first part came 0.2 s
    late and the second collapsed onto one stamp (57 equal stamps lost a hold in a demo)."""
    bench.connected()
    bench.advance(0.5)
    before = len(bench.port.messages("tension"))
    bench.advance(0.4, device=False)          # the device stalls; the host goes on
    for _ in range(2):                        # it catches up, read in two parts
        bench.twin.advance(0.2)
        bench.loop.tick()
        bench.advance(0.005, device=False)
    bench.advance(0.3)
    stamps = [stamp_ns(m) for m in bench.port.messages("tension")[before - 5:]]
    assert len(stamps) == 5 + 20 + 15          # before, the burst (0.4 s), after (0.3 s)
    assert all(abs(b - a - 20_000_000) <= 1_000_000 for a, b in itertools.pairwise(stamps)), \
        [(b - a) / 1e6 for a, b in itertools.pairwise(stamps)]


def test_a_flood_of_clamped_setpoints_is_counted_whole_and_logged_once_a_period(make) -> None:
    """10,000 out-of-range setpoints in 1 s (49,694 log lines in 10 s before): every one is
    counted, one warning is logged at once and the next one after the period, with the number
    left out; another kind of warning is not held back by the flood."""
    bench = make(tension_max=12.0)
    bench.connected()
    lines = len(bench.log.lines)
    for i in range(10_000):
        bench.setpoint(30.0 + i * 1e-3)
        if i % 10 == 9:
            bench.advance(0.001)
    bench.setpoint(math.nan)
    flood = bench.log.lines[lines:]
    assert sum("out of range" in line for line in flood) == 1
    assert sum("is not finite" in line for line in flood) == 1
    bench.advance(PERIOD_S)
    bench.setpoint(40.0)
    assert "(9999 more like it in the last" in bench.log.lines[-1]
    bench.advance(0.2)
    assert int(values(bench.component("actuator"))["clamped_setpoints"]) == 10_001


def test_setpoint_above_the_maximum_is_clamped_and_a_lower_maximum_reclamps(make) -> None:
    """With the opt-in to writable safety limits, a lower ``tension_max`` re-clamps the target
    at once and out-of-range values are still refused."""
    bench = make(tension_max=12.0, **{"safety.limits_writable": True})
    bench.connected()
    bench.setpoint(35.0)
    bench.advance(0.005)
    assert bench.state()["target"] == "12.000"
    assert "setpoint = 35 N is out of range [0, 12] N; clamped to 12 N" in bench.log.text
    bench.advance(0.2)  # the next /diagnostics
    warned = bench.component("actuator")
    assert level(warned) == 1 and int(values(warned)["clamped_setpoints"]) == 1
    assert "clamped to 12 N" in values(warned)["last_warning"]
    assert "clamped to [0, 12] N" in warned.message
    bench.until(lambda: abs(bench.twin.plant.tension - 12.0) < BAND, 5.0, "12 N on the tendon")
    bench.advance(1.0)
    assert bench.twin.core.setpoint_mn == 12000

    store = bench.port.store
    assert store.set({"tension_max": 10.0}).successful  # a lower maximum re-clamps the target
    bench.advance(0.005)
    assert store.get("tension_max") == 10.0 and bench.state()["target"] == "10.000"
    refused = store.set({"tension_max": 25.0})
    assert not refused.successful and "tension_max" in refused.reason, refused
    refused = store.set({"backoff_max": 0.02})  # below backoff_initial: the node's own check
    assert not refused.successful and "backoff_initial" in refused.reason, refused
    refused = store.set({"port": "/dev/null"})
    assert not refused.successful and "read-only" in refused.reason, refused
    assert store.get("tension_max") == 10.0 and store.get("port") == URL
    bench.advance(1.0)
    assert bench.twin.core.setpoint_mn == 10000


def test_safety_limits_are_read_only_at_run_time_by_default(bench) -> None:
    """Without ``safety.limits_writable`` (itself read-only) nobody can raise the force limits;
    the refusal names the parameter and the opt-in. Other driver parameters stay writable."""
    bench.connected()
    store = bench.port.store
    for name, value in (("tension_max", 22.0), ("setpoint_rate", 1000.0)):
        refused = store.set({name: value})
        assert not refused.successful, refused
        assert f"{name} = {value}" in refused.reason, refused
        assert "safety.limits_writable: true" in refused.reason, refused
    assert store.get("tension_max") == 20.0 and store.get("setpoint_rate") == 40.0
    refused = store.set({"safety.limits_writable": True})
    assert not refused.successful and "read-only" in refused.reason, refused
    assert store.set({"heartbeat_period": 0.05}).successful
    bench.setpoint(22.0)
    bench.advance(0.005)
    assert bench.state()["target"] == "20.000"


def released_until_armed(bench: DriverBench, reason: str) -> None:
    """The driver reports itself disarmed for ``reason``; the device stays released with a slack
    tendon and a setpoint is refused; ``clear_faults`` arms it at 0 N (mode T, tendon still
    slack for 1 s) and only a new setpoint tensions it again."""
    core, plant = bench.twin.core, bench.twin.plant
    bench.until(lambda: bench.state().get("armed") == "false"
                and reason in bench.state().get("disarm_reason", "")
                and bench.state().get("link") == "connected", 5.0, f"disarmed ({reason})")
    bench.until(lambda: core.mode is Mode.RELEASE and plant.tension == 0.0, 2.0, "released")
    bench.setpoint(10.0)  # refused while disarmed
    assert bench.state()["rejected_setpoints"] == "1" and bench.state()["target"] == "0.000"
    for _ in range(150):  # 1.5 s
        bench.advance(0.01)
        assert core.mode is Mode.RELEASE and plant.tension == 0.0, "re-tensioned while disarmed"
    state = bench.state()
    assert state["target"] == "0.000" and state["armed"] == "false", state
    assert level(bench.states()[-1]) in (1, 2)
    answer = bench.call("clear_faults")
    assert answer.success and "armed at target 0 N" in answer.message, answer
    bench.until(lambda: bench.state().get("armed") == "true" and bench.state().get("mode")
                == "tension", 1.0, "armed by clear_faults")
    for _ in range(100):  # 1 s
        bench.advance(0.01)
        assert core.setpoint_mn == 0 and plant.tension < 0.3, "armed at the old setpoint"
    bench.setpoint(4.0)
    bench.until(lambda: abs(plant.tension - 4.0) < BAND, 5.0, "4 N after a new setpoint")


def test_a_device_rebooted_on_reopen_stays_released_until_armed(bench) -> None:
    """Holding 10 N, the port closes and the device comes back freshly booted, with no latched
    fault (a UNO resets when its port is opened): the driver never re-tensions it by itself. The
    link drops at the driver's next step and comes back after backoff_initial (0.5 s)."""
    bench.hold(10.0)
    pulled = bench.ms
    bench.loop.reopen(reboot=True)
    dropped = bench.until(lambda: bench.node.status.link.value == "disconnected", 0.01,
                          "the link dropped")
    assert dropped - pulled <= 5 and dropped % 5 == 0  # the next 5 ms step
    reopened = bench.until(lambda: bench.loop.opens == 2, 1.0, "a new link")
    assert reopened - dropped == 500  # backoff_initial
    released_until_armed(bench, "link lost")
    assert "device rebooted" in bench.log.text and "disarmed: link lost" in bench.log.text


def test_a_frozen_device_stays_released_until_armed_and_is_not_a_reboot(bench) -> None:
    """The device's loop hangs for 1 s holding 8 N, then resumes with the host's heartbeats
    buffered (so its own watchdog does not trip): the driver releases it and says it froze."""
    bench.hold(8.0)
    bench.twin.hung = True
    bench.advance(1.0)
    bench.twin.hung = False
    released_until_armed(bench, "frozen")
    assert "disarmed: device silent for" in bench.log.text and "reboot" not in bench.log.text
    assert bench.loop.opens == 1  # the link never dropped


def test_a_paused_twin_is_a_delay_not_a_freeze_and_the_tendon_stays_held(bench) -> None:
    """The whole device pauses for 0.7 s (its clock, bench and loop: a twin whose process was
    not scheduled, seen in CI as "device silent for 0.67 s (frozen?)") while the host steps: its
    next frame is 20 ms of device time after the last, so the driver warns of delayed frames
    and stays armed, holding 8 N; a hang of the same length with the clock running disarms
    (test above)."""
    bench.hold(8.0)
    device_ms = bench.twin.device_ms
    bench.advance(0.7, device=False)
    assert bench.twin.device_ms == device_ms
    bench.advance(0.5)
    state = bench.state()
    assert state["armed"] == "true" and state["disarm_reason"] == "", state
    assert "device frames delayed: none for 0.7" in bench.log.text
    assert "while its clock ran 0.0" in bench.log.text and "frozen" not in bench.log.text
    assert bench.twin.core.mode is Mode.TENSION
    assert bench.twin.plant.tension == pytest.approx(8.0, abs=0.25)
    assert bench.loop.opens == 1


def test_estop_releases_at_the_next_device_tick_and_stays_released_until_cleared(bench) -> None:
    bench.hold(8.0)
    core = bench.twin.core
    bench.watch_release()
    sent_ms = bench.twin.device_ms
    bench.estop()
    # E reached the device within the subscription callback: released before any time passed
    assert core.mode is Mode.RELEASE and core.faults & Fault.ESTOP
    assert core.pulse_us == c.PULSE_RELEASE_US
    bench.advance(0.001)
    assert bench.released_at == sent_ms + 1  # the device's loop, 1 ms on, finds it released
    bench.until(lambda: bench.twin.plant.tension == 0.0, 1.0, "a slack tendon")
    bench.until(lambda: "ESTOP" in values(bench.states()[-1]).get("faults", ""), 0.2,
                "ESTOP in device_state")
    assert level(bench.states()[-1]) == 2 and values(bench.states()[-1])["target"] == "0.000"
    bench.advance(0.5)
    assert core.mode is Mode.RELEASE  # latched: no automatic recovery
    assert bench.call("clear_faults").success
    bench.until(lambda: bench.state().get("faults") == "" and bench.state().get("mode")
                == "tension", 1.0, "faults cleared, holding 0 N again")


def test_a_pulled_cable_reconnects_after_the_backoff_and_reports_the_watchdog(make) -> None:
    """A pulled cable: the link drops at the next step, the device's watchdog releases the tendon
    exactly 500 ms after the host's last byte, the driver reconnects after backoff_initial
    (1 s), reports reconnects = 1 and the latched fault, and holds again once it is cleared."""
    bench = make(backoff_initial=1.0)
    bench.hold(8.0)
    bench.watch_release()
    bench.loop.unplug()
    pulled = bench.ms
    dropped = bench.until(lambda: bench.node.status.link.value == "disconnected", 0.01,
                          "the link dropped")
    assert dropped - pulled <= 5 and dropped % 5 == 0
    assert "device link lost" in bench.log.text
    bench.advance(0.2)
    assert bench.component_level("serial link") == 2
    assert "read failed: cable pulled" in bench.component("serial link").message
    bench.loop.plug()
    reopened = bench.until(lambda: bench.loop.opens == 2, 2.0, "a new link")
    assert reopened - dropped == 1000  # backoff_initial
    assert bench.released_at is not None and bench.released_last_rx is not None
    assert bench.released_last_rx % c.CONTROL_PERIOD_MS == 0  # see the host-stop test
    assert bench.released_at - bench.released_last_rx == c.WATCHDOG_MS
    bench.until(lambda: bench.state().get("link") == "connected"
                and "WATCHDOG" in bench.state().get("faults", ""), 1.0,
                "connected again, with the watchdog release of the outage reported")
    bench.advance(0.2)
    assert values(bench.component("serial link"))["reconnects"] == "1"
    assert bench.twin.core.mode is Mode.RELEASE
    assert bench.call("clear_faults").success
    bench.connected(1.0)
    count = len(bench.port.messages("tension"))
    bench.advance(0.2)
    assert len(bench.port.messages("tension")) == count + 10  # 50 Hz again


def test_reconnects_backs_off_exponentially_while_the_cable_is_out(make) -> None:
    """The first attempt backoff_initial (0.5 s) after the drop, then each failed open doubles
    the delay, 1 -> 2 -> 4 s, up to backoff_max (4 s)."""
    bench = make(backoff_max=4.0)
    bench.connected()
    bench.loop.unplug()
    dropped = bench.until(lambda: bench.node.status.link.value == "disconnected", 0.01,
                          "the link dropped")
    bench.advance(16.0)
    attempts = bench.open_attempts[1:]
    assert [ms - dropped for ms in attempts] == [500, 1500, 3500, 7500, 11500, 15500]


def test_statuses_carry_every_key_even_before_the_first_step(make) -> None:
    """The race seen once on rclpy (KeyError: 'reconnects'): a host that starts spinning late
    finds the diagnostics and state timers due with the step timer and runs them first; every
    status then still carries the keys it carries once stepped."""
    bench = make(state_period_s=0.1)
    bench.advance(0.3, host=False)  # the process is busy before it spins
    bench.resume_host()             # every timer is due now; the first created fire first
    first = bench.port.messages("/diagnostics")[0]
    assert all(s.message == "not stepped yet" for s in first.status)
    assert values(bench.port.messages("device_state")[0])["reconnects"] == "0"
    bench.advance(0.5)
    later = bench.port.messages("/diagnostics")[-1]
    assert bench.node.status is not None
    assert [[kv.key for kv in s.values] for s in first.status] == \
        [[kv.key for kv in s.values] for s in later.status]
    assert values(bench.port.messages("device_state")[0]).keys() == \
        values(bench.states()[-1]).keys()


def test_a_silent_device_is_reported_stale_then_fresh_again(bench) -> None:
    """No telemetry for longer than stale_timeout (0.25 s), shorter than link_timeout: STALE
    from the first state after 0.25 s of silence, fresh again with the first frame."""
    bench.connected()
    bench.advance(0.1)
    last_rx = (bench.port.sent("tension")[-1][0] - bench.start_ns) // 1_000_000  # the last frame
    stale = bench.until(lambda: bench.node.status.level == 3, 1.0, "STALE", device=False)
    assert stale - last_rx == 255  # the first 5 ms step more than 0.25 s after the last frame
    state = bench.until(lambda: level(bench.states()[-1]) == 3, 0.1, "STALE device_state",
                        device=False)
    assert state % 100 == 0 and state - stale < 100  # the next 0.1 s state period
    assert "no telemetry for" in bench.states()[-1].message
    bench.advance(0.4, device=False)
    assert level(bench.component("load cell")) == 3
    assert bench.node.status.link.value == "connected"
    bench.until(lambda: level(bench.states()[-1]) != 3, 0.2, "fresh telemetry again")
    assert bench.state()["link"] == "connected" and bench.loop.opens == 1


def test_device_releases_within_its_watchdog_when_the_host_stops(bench) -> None:
    """The host stops stepping (a hung process); the device releases by itself exactly its
    watchdog time after the host's last byte; WATCHDOG is reported once the host is back."""
    bench.hold(8.0)
    core = bench.twin.core
    bench.watch_release()
    bench.advance(1.5, host=False)
    assert bench.released_at is not None and bench.released_last_rx is not None
    # the firmware checks its watchdog at each 20 ms control tick, so it releases within
    # [WATCHDOG_MS, WATCHDOG_MS + CONTROL_PERIOD_MS) of the last byte; here the host's last
    # byte (heartbeats every 100 ms, setpoints every 20 ms of the same clock) lands on a
    # control tick, so the release comes exactly WATCHDOG_MS after it
    assert bench.released_last_rx % c.CONTROL_PERIOD_MS == 0
    assert bench.released_at - bench.released_last_rx == c.WATCHDOG_MS
    assert core.faults & Fault.WATCHDOG and bench.twin.plant.tension == 0.0
    bench.resume_host()
    bench.until(lambda: "WATCHDOG" in bench.state().get("faults", ""), 0.1,
                "WATCHDOG reported once the host is back")
    assert core.mode is Mode.RELEASE


def test_schedule_waits_for_the_device_runs_the_staircase_and_reports_done(make) -> None:
    bench = make(backoff_max=0.5, **{"schedule.levels": [0.0, 4.0, 8.0], "schedule.hold_s": 1.0,
                                     "schedule.trials": 2, "schedule.autostart": True})
    bench.loop.unplug()
    steps: list[tuple[int, float]] = []
    step = bench.node.step

    def recording() -> None:
        step()
        status = bench.node.status
        if status is not None and bench.node.schedule_state == "running" \
                and (not steps or steps[-1][1] != status.target):
            steps.append((bench.ms, status.target))

    bench.port.timers[[t.callback for t in bench.port.timers].index(step)].callback = recording
    bench.advance(1.0)
    assert bench.state()["schedule"] == "waiting" and bench.state()["link"] != "connected"
    bench.loop.plug()
    bench.until(lambda: bench.state().get("schedule_done") == "true", 10.0, "schedule_done")
    start = steps[0][0]
    assert [(ms - start, target) for ms, target in steps] == [
        (0, 0.0), (1000, 4.0), (2000, 8.0), (3000, 0.0), (4000, 4.0), (5000, 8.0)]
    assert "schedule started" in bench.log.text and "schedule done" in bench.log.text
    done = bench.ms
    assert done - start == 6000  # the step after the last level's hold
    assert max(m.wrench.force.z for m in bench.port.messages("tension")) == \
        pytest.approx(8.0, abs=0.3)
    assert bench.state()["target"] == "0.000"


@pytest.mark.parametrize(("name", "value", "message"), [
    ("tension_max", 30.0, "tension_max = 30.0 is out of range; allowed: [0.001, 22.0]"),
    ("heartbeat_period", 0.3, "heartbeat_period = 0.3 is out of range"),
    ("backoff_max", 0.1, "backoff_max = 0.1 s is out of range; allowed: >= backoff_initial"),
    ("schedule.levels", [0.0, -4.0], "schedule.levels: levels = -4.0 N is out of range"),
    ("schedule.trials", 0, "schedule.trials = 0 is out of range"),
    ("port", " ", "port = ' ' is invalid"),
    ("frame_id", "f" * 10_000_000, "frame_id = 'ffff"),
])
def test_bad_parameters_are_refused_naming_the_parameter(name, value, message) -> None:
    with pytest.raises(InputError) as caught:
        TensionDriverNode(MemoryPort({name: value}, name="bad_driver"))
    assert message in str(caught.value)


def test_a_frame_id_of_10_mb_is_refused_at_runtime_and_the_tension_keeps_its_frame(make) -> None:
    """The attack of issue 25: ``tdcm param set /tension_driver frame_id <10 MB>`` was taken and
    every 50 Hz tension then carried 10 MB."""
    bench = make()
    bench.connected()
    refused = bench.port.store.set({"frame_id": "f" * 10_000_000})
    assert not refused.successful
    assert "allowed: at most 4096 characters" in refused.reason and len(refused.reason) < 200
    bench.advance(0.1)
    assert {m.header.frame_id for m in bench.port.messages("tension")} == {"tdcm_tendon"}


def test_commands_are_trigger_services_that_answer_why(make) -> None:
    """Each command is a ``std_srvs/srv/Trigger`` service whose response says whether it was
    carried out and why not; after an e-stop (a fault) the tendon stays released and the
    schedule is refused until ``clear_faults``; ``release`` slackens and cancels the schedule."""
    bench = make(**{"schedule.levels": [0.0, 3.0], "schedule.hold_s": 1.0,
                    "schedule.trials": 5})
    bench.connected()
    core = bench.twin.core
    for command in COMMANDS:
        assert bench.port.services[f"~/{command}"][0] == "std_srvs/srv/Trigger"
    stopped = bench.call("estop")
    assert stopped.success and "ESTOP latched" in stopped.message, stopped
    # E was sent before the answer: the device released with ESTOP latched, no time passed
    assert core.mode is Mode.RELEASE and core.faults & Fault.ESTOP
    refused = bench.call("start_schedule")
    assert not refused.success, refused
    assert "refused: disarmed (e-stop)" in refused.message, refused
    assert "call clear_faults first" in refused.message, refused
    bench.advance(0.5)
    assert core.mode is Mode.RELEASE and core.setpoint_mn == 0  # nothing started
    cleared = bench.call("clear_faults")
    assert cleared.success and "armed at target 0 N" in cleared.message, cleared
    bench.until(lambda: core.mode is Mode.TENSION, 1.0, "holding 0 N after clear_faults")
    started = bench.call("start_schedule")
    assert started.success and "schedule started: [0.0, 3.0] N" in started.message, started
    bench.advance(1.005)  # 3 N from the step 1 s after the start
    assert bench.state()["schedule"] == "running" and bench.state()["target"] == "3.000"
    released = bench.call("release")
    assert released.success and "clear_faults" in released.message, released
    assert core.mode is Mode.RELEASE and bench.state()["schedule"] == "cancelled"


def test_diagnostics_report_each_component_and_recover(bench) -> None:
    """/diagnostics carries one status per hardware component (serial link, load cell,
    actuator; hardware_id the port) whose level follows the component: an e-stop makes the
    actuator ERROR until clear_faults, silence makes the load cell STALE until readings flow,
    a clamped setpoint warns for the window (5 periods of 0.2 s) only."""
    bench.connected()
    bench.until(lambda: all(bench.component_level(n) == 0 for n in COMPONENTS), 1.0,
                "every component OK")
    assert sorted(bench.components()[-1]) == sorted(COMPONENTS)
    assert {s.hardware_id for s in bench.components()[-1].values()} == {URL}
    assert all(s.name.startswith("tension_driver: ")
               for s in bench.port.messages("/diagnostics")[-1].status)
    assert bench.call("estop").success
    bench.advance(0.2)
    assert bench.component_level("actuator") == 2
    assert "ESTOP" in bench.component("actuator").message
    assert bench.component_level("serial link") == 0 and bench.component_level("load cell") == 0
    assert bench.call("clear_faults").success
    bench.until(lambda: bench.component_level("actuator") == 0, 1.0, "actuator OK again")
    clamped = bench.ms
    bench.setpoint(30.0)  # above tension_max 20 N: clamped
    bench.until(lambda: bench.component_level("actuator") == 1, 0.2, "actuator WARN")
    assert "setpoint clamped to [0, 20] N" in bench.component("actuator").message
    ok = bench.until(lambda: bench.component_level("actuator") == 0, 2.0,
                     "actuator OK once the clamp left the window")
    # the clamp (just after the update at `clamped`) warns in the 5 updates of the window that
    # follows, 0.2 s to 1.0 s after it, and no longer at the sixth
    assert clamped % 200 == 0 and ok - clamped == 1200
    warned = [level(array["actuator"]) for array in bench.components()[-6:]]
    assert warned == [1, 1, 1, 1, 1, 0]
    bench.advance(0.5, device=False)
    assert bench.component_level("load cell") == 3
    assert "no telemetry for" in bench.component("load cell").message
    bench.until(lambda: bench.component_level("load cell") == 0, 0.3, "load cell OK again")


# --- the roll: roll_setpoint in (clamped, slewed, refused while disarmed), joint_states out --------
ROLL_RATE = 0.8  #: rad/s, the driver's slew in these tests


@pytest.fixture
def roll_bench() -> Iterator[DriverBench]:
    made = DriverBench({"roll_rate": ROLL_RATE}, seed=7)
    yield made
    made.close()


def roll_states(bench: DriverBench) -> list[Any]:
    """The roll joint's messages on joint_states (the tendon joint's are the others)."""
    return [m for m in bench.port.messages("joint_states") if list(m.name) == ["roll"]]


def joint_positions(bench: DriverBench, first: int = 0) -> list[tuple[float, float]]:
    return [(stamp_ns(m) / 1e9, float(m.position[0])) for m in roll_states(bench)[first:]]


def test_roll_setpoint_is_slewed_clamped_and_published_as_joint_states(roll_bench) -> None:
    bench = roll_bench
    bench.connected()
    bench.advance(0.5)
    joints = roll_states(bench)
    assert len(joints) > 20
    assert all(list(m.position) == [0.0] and len(m.velocity) == 0 for m in joints)
    first = len(joints)
    bench.roll(0.9)
    bench.until(lambda: float(roll_states(bench)[-1].position[0]) == 0.9, 2.0,
                "roll 0.9 rad on joint_states")
    moving = [p for p in joint_positions(bench, first) if 0.0 < p[1] < 0.9]
    assert len(moving) >= 54  # 1.125 s at 0.8 rad/s of 50 Hz frames on the way
    slope = (moving[-1][1] - moving[0][1]) / (moving[-1][0] - moving[0][0])
    assert slope == pytest.approx(ROLL_RATE, rel=0.01)
    # joint_states reports the servo pulse; the twin's servo follows it at its own speed
    bench.until(lambda: abs(bench.twin.plant.roll - 0.9) <= 2e-3, 1.0, "the servo at 0.9 rad")
    bench.roll(2.0)
    bench.advance(0.005)
    assert bench.state()["roll_target"] == "1.571"  # clamped to pi/2
    assert bench.state()["clamped_rolls"] == "1"
    assert "clamped to 1.5708 rad" in bench.state()["last_warning"]
    bench.until(lambda: bench.twin.core.roll_mrad == 1571, 2.0, "the servo at pi/2")
    stamps = [stamp_ns(m) for m in bench.port.messages("joint_states")]
    assert stamps == sorted(stamps)


def test_estop_holds_the_roll_and_refuses_it_until_clear_faults(roll_bench) -> None:
    bench = roll_bench
    bench.connected()
    core, plant = bench.twin.core, bench.twin.plant
    bench.roll(-1.2)
    bench.until(lambda: core.roll_mrad <= -400, 2.0, "rolling toward -1.2 rad")
    bench.estop()
    bench.advance(c.CONTROL_PERIOD_MS / 1000)  # the device's next control tick holds the servo
    assert bench.state()["armed"] == "false"
    held = core.roll_mrad
    assert -1200 < held <= -400 and core.roll_target_mrad == held  # stopped on the way
    bench.roll(1.0)
    assert bench.state()["rejected_rolls"] == "1"
    count = len(roll_states(bench))
    for _ in range(100):  # 1 s
        bench.advance(0.01)
        assert core.roll_mrad == held, "the servo moved while disarmed"
    joints = roll_states(bench)[count:]
    assert len(joints) == 50  # joint_states go on at 50 Hz: the held position
    assert {float(m.position[0]) for m in joints} == {held / 1000}
    assert plant.roll == pytest.approx(held / 1000, abs=2e-3)
    assert bench.call("clear_faults").success
    bench.advance(0.5)
    assert bench.state()["armed"] == "true"
    assert core.roll_mrad == held  # arming alone does not move it
    bench.roll(0.0)
    bench.until(lambda: core.roll_mrad == 0, 3.0, "rolled back to 0")


def test_roll_limits_are_read_only_safety_limits(roll_bench) -> None:
    store = roll_bench.port.store
    assert store.get("roll_max") == pytest.approx(math.pi / 2)
    for name, value in (("roll_max", 1.0), ("roll_rate", 2.0)):
        refused = store.set({name: value})
        assert not refused.successful, refused
        assert "safety.limits_writable: true" in refused.reason, refused
    assert store.get("roll_rate") == ROLL_RATE


def test_a_lost_graph_releases_after_the_timeout_and_stays_released_until_armed(make) -> None:
    """No zenoh router for safety.graph_timeout_s (0.5 s here): nobody can reach the node, not
    even with an e-stop, so the driver releases the tendon; the router's return does not arm it
    again, clear_faults does. A loss shorter than the timeout changes nothing."""
    bench = make(**{"safety.graph_timeout_s": 0.5})
    bench.hold(8.0)
    hubs = bench.port.hubs
    bench.port.hubs = frozenset()
    bench.advance(0.3)
    bench.port.hubs = hubs
    bench.advance(0.5)
    assert bench.state()["armed"] == "true" and bench.twin.core.mode is Mode.TENSION
    assert bench.state()["graph_interruptions"] == "1"
    assert "graph interrupted for less than safety.graph_timeout_s = 0.5 s (the router back)" \
        in bench.state()["last_warning"]
    bench.port.hubs = frozenset()
    bench.advance(0.45)
    assert bench.state()["armed"] == "true"  # not yet: 0.4 s seen lost at the last look
    bench.advance(0.2)
    assert bench.state()["armed"] == "false" and bench.state()["graph_losses"] == "1"
    assert "graph lost: no zenoh router for 0.5 s" in bench.state()["disarm_reason"]
    bench.port.hubs = hubs
    bench.advance(0.2)
    assert "graph back; the tendon stays released until clear_faults" in bench.log.text
    released_until_armed(bench, "graph lost")


# --- ros2_control reach: the tendon joint on joint_states, joint_commands in -----------------------
def joint_command(names: list[str], positions: list[float], efforts: list[float]) -> Any:
    return from_dict("sensor_msgs/msg/JointState", {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "name": names,
        "position": positions, "velocity": [], "effort": efforts})


def test_joint_states_carry_the_tendon_joint_with_the_measured_tension_as_effort(bench) -> None:
    bench.connected()
    bench.setpoint(8.0)
    bench.advance(2.0)
    tendon = [m for m in bench.port.messages("joint_states") if list(m.name) == ["tendon"]]
    tension = bench.port.messages("tension")
    assert len(tendon) == len(tension) > 90  # one per telemetry frame
    assert [float(m.effort[0]) for m in tendon] == [m.wrench.force.z for m in tension]
    assert [stamp_ns(m) for m in tendon] == [stamp_ns(m) for m in tension]
    assert all(len(m.position) == 0 for m in tendon)
    stamps = [stamp_ns(m) for m in bench.port.messages("joint_states")]
    assert stamps == sorted(stamps)  # both joints, in time order


def test_joint_commands_set_tension_and_roll_as_ros2_control_sends_them(roll_bench) -> None:
    bench = roll_bench
    bench.connected()
    bench.port.deliver("joint_commands", joint_command(["tendon"], [], [12.0]))
    bench.advance(0.005)
    assert bench.state()["target"] == "12.000"
    bench.port.deliver("joint_commands", joint_command(["roll", "tendon"], [0.4, math.nan],
                                                       [math.nan, 6.0]))
    bench.advance(0.005)
    assert bench.state()["target"] == "6.000" and bench.state()["roll_target"] == "0.400"
    bench.port.deliver("joint_commands", joint_command(["tendon"], [], [99.0]))
    bench.advance(0.005)
    assert bench.state()["target"] == "20.000" and bench.state()["clamped_setpoints"] == "1"
    for bad in (joint_command(["tendon"], [], [math.inf]), joint_command(["tendon"], [], [math.nan]),
                joint_command(["wrist"], [1.0], [1.0])):
        bench.port.deliver("joint_commands", bad)
    bench.advance(0.005)
    assert bench.state()["target"] == "20.000"
    assert bench.node.counts["rejected_setpoints"] == 1      # inf N
    assert bench.node.counts["ignored_joint_commands"] == 1  # wrist; NaN effort: no command
    assert "'wrist' is not a joint of this driver" in bench.log.text
    bench.node.estop()
    bench.port.deliver("joint_commands", joint_command(["tendon"], [], [5.0]))
    bench.advance(0.005)
    assert bench.state()["target"] == "0.000"  # disarmed: refused, the tendon stays released


def test_a_router_restarted_between_two_looks_is_an_interruption_not_a_loss(make) -> None:
    """The router replaced faster than a look (tdcm up restarts it in ~0.2 s): the new router's
    id tells; the tendon is held (the gap is below safety.graph_timeout_s), the interruption is
    counted and warned about. A second router joining the first is no interruption."""
    bench = make()
    bench.hold(8.0)
    bench.port.hubs = bench.port.hubs | {"router-b"}  # a second router joins the first
    bench.advance(0.3)
    assert bench.state()["graph_interruptions"] == "0"
    bench.port.hubs = frozenset({"router-c"})  # both gone, a new one in their place
    bench.advance(0.3)
    state = bench.state()
    assert state["graph_interruptions"] == "1" and state["graph_losses"] == "0"
    assert state["armed"] == "true" and bench.twin.core.mode is Mode.TENSION
    assert "(a new router): messages sent to the node meanwhile may be lost" in \
        state["last_warning"]
