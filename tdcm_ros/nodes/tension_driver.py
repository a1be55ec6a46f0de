"""``tension_driver``: the tension device on a serial port, as a node.

Wraps :class:`tdcm_ros.device.driver.TensionDriver` (handshake, heartbeats, setpoint ramp and
clamp, reconnect with backoff, stale detection). A timer (``step_period_s``) steps the driver and
publishes every telemetry frame as ``tension`` (``geometry_msgs/msg/WrenchStamped``,
``wrench.force.z`` = measured tension in N, frame ``frame_id`` (after ``frame_prefix``); stamp = the host time the device
took it, :class:`~tdcm_ros.device.clock_map.DeviceClockMap`: a burst keeps its device spacing). ``/diagnostics`` (every ``diagnostics_period_s``)
carries one status per component (:mod:`tdcm_ros.nodes.driver_diagnostics`): ``serial link``,
``load cell`` and ``actuator`` (mode, faults, setpoints, armed, the schedule state and
``schedule_done``, the roll). ``joint_states`` (``sensor_msgs/msg/JointState``, name ``["roll"]``)
carries the roll servo's position (rad, from the device's telemetry: where its slew-limited pulse
points; 0 rad, its boot position, until a roll is commanded) once per telemetry frame, stamped like
``tension``; and, for every telemetry frame, the driven tendon as joint ``tendon`` whose effort is
the measured tension (N; no position), so a ros2_control topic-based hardware interface reads
both joints from ``joint_states``. ``device_state`` (``diagnostic_msgs/msg/DiagnosticStatus``, every
``state_period_s``) is deprecated: those statuses rolled into one.

Inputs: ``tension_setpoint`` (``std_msgs/msg/Float64``, N: clamped to ``[0, tension_max]`` with a
warning, ramped at ``setpoint_rate``; cancels a running schedule), ``roll_setpoint``
(``std_msgs/msg/Float64``, rad: clamped to ``[-roll_max, roll_max]`` with a warning, slewed at
``roll_rate``; refused while disarmed or with a trip fault latched, the servo holding where it is)
``joint_commands`` (``sensor_msgs/msg/JointState``, as ros2_control's topic-based hardware
interfaces send commands: joint ``tendon``'s effort is a tension setpoint, joint ``roll``'s position
a roll setpoint, each handled exactly as on the two topics above; an empty or NaN field is no
command, an infinite one is refused as on those topics, other joints are counted and ignored)
and ``estop``
(``std_msgs/msg/Empty``: release at once, latch the device's ESTOP fault, disable; a topic so any
node can fire it without waiting). Commands are ``std_srvs/srv/Trigger`` services whose response
says whether they were carried out and why not: ``~/start_schedule`` ((re)start the
``schedule.*`` staircase; refused while disarmed or with a latched fault), ``~/clear_faults``
(clear latched faults, arm, re-enable if ``enabled``; refused while the link is down),
``~/release`` (slacken the tendon, cancel the schedule, until ``clear_faults``) and ``~/estop``
(as the topic). On shutdown the node releases the tendon and closes the port.

After a link loss, a device reboot or freeze, and an e-stop the driver is disarmed (see
:mod:`tdcm_ros.device.driver`): the device is held released at a target of 0 N, setpoints and
schedules are refused, until ``clear_faults``; after it a new setpoint is needed. The actuator's
status reports ``armed`` and ``disarm_reason``.

The force and roll limits :data:`SAFETY_LIMITS` are read-only at run time unless the node is started with
``safety.limits_writable: true`` (itself read-only).

``managed: true`` (read-only) makes it a managed (lifecycle) node, :mod:`tdcm_ros.runtime.lifecycle`:
it starts ``unconfigured`` with the port closed; ``configure`` opens the port and starts the
handshake; ``activate`` is the arm command (as ``clear_faults``, which is refused while not
active); ``deactivate`` releases the tendon and disarms; ``cleanup``, ``shutdown`` and an error
release and close the port. Its safety rules are those above in every state.
"""

from __future__ import annotations

