"""Run a demo plan: the live graph (embedded zenoh or rclpy), the bag, then evaluation and calibration.

The demo process joins the graph itself (a node named ``_tdcm_demo`` on the same runtime) to print
progress, to start the driver's schedule (its ``start_schedule`` service) once the bag holds
every evaluated topic (so the first level is recorded whatever the runtime's discovery time), and
to see the driver report ``schedule_done`` on ``/diagnostics`` (``tension_driver: actuator``).
A tracking plan instead publishes its targets and switches the controller's mode
(:mod:`tdcm_ros.demo.follow`) once the bag holds the bench and the controller's measured tip.
Children inherit the environment (``ROS_DOMAIN_ID``, ``ROS_AUTOMATIC_DISCOVERY_RANGE``, the zenoh
endpoint). Ctrl-C stops the graph cleanly (the bag is closed and keeps everything received) and
skips the evaluation.
"""

from __future__ import annotations

import logging
import signal
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

from tdcm_ros.bagio import BagError
from tdcm_ros.demo.plan import DemoPlan
from tdcm_ros.device import TRIP_FAULTS, Fault
from tdcm_ros.errors import TdcmError
from tdcm_ros.runtime import NodeGraph, RuntimePortError, resolve_topic

log = logging.getLogger("tdcm.demo")
#: Extra time (s) over the schedule before the demo gives up waiting for ``schedule_done``.
START_MARGIN_S = 60.0
#: Time (s) after ``schedule_done`` before the recorder is stopped, so the last samples land.
SETTLE_S = 0.5
#: Longest wait (s) for the bag to hold every evaluated topic before the schedule starts.
READY_TIMEOUT_S = 60.0
#: Time (s) a ``start_schedule`` call waits for the driver's service before it is tried again.
START_RETRY_S = 1.0
START_SERVICE = "/tension_driver/start_schedule"
CLEAR_SERVICE = "/tension_driver/clear_faults"
#: Longest wait (s) for the driver's first actuator status, and for a cleared fault to show.
DRIVER_STATUS_TIMEOUT_S = 15.0
#: The device faults that release the tendon (CALIBRATION does not).
TRIP_FAULT_NAMES = frozenset(flag.name for flag in Fault if flag & TRIP_FAULTS and flag.name)
#: The driver's ``/diagnostics`` status that carries the setpoint and the schedule state.
DRIVER_ACTUATOR = "tension_driver: actuator"
#: The device twin's ``/diagnostics`` status: its simulation's pauses (its thread not scheduled).
DEVICE_TWIN = "device_twin: device twin"


class DemoInterrupted(TdcmError):
    """The user stopped the demo (Ctrl-C or SIGTERM) before the schedule finished."""

    exit_code = 130


@dataclass
class Progress:
    """Latest values seen on the graph (updated by subscription callbacks)."""

    tension: float | None = None
    tip_x: float | None = None
    setpoint: str = ""
    schedule: str = ""
    schedule_done: bool = False
    faults: str = ""               #: the driver's latched trip faults, that release the tendon
    armed: bool | None = None      #: the driver's ``armed`` as last said (None before a status)
    actuator_statuses: int = 0     #: driver actuator statuses seen
    schedule_ran: bool = False     #: a status said the schedule was running
    disarm_reason: str = ""        #: why the driver disarmed last ("" while it never did)
    twin_pauses: str = ""          #: the device twin's late turns and pauses, as its status says
    counts: dict[str, int] = field(default_factory=dict)

    def count(self, topic: str) -> None:
        """Count one message on ``topic``."""
        self.counts[topic] = self.counts.get(topic, 0) + 1

    def line(self, elapsed: float) -> str:
        """One progress line."""
        tension = "-" if self.tension is None else f"{self.tension:6.2f} N"
        tip = "-" if self.tip_x is None else f"{self.tip_x * 1e3:6.2f} mm"
        return (f"  t = {elapsed:5.1f} s  schedule {self.schedule or '-':9s} setpoint "
                f"{self.setpoint or '-':>7s} N  tension {tension}  predicted tip x {tip}  "
                f"markers {self.counts.get('markers', 0)}")