import math
import sys
import time
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import replace
from typing import Any

from tdcm_ros.bagio import from_dict
from tdcm_ros.device import (
    DRIVER_SPECS,
    SCHEDULE_SPECS,
    DeviceClockMap,
    DriverConfig,
    DriverStatus,
    LinkState,
    PortError,
    ProtocolVersionError,
    RollState,
    StepSchedule,
    Telemetry,
    TensionDriver,
    Transport,
    fault_names,
)
from tdcm_ros.errors import InputError
from tdcm_ros.nodes.driver_diagnostics import actuator, load_cell, serial_link
from tdcm_ros.nodes.frames import FRAME_PREFIX_SPECS, declare_frame_prefix, robot_frame
from tdcm_ros.nodes.joint_messages import (
    JOINT_STATE,
    ROLL_JOINT,
    TENDON_JOINT,
    commanded,
    joint_state,
    tendon_effort,
)
from tdcm_ros.nodes.shape_messages import header
from tdcm_ros.runtime import (
    Diagnostics,
    NodeLogic,
    NodePort,
    QoS,
    Status,
    Throttled,
    declare_specs,
    grouped,
    read_specs,
    summary,
    template,
)
from tdcm_ros.runtime.lifecycle import ACTIVE, INACTIVE, Lifecycle, TransitionFailed
from tdcm_ros.runtime.run_node import main_for
from tdcm_ros.spec import Spec, by_name

TRIGGER = "std_srvs/srv/Trigger"
ESTOP_TOPIC, ESTOP_TYPE = "estop", "std_msgs/msg/Empty"  #: open to every user (access_control)
ESTOP_SERVICE = "estop"  #: the one command service open to every user (access_control)
STATUS_TYPE = "diagnostic_msgs/msg/DiagnosticStatus"
SCHEDULE_STATES = ("idle", "waiting", "running", "done", "cancelled")
#: parameters that bound the force on the tendon and the roll: fixed at run time unless safety.limits_writable
SAFETY_LIMITS = ("tension_max", "setpoint_rate", "roll_max", "roll_rate")
LIMITS_WRITABLE = "safety.limits_writable"
GRAPH_TIMEOUT = "safety.graph_timeout_s"
#: s between two looks at the graph (a zenoh session's router list) in the step.
GRAPH_CHECK_PERIOD_S = 0.1
#: DriverConfig fields fixed at start (the link); the others change at run time.
LINK_FIELDS = ("port", "baudrate")
#: Parameters of the node fixed at start, besides the link.
FIXED_SPECS = by_name(
    Spec(LIMITS_WRITABLE, description="allow run-time changes of the safety limits "
         f"{', '.join(SAFETY_LIMITS)}", default=False, kind="bool"),
    Spec("schedule.autostart", description="run the schedule once the device is connected",
         default=False, kind="bool"),
    Spec(GRAPH_TIMEOUT, "s", "release and disarm after the graph (zenoh router) is lost this long",
         1.0, low=0.1, high=60.0),
    Spec("step_period_s", "s", "driver step period; telemetry is 50 Hz", 0.005, low=0.001,
         high=0.02),
    Spec("state_period_s", "s", "device_state period (deprecated topic)", 0.1, low=0.01,
         high=10.0),
    Spec("diagnostics_period_s", "s", "/diagnostics period", 0.5, low=0.05, high=60.0),
    Spec("managed", description="a managed (lifecycle) node: starts unconfigured; configure "
         "opens the port, activate arms, deactivate releases, cleanup closes", default=False,
         kind="bool"))
#: Why a managed driver is disarmed outside ``active``.
NOT_ACTIVE = "managed node not active: activate arms"
#: Parameters of the node a client may change at run time, besides the driver and schedule.
TUNABLE_SPECS = by_name(
    Spec("frame_id", description="frame of `tension`", default="tdcm_tendon", kind="str"),
    Spec("enabled", description="hold the setpoint (device mode T) when no fault", default=True,
         kind="bool"))

#: Every parameter of the node by full name, as declared below (parameter files are checked
#: against it).
PARAMETERS = {**grouped(DRIVER_SPECS), **grouped(FIXED_SPECS), **grouped(FRAME_PREFIX_SPECS),
              **grouped(TUNABLE_SPECS),
              **grouped(SCHEDULE_SPECS, "schedule.")}


class TensionDriverNode(NodeLogic):
    """The tension device as a node; see the module docstring."""

    default_name = "tension_driver"

    def __init__(self, port: NodePort, *, clock: Callable[[], float] = time.monotonic,
                 open_port: Callable[[str], Transport] | None = None) -> None:
        """``clock`` (s, monotonic) and ``open_port`` (a :class:`Transport` for the ``port``
        parameter; default: the serial port) go to the driver: a test gives the port's simulated
        clock and an in-process link to a device twin."""
        super().__init__(port)
        link = declare_specs(port, {name: DRIVER_SPECS[name] for name in LINK_FIELDS},
                             read_only=True)
        url = str(link["port"])
        _non_empty("port")(url)
        fixed = declare_specs(port, FIXED_SPECS, read_only=True)
        self.frame_prefix = declare_frame_prefix(port)
        self.limits_writable = bool(fixed[LIMITS_WRITABLE])
        self.driver_specs = {name: self._noted(spec) for name, spec in DRIVER_SPECS.items()
                             if name not in LINK_FIELDS}
        declare_specs(port, self.driver_specs)
        declare_specs(port, TUNABLE_SPECS)
        declare_specs(port, SCHEDULE_SPECS, prefix="schedule.")
        autostart = bool(fixed["schedule.autostart"])
        step_period = float(fixed["step_period_s"])
        state_period = float(fixed["state_period_s"])
        diag_period = float(fixed["diagnostics_period_s"])
        config = DriverConfig(**link, **self._driver_values({}))
        self.schedule = self._schedule({})
        port.add_on_set_parameters(self._on_set)

        self.counts: Counter[str] = Counter()
        self._last_stamp_ns = {"tension": 0, "joint_states": 0}
        self.clock_map = DeviceClockMap()
        self.last_warning = ""
        self._warnings = Throttled(clock=clock)
        self.schedule_state = "waiting" if autostart else "idle"
        self.status: DriverStatus | None = None
        self.driver = TensionDriver(config, clock=clock, open_port=open_port, warn=self._warn)
        self._clock = clock
        self.graph_timeout = float(fixed[GRAPH_TIMEOUT])
        self._graph_checked = self._graph_seen = clock()
        self._graph_lost = self._graph_missing = False
        self._hubs: frozenset[str] = frozenset()  # the routers at the last look that saw one
        if bool(port.get_parameter("enabled")):
            self.driver.enable()
        self.lifecycle: Lifecycle | None = None
        if bool(fixed["managed"]):
            self.lifecycle = Lifecycle(port, {
                "on_configure": self._configure, "on_activate": self._activate,
                "on_deactivate": self._deactivate, "on_cleanup": self._close,
                "on_shutdown": self._close, "on_error": self._close})
            self.driver.disarm(NOT_ACTIVE)

        self.tension = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped",
                                             QoS(depth=100))
        self.joints = port.create_publisher("joint_states", JOINT_STATE, QoS(depth=100))
        self.state = port.create_publisher("device_state", STATUS_TYPE, QoS(depth=10))
        self.diagnostics = Diagnostics(port, diag_period)
        self.clamps = self.diagnostics.window()
        hardware = url
        self.diagnostics.add("serial link", hardware,
                             lambda: serial_link(self.status, self.counts))
        self.diagnostics.add("load cell", hardware, lambda: load_cell(self.status))
        self.diagnostics.add("actuator", hardware, self._check_actuator)
        port.create_subscription("tension_setpoint", "std_msgs/msg/Float64", self._on_setpoint,
                                 QoS(depth=10))
        port.create_subscription("roll_setpoint", "std_msgs/msg/Float64", self._on_roll,
                                 QoS(depth=10))
        port.create_subscription("joint_commands", JOINT_STATE, self._on_joint_commands,
                                 QoS(depth=10))
        port.create_subscription(ESTOP_TOPIC, ESTOP_TYPE, self._on_estop, QoS(depth=10))
        for name, command in (("start_schedule", self.start_schedule),
                              ("clear_faults", self.clear_faults), ("release", self.release),
                              (ESTOP_SERVICE, self.estop)):
            port.create_service(f"~/{name}", TRIGGER, _answering(command))
        port.create_timer(step_period, self.step)
        port.create_timer(state_period, self.publish_state)
        port.logger.info("driving the tension device on %s (tension_max %g N)", url,
                         config.tension_max)

    # --- parameters -------------------------------------------------------------------------
    def _noted(self, spec: Spec) -> Spec:
        """A driver spec, its description noting a safety limit locked at run time."""
        if spec.name in SAFETY_LIMITS and not self.limits_writable:
            return replace(spec, description=f"{spec.description}; read-only unless "
                                             f"{LIMITS_WRITABLE}")
        return spec

    def _driver_values(self, changes: Mapping[str, Any]) -> dict[str, Any]:
        return read_specs(self.port, self.driver_specs, changes=changes)

    def _schedule(self, changes: Mapping[str, Any]) -> StepSchedule:
        """The schedule from the parameters; raises ``InputError`` naming the parameter."""
        return StepSchedule(**read_specs(self.port, SCHEDULE_SPECS, prefix="schedule.",
                                         changes=changes))

    def _on_set(self, changes: Mapping[str, Any]) -> None:
        """Validate runtime changes as a whole, then apply them (raising keeps the old values)."""
        self._check_limits_writable(changes)
        config = replace(self.driver.config, **self._driver_values(changes))
        schedule = self._schedule(changes)
        self.driver.config, self.schedule = config, schedule
        status = self.status
        if (status is not None and not self.driver.schedule_running
                and status.target > self.driver.tension_max):
            self._request(status.target)  # re-clamp a held setpoint to the lower maximum
        # a held roll target is re-clamped to a lower roll_max by the driver's next step
        if "enabled" in changes:
            if changes["enabled"]:
                self.driver.enable()
            else:
                self.driver.release()

    def _check_limits_writable(self, changes: Mapping[str, Any]) -> None:
        """Refuse a run-time change of a safety limit unless the node was started with
        ``safety.limits_writable: true``; raises ``InputError`` naming the parameter."""
        if self.limits_writable:
            return
        for name in SAFETY_LIMITS:
            if name in changes:
                current = self.port.get_parameter(name)
                raise InputError(
                    f"{name} = {changes[name]!r} refused: {name} is a safety limit, read-only at "
                    f"run time (it stays {current!r}); to allow run-time changes start the node "
                    f"with {LIMITS_WRITABLE}: true", parameter=name, value=changes[name],
                    allowed=f"{current!r} (read-only unless {LIMITS_WRITABLE}: true)")

    # --- inputs -----------------------------------------------------------------------------
    def _warn(self, text: str) -> None:
        """Keep ``text`` as the latest warning (diagnostics) and log it, throttled per kind."""
        self.last_warning = text
        suffix = self._warnings.admit(template(text))
        if suffix is not None:
            self.port.logger.warning("%s%s", text, suffix)

    def _request(self, newtons: float) -> None:
        applied = self.driver.set_setpoint(newtons)
        if applied != newtons and self.driver.armed:
            self.counts["clamped_setpoints"] += 1

    def _on_setpoint(self, message: Any) -> None:
        self._tension_command(float(message.data), "tension_setpoint")

    def _tension_command(self, newtons: float, source: str) -> None:
        if not math.isfinite(newtons):
            self.counts["rejected_setpoints"] += 1
            self._warn(f"{source} = {newtons!r} N is not finite; ignored")
            return
        self._cancel_schedule()
        if not self.driver.armed:
            self.counts["rejected_setpoints"] += 1
        self._request(newtons)

    def _on_roll(self, message: Any) -> None:
        self._roll_command(float(message.data), "roll_setpoint")

    def _on_joint_commands(self, message: Any) -> None:
        """ros2_control's command: ``tendon`` effort (N) and ``roll`` position (rad); either
        joint without its field (empty or NaN, as ros2_control leaves what it does not command)
        is no command; another joint is counted and ignored."""
        for joint, (position, effort) in commanded(message).items():
            if joint == TENDON_JOINT and effort is not None:
                self._tension_command(effort, f"joint_commands {TENDON_JOINT} effort")
            elif joint == ROLL_JOINT and position is not None:
                self._roll_command(position, f"joint_commands {ROLL_JOINT} position")
            elif joint not in (TENDON_JOINT, ROLL_JOINT):  # theirs with no field: no command
                self.counts["ignored_joint_commands"] += 1
                self._warn(f"joint_commands: {joint!r} is not a joint of this driver; ignored "
                           f"(commands: {TENDON_JOINT} effort in N, {ROLL_JOINT} position in rad)")

    def _roll_command(self, radians: float, source: str) -> None:
        if not math.isfinite(radians):
            self.counts["rejected_rolls"] += 1
            self._warn(f"{source} = {radians!r} rad is not finite; ignored")
            return
        held = self.driver.set_roll(radians)
        if held is None:
            self.counts["rejected_rolls"] += 1
        elif held != radians:
            self.counts["clamped_rolls"] += 1

    def _on_estop(self, _message: Any) -> None:
        self.estop()

    def _cancel_schedule(self) -> None:
        if self.schedule_state in ("waiting", "running"):
            self.schedule_state = "cancelled"

    # --- commands (std_srvs/srv/Trigger services): (carried out, why / what) ------------------
    def estop(self) -> tuple[bool, str]:
        """Release at once (device e-stop, ESTOP latched), disarm, cancel the schedule."""
        self.counts["estops"] += 1
        self.driver.estop()
        self._cancel_schedule()
        return True, "e-stop sent: tendon released, ESTOP latched; call clear_faults to arm again"

    def release(self) -> tuple[bool, str]:
        """Slacken the tendon (mode R) and cancel the schedule; ``clear_faults`` holds again."""
        self.driver.release()
        self._cancel_schedule()
        return True, "released: tendon slack; call clear_faults to hold tension again"

    def clear_faults(self) -> tuple[bool, str]:
        """The operator's arm command: clear faults, arm, re-enable if ``enabled``; a managed
        node arms only when active (``activate`` is its arm command)."""
        if self.lifecycle is not None and self.lifecycle.state != ACTIVE:
            return False, (f"refused: lifecycle state {self.lifecycle.label}; activate arms "
                           "(it clears the faults)")
        return self._arm()

    def _arm(self) -> tuple[bool, str]:
        if not self.driver.clear_faults():
            return False, (f"refused: link {self.driver.link.value}; clear_faults needs the "
                           "device connected")
        if bool(self.port.get_parameter("enabled")):
            self.driver.enable()
        target = self.status.target if self.status else 0.0
        self.port.logger.info("faults cleared and armed on request (target %g N)", target)
        return True, (f"faults cleared and armed at target {target:g} N (the device keeps a "
                      f"fault while still over its trip); a new setpoint is needed for tension")

    def start_schedule(self) -> tuple[bool, str]:
        """(Re)start the ``schedule.*`` staircase, or wait for the link; refused while disarmed
        or with a fault latched, naming it."""
        status = self.status
        latest = status.telemetry if status else None
        if not self.driver.armed:
            reason = self.driver.disarm_reason
            self.port.logger.warning("start_schedule refused: disarmed (%s)", reason)
            return False, (f"refused: disarmed ({reason}); the tendon stays released; call "
                           f"clear_faults first")
        if latest is not None and latest.faults:
            return False, (f"refused: fault latched ({fault_names(latest.faults)}, tension "
                           f"{latest.tension:.1f} N, tension_max {self.driver.tension_max:g} N); "
                           f"call clear_faults first")
        if status is None or status.link is not LinkState.CONNECTED:
            self.schedule_state = "waiting"
            return True, "waiting for the device link; the schedule starts once connected"
        return self._run_schedule()

    def _run_schedule(self) -> tuple[bool, str]:
        for level in self.schedule.levels:
            if level > self.driver.tension_max:
                self.counts["clamped_setpoints"] += 1
        if not self.driver.run_schedule(self.schedule):
            self.schedule_state = "cancelled"
            return False, f"refused: {self.last_warning}"
        self.schedule_state = "running"
        text = (f"schedule started: {list(self.schedule.levels)} N, {self.schedule.hold:g} s "
                f"each, {self.schedule.trials} trial(s)")
        self.port.logger.info("%s", text)
        return True, text

    # --- the step ---------------------------------------------------------------------------
    # --- lifecycle (managed: true) ---------------------------------------------------------
    def _configure(self) -> None:
        try:
            self.driver.open_link()
        except PortError as error:
            raise TransitionFailed(f"port {self.driver.config.port}: {error}") from error

    def _activate(self) -> None:
        armed, message = self._arm()
        if not armed:
            raise TransitionFailed(message)

    def _deactivate(self) -> None:
        self.driver.release()
        self._cancel_schedule()
        self.driver.disarm(NOT_ACTIVE)

    def _close(self) -> None:
        self._cancel_schedule()
        self.driver.disarm(NOT_ACTIVE)
        self.driver.close()
        self.status = None

    def step(self) -> None:
        """Step the driver; publish every telemetry frame received (a managed node: only while
        configured)."""
        if self.lifecycle is not None and self.lifecycle.state not in (INACTIVE, ACTIVE):
            return
        self._watch_graph()
        try:
            result = self.driver.step()
        except ProtocolVersionError as error:
            self.counts["version_mismatches"] += 1
            self.last_warning = str(error)
            self.port.logger.error("%s", error)
            return
        previous, self.status = self.status, result.status
        if previous is None or previous.link is not result.status.link:
            self._log_link(result.status)
        if previous is not None and previous.armed and not result.status.armed \
                and self.schedule_state in ("waiting", "running"):
            self.schedule_state = "cancelled"
        if result.telemetry or result.joints:
            self._publish_frames(result.telemetry, result.joints)
        connected = result.status.link is LinkState.CONNECTED
        if self.schedule_state == "waiting" and connected:
            self._run_schedule()
        elif self.schedule_state == "running" and not self.driver.schedule_running:
            self.schedule_state = "done"
            self.port.logger.info("schedule done")

    def _watch_graph(self) -> None:
        """Every :data:`GRAPH_CHECK_PERIOD_S` s: after ``safety.graph_timeout_s`` s without a
        graph (no zenoh router: no operator can reach the node, not even with an e-stop) the
        driver releases the tendon and stays disarmed until ``clear_faults``. A shorter gap,
        seen by a look or by the routers being new ones (a router restarted between two looks),
        holds the tendon but is counted (``graph_interruptions``) and warned about: what was
        sent to the node meanwhile may be lost."""
        now = self._clock()
        if now - self._graph_checked < GRAPH_CHECK_PERIOD_S:
            return
        self._graph_checked = now
        hubs = self.port.graph_hubs()
        if not hubs:
            self._graph_missing = True
            if not self._graph_lost and now - self._graph_seen >= self.graph_timeout:
                self._graph_lost = True
                self.counts["graph_losses"] += 1
                self.driver.disarm(f"graph lost: no zenoh router for "
                                   f"{now - self._graph_seen:.1f} s")
            return
        restarted = bool(self._hubs) and hubs.isdisjoint(self._hubs)
        if self._graph_lost:
            self.port.logger.warning("graph back; the tendon stays released until clear_faults")
        elif self._graph_missing or restarted:
            self.counts["graph_interruptions"] += 1
            self._warn(f"graph interrupted for less than safety.graph_timeout_s = "
                       f"{self.graph_timeout:g} s ({'a new router' if restarted else 'the router back'}"
                       "): messages sent to the node meanwhile may be lost; the tendon is held")
        self._graph_seen, self._graph_lost, self._graph_missing = now, False, False
        self._hubs = hubs

    def _log_link(self, status: DriverStatus) -> None:
        if status.link is LinkState.CONNECTED and status.banner is not None:
            self.port.logger.info("link connected: firmware %s, load cell %s, watchdog %g s",
                                  status.banner.firmware, status.banner.cell,
                                  status.banner.watchdog)
        elif status.link is LinkState.DISCONNECTED:
            self.port.logger.warning("link down: %s", status.message)

    def _publish_frames(self, frames: tuple[Telemetry, ...], joints: tuple[RollState, ...]
                        ) -> None:
        """``tension`` for every telemetry frame, ``joint_states`` for every roll sample;
        stamp = the host time the device took it (:class:`DeviceClockMap`), never after now nor
        before the topic's previous stamp."""
        now = self.port.now_ns()
        self.clock_map.observe(max([frame.time for frame in frames]
                                   + [joint.time for joint in joints]), now)
        frame_id = robot_frame(self.frame_prefix, str(self.port.get_parameter("frame_id")))
        for frame in frames:
            self.tension.publish(from_dict("geometry_msgs/msg/WrenchStamped", {
                "header": header(self._stamp("tension", now, frame.time), frame_id),
                "wrench": {"force": {"z": frame.tension}}}))
        # both joints on joint_states in device-time order (a stamp never goes back)
        samples = sorted([(frame.time, 0, frame.tension) for frame in frames]
                         + [(joint.time, 1, joint.position) for joint in joints])
        for device_s, is_roll, value in samples:
            stamp = self._stamp("joint_states", now, device_s)
            self.joints.publish(joint_state(stamp, value) if is_roll else tendon_effort(stamp, value))
        self.counts["telemetry_frames"] += len(frames)

    def _stamp(self, topic: str, now: int, device_s: float) -> int:
        """The host time (ns) of device time ``device_s``, at most ``now`` and raised to
        ``topic``'s previous stamp (stamps never go back)."""
        stamp = max(min(self.clock_map.host_ns(device_s), now), self._last_stamp_ns[topic])
        self._last_stamp_ns[topic] = stamp
        return stamp

    # --- state and diagnostics ----------------------------------------------------------------
    def _check_actuator(self) -> Status:
        clamped = self.clamps.recent(self.counts["clamped_setpoints"], self.port.now_ns())
        return actuator(self.status, tension_max=self.driver.tension_max,
                        roll_max=self.driver.config.roll_max,
                        schedule_state=self.schedule_state, counts=self.counts,
                        last_warning=self.last_warning, clamped_recently=clamped)

    def publish_state(self) -> None:
        """Publish ``device_state`` (deprecated): the components' statuses rolled into one."""
        rolled = summary(self.diagnostics.statuses(), self.port.node_name,
                         str(self.port.get_parameter("port")))
        self.state.publish(from_dict(STATUS_TYPE, rolled))

    def close(self) -> None:
        """Release the tendon and close the port."""
        self.driver.close()
        self.port.logger.info("tendon released, port closed")


def _answering(command: Callable[[], tuple[bool, str]]) -> Callable[[Any], Any]:
    """A ``std_srvs/srv/Trigger`` handler running ``command``."""
    def handle(_request: Any) -> Any:
        success, message = command()
        return from_dict(f"{TRIGGER}_Response", {"success": success, "message": message})
    return handle


def _non_empty(name: str) -> Any:
    def check(value: Any) -> None:
        if not str(value).strip():
            raise InputError(f"{name} = {value!r} is invalid; allowed: a non-empty path or URL",
                             parameter=name, value=value, allowed="a non-empty path or URL")
    return check


def main() -> int:
    """``ros2 run tdcm_ros tension_driver`` / ``tension_driver`` console script."""
    return main_for(TensionDriverNode)


if __name__ == "__main__":
    sys.exit(main())