def _watch(port: Any, progress: Progress) -> None:
    """Subscribe the topics the progress line shows."""
    from tdcm_ros.runtime import QoS

    def on_tension(message: Any) -> None:
        progress.tension = float(message.wrench.force.z)
        progress.count("tension")

    def on_tip(message: Any) -> None:
        progress.tip_x = float(message.pose.position.x)
        progress.count("tip_pose")

    def on_diagnostics(message: Any) -> None:
        for status in message.status:
            if status.name == DRIVER_ACTUATOR:
                values = {kv.key: kv.value for kv in status.values}
                progress.setpoint = values.get("setpoint", progress.setpoint)
                progress.schedule = values.get("schedule", progress.schedule)
                progress.schedule_done = (progress.schedule_done
                                          or values.get("schedule_done") == "true")
                progress.faults = "|".join(name for name in values.get("faults", "").split("|")
                                           if name in TRIP_FAULT_NAMES)
                progress.schedule_ran = progress.schedule_ran or progress.schedule == "running"
                progress.disarm_reason = values.get("disarm_reason", progress.disarm_reason)
                if values.get("armed") in ("true", "false"):
                    progress.armed = values["armed"] == "true"
                progress.actuator_statuses += 1
            elif status.name == DEVICE_TWIN:
                values = {kv.key: kv.value for kv in status.values}
                if "sim_pauses" in values:
                    progress.twin_pauses = (
                        f"caught up {values.get('sim_late_turns', '?')} late turn(s) and paused "
                        f"{values['sim_pauses']} time(s), {values.get('sim_paused_s', '?')} s in all")

    def on_markers(message: Any) -> None:
        progress.count("markers")

    qos = QoS(depth=10)
    port.create_subscription("tension", "geometry_msgs/msg/WrenchStamped", on_tension, qos)
    port.create_subscription("tip_pose", "geometry_msgs/msg/PoseStamped", on_tip, qos)
    port.create_subscription("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                             on_diagnostics, qos)
    port.create_subscription("markers", "mocap4r2_msgs/msg/Markers", on_markers, qos)


def start_schedule(context: Any) -> bool:
    """Call the driver's ``start_schedule``; False if no driver answered yet. A refusal ends
    the demo with the driver's reason."""
    try:
        answer = context.call_service(START_SERVICE, "std_srvs/srv/Trigger",
                                      timeout=START_RETRY_S)
    except RuntimePortError as error:
        log.info("start_schedule not answered yet: %s", error)
        return False
    if not answer.success:
        raise RuntimePortError(f"the driver refused to start the schedule: {answer.message}")
    return True


def held_released(progress: Progress) -> str:
    """Why the driver holds the tendon released, as its last status says ("" if it does not):
    its latched trip faults, its disarm reason, or both."""
    reasons = []
    if progress.faults:
        reasons.append(f"device fault {progress.faults}")
    if progress.armed is False:
        reasons.append(f"disarmed ({progress.disarm_reason or 'no reason given'})")
    return " and ".join(reasons)


def clear_start_up_fault(context: Any, loop: _Loop, progress: Progress,
                         say: Callable[[str], None]) -> None:
    """Before the schedule or the first target: wait for the driver's actuator status; a device
    fault latched or a disarm while the graph started (e.g. the watchdog of a starved driver
    process, or a device twin not scheduled for its watchdog time) is cleared once through
    ``clear_faults``, said, and must be gone from the statuses within
    ``DRIVER_STATUS_TIMEOUT_S``. No target has been sent then, so arming sends none."""
    deadline = time.monotonic() + DRIVER_STATUS_TIMEOUT_S
    while not progress.actuator_statuses:
        loop.turn(deadline, lambda: f"no {DRIVER_ACTUATOR!r} status on /diagnostics within "
                                    f"{DRIVER_STATUS_TIMEOUT_S:g} s")
    held = held_released(progress)
    if not held:
        return
    answer = context.call_service(CLEAR_SERVICE, "std_srvs/srv/Trigger",
                                  timeout=DRIVER_STATUS_TIMEOUT_S)
    if not answer.success:
        raise RuntimePortError(f"the driver latched {held} while the graph started and "
                               f"refused clear_faults: {answer.message}")
    say(f"the driver latched {held} while the graph started (no target sent yet); cleared it "
        f"with clear_faults{twin_pauses(progress)}")
    deadline = time.monotonic() + DRIVER_STATUS_TIMEOUT_S
    while held_released(progress):  # a status sent before the clear may still arrive after it
        loop.turn(deadline, lambda: f"{held_released(progress)} is still latched "
                                    f"{DRIVER_STATUS_TIMEOUT_S:g} s after clear_faults; the "
                                    "tendon stays released")


def twin_pauses(progress: Progress) -> str:
    """What the device twin said of its late turns and its simulation's pauses (its thread not
    scheduled on time: a loaded machine), for an error about the run's bench; "" before it said
    anything."""
    if not progress.twin_pauses:
        return ""
    return (f"; the device twin {progress.twin_pauses} so far (its thread not scheduled on time: "
            "a loaded machine)")


def fault_free(progress: Progress) -> None:
    """Raise if the driver reports a latched device fault or a disarm: the tendon is then
    released until an operator clears it, and the run's tracking figures would not mean
    anything."""
    if held := held_released(progress):
        raise RuntimePortError(f"the driver reports {held} during the run: the tendon is "
                               "released until clear_faults, so the tracking run stopped (the "
                               f"bag so far is kept){twin_pauses(progress)}")


def schedule_not_cancelled(progress: Progress) -> None:
    """Raise once the driver reports the running schedule cancelled (it disarmed: the tendon
    is released until ``clear_faults``), naming the driver's reason, instead of waiting for a
    ``schedule_done`` that cannot come."""
    if progress.schedule_ran and progress.schedule == "cancelled":
        raise RuntimePortError(f"the driver cancelled the schedule: disarmed "
                               f"({progress.disarm_reason or 'no reason given'}); the tendon is "
                               "released until clear_faults (the bag so far is kept)"
                               f"{twin_pauses(progress)}")


def _graph_alive(graph: NodeGraph) -> None:
    exited = [c for c in graph.children if not c.running]
    if exited:
        names = ", ".join(f"{c.name} (exit {c.process.returncode})" for c in exited)
        logs = f"; see {graph.log_dir}/<name>.log" if graph.log_dir else ""
        raise RuntimePortError(f"demo process exited early: {names}{logs}")


def bag_holds(bag: Path, topics: tuple[str, ...]) -> bool:
    """True once the bag being written at ``bag`` holds a message on each of ``topics``."""
    from tdcm_ros.bagio.reader import open_bag

    try:
        counts = open_bag(bag).counts
    except BagError:  # not created yet, or no chunk flushed yet
        return False
    return all(counts.get(resolve_topic(topic), 0) > 0 for topic in topics)


class _Loop:
    """One 0.1 s turn of the demo's waits: spin, then fail on Ctrl-C, a dead child or a deadline."""

    def __init__(self, graph: NodeGraph, context: Any, stop: threading.Event) -> None:
        self.graph, self.context, self.stop = graph, context, stop

    def turn(self, deadline: float, late: Callable[[], str], seconds: float = 0.1) -> None:
        """Spin ``seconds``; ``late()`` is the error message once ``deadline`` (monotonic s)
        passed."""
        if self.stop.is_set():
            raise DemoInterrupted("demo interrupted; the bag so far is closed and readable")
        _graph_alive(self.graph)
        if time.monotonic() > deadline:
            raise RuntimePortError(late())
        self.context.spin_for(seconds)


def _run_schedule(plan: DemoPlan, context: Any, loop: _Loop, progress: Progress,
                  say: Callable[[str], None], progress_period: float) -> None:
    """Start the driver's schedule and wait until it reports ``schedule_done``."""
    started = time.monotonic()
    deadline = started + plan.schedule.duration + START_MARGIN_S
    next_line = started
    requested = False
    while not progress.schedule_done:
        schedule_not_cancelled(progress)
        requested = requested or start_schedule(context)
        loop.turn(deadline, lambda: f"the schedule did not finish within "
                                    f"{plan.schedule.duration:g} s + {START_MARGIN_S:g} s "
                                    f"(last state {progress.schedule or 'none'}); see "
                                    f"{loop.graph.log_dir}")
        if time.monotonic() >= next_line:
            say(progress.line(time.monotonic() - started))
            next_line += progress_period


def record_live(plan: DemoPlan, *, endpoint: str, runtime: str = "zenoh",
                say: Callable[[str], None] = print, progress_period: float = 2.0) -> Progress:
    """Run the graph on ``runtime`` (``zenoh``: with a router on ``endpoint`` unless one answers
    there; ``rclpy``) until the driver's schedule is done, or a tracking plan's last target is
    published; the bag is closed on return. ``progress_period`` is the time between progress
    lines (s)."""
    from tdcm_ros.runtime.run_node import open_context

    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        # set from another thread: Event.set here could wait forever for the event's lock,
        # held by this (main) thread when the signal lands inside stop.wait
        threading.Thread(target=stop.set, daemon=True).start()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    logs = plan.out / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    progress = Progress()
    graph = NodeGraph(endpoint=endpoint, runtime=runtime, log_dir=logs, stop_event=stop)
    context: Any = None
    try:
        graph.ensure_router()
        recorder = graph.start("recorder", [sys.executable, "-m", "tdcm_ros.cli.main", "record",
                                            "--runtime", runtime, str(plan.bag),
                                            *plan.recorded_topics])
        context = open_context(runtime)
        port = context.create_port("_tdcm_demo")
        _watch(port, progress)
        overrides = plan.node_overrides()
        for name in plan.node_order:
            if stop.is_set():
                break
            graph.start_node(name, overrides=overrides[name],
                             ready_path=plan.link if name == "device_twin" else None)
        say(f"graph up on {runtime}: {'router, ' if graph.router else ''}recorder, "
            f"{', '.join(plan.node_order)} (logs in {logs})")
        loop = _Loop(graph, context, stop)
        ready_by = time.monotonic() + READY_TIMEOUT_S
        ready = plan.ready_topics
        while not bag_holds(plan.bag, ready):
            loop.turn(ready_by, lambda: f"the recorder wrote no {', '.join(ready)} "
                                        f"within {READY_TIMEOUT_S:g} s; see {logs}")
        started = time.monotonic()
        clear_start_up_fault(context, loop, progress, say)
        if plan.targets is None:
            say(f"the bag holds {', '.join(ready)}; starting the schedule")
            _run_schedule(plan, context, loop, progress, say, progress_period)
        else:
            from tdcm_ros.demo.follow import follow

            say(f"the bag holds {', '.join(ready)}; following the trajectory")

            def turn(deadline: float, late: Callable[[], str], seconds: float) -> None:
                fault_free(progress)
                loop.turn(deadline, late, seconds)

            follow(plan.targets, context, port, turn, say=say,
                   progress_period=progress_period, margin_s=START_MARGIN_S)
        context.spin_for(SETTLE_S)
        status = graph.stop(recorder)
        if status not in (0, 130, -signal.SIGINT):
            raise RuntimePortError(f"the recorder exited with {status}; see {logs}/recorder.log")
        say(f"{'schedule' if plan.targets is None else 'trajectory'} done after "
            f"{time.monotonic() - started:.1f} s; bag closed: {plan.bag}")
        return progress
    finally:
        if context is not None:
            context.close()
        graph.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
