"""Transport-free logic of the ``tension_driver`` node.

:class:`TensionDriver` owns one device link. The caller supplies the clock (s) and, optionally,
the port opener, then calls :meth:`.TensionDriver.step` periodically (every 5-10 ms); each call
reads what the device sent, runs the link state machine and returns a :class:`StepResult`: the
telemetry frames received (publish each as ``tension``) and a :class:`DriverStatus` (device
state and a diagnostics level + message). Nothing blocks and nothing sleeps.

Link: open -> send ``I`` (repeated every 0.5 s) until a banner arrives (``handshake_timeout``);
a banner of another protocol version raises :class:`.ProtocolVersionError`. While connected the
driver sends a heartbeat every ``heartbeat_period``, ramps the commanded setpoint toward the
target at ``setpoint_rate`` N/s, and asks for mode T while enabled and the device is released
without faults. Port failures, a missing banner or ``link_timeout`` s without telemetry close
the port and retry after an exponential backoff (``backoff_initial`` doubling to
``backoff_max``). Device faults (watchdog, over-tension, e-stop, sensor) are never cleared
automatically: call :meth:`.TensionDriver.clear_faults`.

Roll: :meth:`.TensionDriver.set_roll` clamps a roll target to ``[-roll_max, roll_max]`` (with a
warning) and the driver slews the roll it sends (``R``) at ``roll_rate`` rad/s from the roll the
device reports (a request waits until that is known). Nothing is sent for the roll before a first
request, so the servo stays where it is; a trip fault on the device (it stops the servo and
refuses ``R`` until ``C``) drops the target and refuses new ones, like a disarm. The device's roll
comes back in ``J`` frames after every ``T`` once it has accepted an ``R``; before that (two ``T``
in a row) it holds its boot position 0 rad. :attr:`StepResult.joints` holds
one :class:`~tdcm_ros.device.protocol.RollState` per telemetry tick: the ``J`` frame, or the boot
position; none while it is not yet known which (the first ``T`` after a banner).

Arming: the driver starts armed. It disarms -- target and setpoint 0 N, schedule cancelled, mode
R sent, setpoints, schedules and roll targets refused, the roll left where the device holds it --
on an e-stop and on every event after which the device's
state is unknown: the link lost while connected (port error, ``link_timeout``, a version
mismatch), a device reboot (its clock running backwards, after a banner nobody asked for or
not)
and a freeze (no telemetry for the device's own watchdog time while the host kept stepping, and
the device's clock ran that long between its frames: a step counts at most ``heartbeat_period`` s
of silence, so a stall of this host -- the device's frames not read -- is not taken for one, nor
frames delayed while the device's clock stood still -- a stalled line, a twin not scheduled).
Disarmed, it commands mode R whatever the device reports. Only :meth:`.TensionDriver.clear_faults`
(the operator's arm command, accepted while connected) arms it again, at a target of 0 N: a new
setpoint is needed before any tension.
"""

from __future__ import annotations

import enum
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

from tdcm_ros.device import constants as c
from tdcm_ros.device.core import TRIP_FAULTS
from tdcm_ros.device.errors import (
    DeviceInputError,
    FrameError,
    PortError,
    ProtocolVersionError,
)
from tdcm_ros.device.protocol import (
    DEVICE_TYPES,
    Ack,
    Banner,
    ClearFaults,
    Command,
    EStop,
    Fault,
    Heartbeat,
    Info,
    LineDecoder,
    Mode,
    Nack,
    Reject,
    RollState,
    SetMode,
    SetRoll,
    SetSetpoint,
    Telemetry,
    encode,
)
from tdcm_ros.device.schedule import StepSchedule
from tdcm_ros.device.transport import Transport, open_transport
from tdcm_ros.errors import out_of_range
from tdcm_ros.spec import check_fields, spec_field, specs_of

_LOG = logging.getLogger(__name__)
INFO_RETRY = 0.5        #: s between banner requests during the handshake
SETPOINT_PERIOD = 0.02  #: s, shortest interval between two setpoint commands
MODE_RETRY = 0.2        #: s between two mode requests
REJECT_LOG_PERIOD = 1.0  #: s, shortest interval between two warnings about rejected lines
CLOCK_WRAP = 2**32 / 1000  #: s, the device clock (u32 ms) wraps after this


class LinkState(enum.Enum):
    """State of the link to the device."""

    DISCONNECTED = "disconnected"
    HANDSHAKING = "handshaking"
    CONNECTED = "connected"


class Level(enum.IntEnum):
    """Diagnostics level, numerically equal to ``diagnostic_msgs/DiagnosticStatus``."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


@dataclass(frozen=True)
class DriverConfig:
    """Driver parameters (SI: N, N/s, s). ``port`` is a device path, pty path or pyserial URL."""

    port: str = spec_field("/dev/ttyACM0", description="device path, pty path or pyserial URL")
    baudrate: int = spec_field(c.BAUD_RATE, unit="baud", low=1200, high=4_000_000,
                               description="serial line rate")
    tension_max: float = spec_field(20.0, unit="N", low=0.001, high=c.SETPOINT_MAX_MN / 1000,
                                    description="largest setpoint")
    setpoint_rate: float = spec_field(40.0, unit="N/s", low=0.1, high=1000.0,
                                      description="setpoint ramp rate")
    heartbeat_period: float = spec_field(
        0.1, unit="s", low=0.01, high=c.WATCHDOG_MS / 2000, high_open=True,
        description="heartbeat period, below half the device watchdog")
    handshake_timeout: float = spec_field(3.0, unit="s", low=0.1, high=60.0,
                                          description="time allowed for the banner")
    stale_timeout: float = spec_field(0.25, unit="s", low=0.02, high=10.0,
                                      description="telemetry age reported as stale")
    link_timeout: float = spec_field(2.0, unit="s", low=0.1, high=60.0,
                                     description="telemetry silence that drops the link")
    backoff_initial: float = spec_field(0.5, unit="s", low=0.01, high=60.0,
                                        description="first reconnect delay")
    backoff_max: float = spec_field(8.0, unit="s", low=0.01, high=600.0,
                                    description="largest reconnect delay")
    roll_max: float = spec_field(math.pi / 2, unit="rad", low=0.0, high=c.ROLL_MAX_MRAD / 1000,
                                 description="largest |roll| target")
    roll_rate: float = spec_field(
        1.0, unit="rad/s", low=0.01, high=c.ROLL_SLEW_MRAD_PER_TICK / c.CONTROL_PERIOD_MS,
        description="roll slew rate (the device's own limit is 2 rad/s)")

    def __post_init__(self) -> None:
        check_fields(self, DRIVER_SPECS, error=DeviceInputError)
        if self.backoff_max < self.backoff_initial:
            raise out_of_range("backoff_max", self.backoff_max, f">= backoff_initial "
                               f"({self.backoff_initial})", unit="s", error=DeviceInputError)


#: Specs of the driver parameters, by field name.
DRIVER_SPECS = specs_of(DriverConfig)


@dataclass(frozen=True)
class DriverStatus:
    """Snapshot for the device-state topic and ``/diagnostics``."""

    link: LinkState
    level: Level
    message: str
    target: float                 #: N, requested setpoint after clamping
    setpoint: float               #: N, setpoint last sent (ramped toward ``target``)
    enabled: bool                 #: the driver wants the device in mode T
    armed: bool                   #: False: held released until clear_faults (see the module)
    disarm_reason: str            #: why it was disarmed last ("" while never disarmed)
    telemetry: Telemetry | None   #: latest frame
    banner: Banner | None
    reconnects: int               #: links lost since start
    rejected_lines: int           #: malformed lines from the device
    nacks: int                    #: commands the device refused
    disarms: int                  #: times the driver disarmed since start
    roll: RollState | None = None        #: latest roll of the device (None: not known yet)
    roll_target: float | None = None     #: rad, requested roll after clamping (None: none)
    roll_setpoint: float | None = None   #: rad, roll last slewed toward the target


@dataclass(frozen=True)
class StepResult:
    """What one :meth:`.TensionDriver.step` produced."""

    telemetry: tuple[Telemetry, ...]
    status: DriverStatus
    joints: tuple[RollState, ...] = ()  #: the roll at each telemetry tick known this step


def fault_names(faults: Fault) -> str:
    """``'WATCHDOG|ESTOP'`` style text for a fault set."""
    return "|".join(flag.name or "" for flag in Fault if flag in faults)


class TensionDriver:
    """Link to one tension device; see the module docstring for the behaviour.

    ``clock`` returns the time in s (monotonic); ``open_port`` opens a :class:`Transport` for
    ``config.port`` (default: :func:`.open_transport`); ``warn`` receives warnings (clamped
    setpoints, refused commands, lost links; default: this module's logger).
    """

    def __init__(self, config: DriverConfig, *, clock: Callable[[], float],
                 open_port: Callable[[str], Transport] | None = None,
                 warn: Callable[[str], None] | None = None) -> None:
        self.config = config
        self._clock = clock
        self._open_port = open_port or (lambda url: open_transport(url, baudrate=config.baudrate))
        self._warn = warn or _LOG.warning
        self._transport: Transport | None = None
        self._decoder = LineDecoder(accept=DEVICE_TYPES)
        self._link = LinkState.DISCONNECTED
        self._link_error = "not opened yet"
        self._next_attempt = clock()
        self._backoff = config.backoff_initial
        self._reconnects = 0
        self._nacks = 0
        self._rejected = 0
        self._version_error: FrameError | None = None
        self._banner: Banner | None = None
        self._latest: Telemetry | None = None
        self._enabled = False
        self._armed = True
        self._disarm_reason = ""
        self._disarms = 0
        self._info_pending = 0      # banner requests not yet answered
        self._banner_unexplained = False  # a banner nobody asked for: the next frame decides
        self._silent = False        # the host saw the device silent for its watchdog time
        self._awake_silence = 0.0   # s without telemetry counted while the host kept stepping
        self._rejects_unlogged = 0  # rejected lines since the last warning about them
        self._next_reject_log = clock()
        self._target = 0.0
        self._setpoint = 0.0
        self._sent_setpoint: float | None = None
        self._schedule: StepSchedule | None = None
        self._schedule_start = 0.0
        self._roll: RollState | None = None     # the latest J frame or boot position
        self._roll_engaged: bool | None = None  # the device sends J frames (None: not known)
        self._t_without_j = False               # the last frame was a T, no J after it yet
        self._joints: list[RollState] = []      # roll samples of the current step
        self._roll_target: float | None = None
        self._roll_setpoint: float | None = None
        self._sent_roll: float | None = None
        self._last_roll_send = self._last_roll_ramp = clock()
        now = clock()
        self._since = now  # start of the current link phase
        self._last_rx = self._last_heartbeat = self._last_setpoint = self._last_mode = now
        self._last_ramp = self._last_info = self._last_step = now

    # --- public commands ------------------------------------------------------------------
    @property
    def tension_max(self) -> float:
        """Largest setpoint, in N: the configured maximum or the device's, whichever is lower."""
        if self._banner is None:
            return self.config.tension_max
        return min(self.config.tension_max, self._banner.setpoint_max)

    def _clamp(self, newtons: float, what: str) -> float:
        if not math.isfinite(newtons):
            raise out_of_range(what, newtons, "a finite number", unit="N", error=DeviceInputError)
        clamped = min(max(newtons, 0.0), self.tension_max)
        if clamped != newtons:
            self._warn(f"{what} = {newtons:g} N is out of range [0, {self.tension_max:g}] N; "
                       f"clamped to {clamped:g} N")
        return clamped

    def set_setpoint(self, newtons: float) -> float:
        """Request a tension (N); cancels a running schedule. Returns the target now held, in N:
        the clamped value, or 0 N while disarmed (the request is refused with a warning)."""
        self._schedule = None
        clamped = self._clamp(newtons, "setpoint")
        if self._refused_while_disarmed(f"setpoint = {newtons:g} N"):
            return self._target
        self._target = clamped
        return self._target

    def run_schedule(self, schedule: StepSchedule) -> bool:
        """Follow ``schedule`` from now on (levels above the maximum are clamped, with a warning).
        Returns False (with a warning) while disarmed: nothing runs."""
        if self._refused_while_disarmed("the schedule"):
            return False
        for level in sorted(set(schedule.levels)):
            self._clamp(level, "schedule level")
        self._schedule = schedule
        self._schedule_start = self._clock()
        return True

    def set_roll(self, radians: float) -> float | None:
        """Request a roll (rad), clamped to ``[-roll_max, roll_max]`` with a warning; slewed at
        ``roll_rate``. Returns the roll target now held (the clamped value), or None when refused
        with a warning: while disarmed or with a trip fault latched (the roll holds)."""
        limit = self.config.roll_max
        if not math.isfinite(radians):
            raise out_of_range("roll", radians, "a finite number", unit="rad",
                               error=DeviceInputError)
        clamped = min(max(radians, -limit), limit)
        if clamped != radians:
            self._warn(f"roll = {radians:g} rad is out of range [{-limit:g}, {limit:g}] rad; "
                       f"clamped to {clamped:g} rad")
        if self._refused_while_disarmed(f"roll = {radians:g} rad", what_stays="the roll holds"):
            return None
        if self._roll_faults():
            self._roll_target = self._roll_setpoint = None
            self._warn(f"roll = {radians:g} rad refused: device fault "
                       f"{fault_names(self._roll_faults())}; the roll holds until clear_faults")
            return None
        self._roll_target = clamped
        return clamped

    def _roll_faults(self) -> Fault:
        """The latched faults that stop the device's roll servo (it refuses R until C)."""
        return self._latest.faults & TRIP_FAULTS if self._latest is not None else Fault(0)

    def _refused_while_disarmed(self, what: str, *,
                                what_stays: str = "the tendon stays released") -> bool:
        if self._armed:
            return False
        self._warn(f"{what} refused: disarmed ({self._disarm_reason}); {what_stays} until "
                   f"clear_faults, then needs a new setpoint")
        return True

    @property
    def link(self) -> LinkState:
        """The link's state now."""
        return self._link

    @property
    def armed(self) -> bool:
        """False while the driver holds the device released until :meth:`clear_faults`."""
        return self._armed

    @property
    def disarm_reason(self) -> str:
        """Why the driver was disarmed last (``""`` while never disarmed)."""
        return self._disarm_reason

    @property
    def schedule_running(self) -> bool:
        """True while a schedule is being followed."""
        return self._schedule is not None

    def enable(self) -> None:
        """Ask for closed-loop tension (mode T) whenever the device is released without faults."""
        self._enabled = True

    def release(self) -> None:
        """Ask for mode R (tendon slack) now."""
        self._enabled = False
        self._send_now(SetMode(Mode.RELEASE))

    def estop(self) -> None:
        """Release at once: send ``E`` (latching the device's ESTOP fault), then disarm and
        disable. Without a link the device's watchdog releases it."""
        self._enabled = False
        self._send_now(EStop())
        self._disarm("e-stop", send_release=False)  # E has released it

    def disarm(self, reason: str) -> None:
        """Release now and hold the device released until :meth:`clear_faults` (a fault seen
        outside the link, e.g. the node's graph lost); nothing if already disarmed."""
        if self._armed:
            self._disarm(reason)

    def clear_faults(self) -> bool:
        """The operator's arm command: clear the device's latched faults (the device refuses
        while over the trip) and arm the driver at its current target (0 N after a disarm).
        Refused with a warning, returning False, while the link is not connected."""
        if self._link is not LinkState.CONNECTED:
            self._warn(f"clear_faults refused: link {self._link.value}")
            return False
        self._send_now(ClearFaults())
        if not self._armed:
            self._armed = True
            self._warn(f"armed by clear_faults (was disarmed: {self._disarm_reason}); target "
                       f"{self._target:g} N")
        return True

    def _disarm(self, reason: str, *, send_release: bool = True) -> None:
        """Hold the device released until :meth:`clear_faults`: target and setpoint 0 N,
        schedule cancelled, mode R sent at once if ``send_release`` (best effort; repeated while
        the device reports mode T)."""
        self._armed, self._disarm_reason = False, reason
        self._disarms += 1
        self._schedule = None
        self._target = self._setpoint = 0.0
        self._sent_setpoint = None
        self._roll_target = self._roll_setpoint = self._sent_roll = None  # the roll holds
        self._warn(f"disarmed: {reason}; tendon held released until clear_faults")
        if send_release and self._transport is not None:
            try:
                self._send(SetMode(Mode.RELEASE))
            except PortError:
                pass  # the next read or write drops the link

    def open_link(self) -> None:
        """Open the port and start the handshake now, whatever the backoff (a managed node's
        configure); raises :class:`PortError` naming why the port did not open."""
        self._connect(self._clock())
        if self._transport is None:
            raise PortError(self._link_error)

    def close(self) -> None:
        """Release the tendon (best effort) and close the port."""
        self._enabled = False
        self._send_now(SetMode(Mode.RELEASE))
        self._drop("closed by the host", reconnect=False)

    # --- the step ---------------------------------------------------------------------------
    def step(self) -> StepResult:
        """Do everything due now; raises :class:`.ProtocolVersionError` on a version mismatch."""
        now = self._clock()
        gap, self._last_step = now - self._last_step, now
        received: list[Telemetry] = []
        self._joints = []
        if self._link is LinkState.DISCONNECTED and now >= self._next_attempt:
            self._connect(now)
        if self._transport is not None:
            try:
                self._service(now, min(gap, self.config.heartbeat_period), received)
            except PortError as error:
                self._drop(str(error))
        return StepResult(tuple(received), self._status(now), tuple(self._joints))

    def _connect(self, now: float) -> None:
        try:
            self._transport = self._open_port(self.config.port)
        except PortError as error:
            self._retry_later(now, str(error))
            return
        self._decoder = LineDecoder(accept=DEVICE_TYPES, on_reject=self._on_reject)
        self._link, self._since = LinkState.HANDSHAKING, now
        self._last_info = now
        self._send_info()

    def _send_info(self) -> None:
        """Ask for the banner; the answer is not taken for a reboot."""
        self._send(Info())
        self._info_pending += 1

    def _retry_later(self, now: float, reason: str) -> None:
        self._link_error = reason
        self._next_attempt = now + self._backoff
        self._backoff = min(self._backoff * 2, self.config.backoff_max)

    def _drop(self, reason: str, *, reconnect: bool = True) -> None:
        was_connected, self._link = self._link is LinkState.CONNECTED, LinkState.DISCONNECTED
        if was_connected and reconnect:
            self._reconnects += 1
            self._warn(f"device link lost: {reason}")
        if was_connected:
            self._disarm(f"link lost: {reason}")
        if self._transport is not None:
            self._transport.close()
            self._transport = None
        self._sent_setpoint = None
        self._silent, self._awake_silence = False, 0.0
        self._retry_later(self._clock(), reason)

    def _on_reject(self, error: FrameError) -> None:
        """Count a rejected device line; warn about it at most every ``REJECT_LOG_PERIOD`` s."""
        self._rejected += 1
        if error.reason is Reject.VER:
            self._version_error = error
        self._rejects_unlogged += 1
        now = self._clock()
        if now >= self._next_reject_log:
            self._next_reject_log = now + REJECT_LOG_PERIOD
            self._warn(f"rejected {self._rejects_unlogged} line(s) from the device "
                       f"({self._rejected} in all); last: {error}")
            self._rejects_unlogged = 0

    def _send(self, command: Command) -> None:
        if self._transport is None:
            raise PortError("no port open")
        self._transport.write(encode(command))

    def _send_now(self, command: Command) -> None:
        if self._transport is None:
            return
        try:
            self._send(command)
        except PortError as error:
            self._drop(str(error))

    def _service(self, now: float, awake: float, received: list[Telemetry]) -> None:
        """Read and handle the device's frames, then keep the link; ``awake`` s of the time since
        the last step count as silence (the host's own stall does not)."""
        transport = self._transport
        if transport is None:
            return
        self._awake_silence += awake
        for message in self._decoder.feed(transport.read()):
            self._handle(message, now, received)
        if self._version_error is not None:
            error, self._version_error = self._version_error, None
            self._drop(str(error), reconnect=False)
            raise ProtocolVersionError(
                f"protocol_version = {error.version} sent by {self.config.port!r}; allowed: "
                f"{c.PROTOCOL_VERSION}", parameter="protocol_version", value=error.version,
                allowed=str(c.PROTOCOL_VERSION)) from error
        if self._link is LinkState.HANDSHAKING:
            if now - self._since >= self.config.handshake_timeout:
                self._drop(f"no banner within {self.config.handshake_timeout:g} s")
            elif now - self._last_info >= INFO_RETRY:
                self._last_info = now
                self._send_info()
            return
        if self._latest is not None and self._banner is not None \
                and self._awake_silence >= self._banner.watchdog:
            self._silent = True  # seen while stepping: the device, not this host, stalled
        if now - self._last_rx >= self.config.link_timeout:
            self._drop(f"no telemetry for {now - self._last_rx:.2f} s")
            return
        self._keep_alive(now)

    def _handle(self, message: object, now: float, received: list[Telemetry]) -> None:
        if isinstance(message, Telemetry):
            received.append(message)
            self._on_telemetry(message, now)
            self._roll_tick(message)
        elif isinstance(message, RollState):
            self._roll, self._roll_engaged, self._t_without_j = message, True, False
            self._joints.append(message)
        elif isinstance(message, Ack) and message.command == "R":
            self._roll_engaged = True  # J frames follow from the next tick on
        elif isinstance(message, Banner):
            self._on_banner(message, now)
        elif isinstance(message, Nack):
            self._nacks += 1
            self._warn(f"device refused command {message.command}: {message.reason.value}")

    def _on_telemetry(self, frame: Telemetry, now: float) -> None:
        """Take a frame; a device clock running backwards is a reboot, a frame after the host saw
        the device silent for its watchdog time ends a freeze if the device's own clock ran
        that long too: either disarms. Silence over which the device's clock stood still was
        a delay of its frames (a stalled serial line, a suspended simulator), not a freeze."""
        previous, silence, silent = self._latest, self._awake_silence, self._silent
        self._latest, self._last_rx, self._silent, self._awake_silence = frame, now, False, 0.0
        banner, self._banner_unexplained = self._banner_unexplained, False
        if previous is not None and frame.time < previous.time \
                and previous.time - frame.time < CLOCK_WRAP / 2:
            sent = "it sent a boot banner and " if banner else ""
            self._warn(f"device rebooted: {sent}its clock went back from {previous.time:.3f} s "
                       f"to {frame.time:.3f} s")
            self._forget_roll()
            if self._armed:
                self._disarm("device rebooted")
        elif silent and previous is not None and self._banner is not None:
            ran = (frame.time - previous.time) % CLOCK_WRAP
            if ran >= self._banner.watchdog:
                if self._armed:
                    self._disarm(f"device silent for {silence:.2f} s (frozen?)")
            else:
                self._warn(f"device frames delayed: none for {silence:.2f} s while its clock "
                           f"ran {ran:.3f} s; not a freeze (a stalled serial line or a "
                           f"suspended simulator)")

    def _roll_tick(self, frame: Telemetry) -> None:
        """A ``T`` frame: a ``J`` follows it if the device's roll is engaged; two ``T`` in a row
        show it is not, so it holds its boot position 0 rad."""
        if self._roll_engaged is None and self._t_without_j:
            self._roll_engaged = False
        self._t_without_j = True
        if self._roll_engaged is False:
            self._roll = RollState(frame.time, 0.0, 0.0, c.ROLL_PULSE_CENTER_US)
            self._joints.append(self._roll)

    def _forget_roll(self) -> None:
        """After a banner or a reboot the device's roll is not known until its next frames."""
        self._roll, self._roll_engaged, self._t_without_j = None, None, False
        self._roll_setpoint = self._sent_roll = None

    def _on_banner(self, banner: Banner, now: float) -> None:
        """Complete the handshake. A banner nobody asked for once telemetry has flowed is a
        reboot or the answer to the handshake's request behind a boot banner that took its
        place (a UNO resets when its port is opened; its boot banner and first frames can
        reach the host before the request reaches the device): the device's clock in its next
        frame tells them apart (:meth:`_on_telemetry`: back to 0 after a reboot), and until then
        no mode is sent (:meth:`_keep_alive`), so a rebooted device is never re-tensioned."""
        solicited = self._info_pending > 0
        self._info_pending = max(0, self._info_pending - 1)
        if self._link is LinkState.CONNECTED and not solicited and self._latest is not None:
            self._banner_unexplained = True
        self._forget_roll()
        self._banner, self._link = banner, LinkState.CONNECTED
        self._last_rx = self._last_ramp = now
        self._awake_silence = 0.0
        self._backoff = self.config.backoff_initial
        self._sent_setpoint = None

    def _keep_alive(self, now: float) -> None:
        if now - self._last_heartbeat >= self.config.heartbeat_period:
            self._last_heartbeat = now
            self._send(Heartbeat())
        if self._schedule is not None:
            level = self._schedule.setpoint(now - self._schedule_start)
            if level is None:
                self._schedule = None
            self._target = min(level or 0.0, self.tension_max)
        step = self.config.setpoint_rate * (now - self._last_ramp)
        self._last_ramp = now
        self._setpoint += max(-step, min(step, self._target - self._setpoint))
        if self._sent_setpoint != self._setpoint and now - self._last_setpoint >= SETPOINT_PERIOD:
            self._last_setpoint, self._sent_setpoint = now, self._setpoint
            self._send(SetSetpoint(self._setpoint))
        self._slew_roll(now)
        latest = self._latest
        if latest is None or self._banner_unexplained or now - self._last_mode < MODE_RETRY:
            return
        holding = self._enabled and self._armed
        if holding and latest.mode is Mode.RELEASE and not latest.faults:
            self._last_mode = now
            self._send(SetMode(Mode.TENSION))
        elif not holding and latest.mode is Mode.TENSION:
            self._last_mode = now
            self._send(SetMode(Mode.RELEASE))

    def _slew_roll(self, now: float) -> None:
        """Move the roll setpoint toward the target at ``roll_rate``; send it when it changed."""
        step = self.config.roll_rate * (now - self._last_roll_ramp)
        self._last_roll_ramp = now
        if self._roll_faults():
            self._roll_target = self._roll_setpoint = None  # the device holds; so do we
        if self._roll_setpoint is None and self._roll is not None:
            self._roll_setpoint = self._roll.position  # slew from where the device is
        target, setpoint = self._roll_target, self._roll_setpoint
        if target is None or setpoint is None or not self._armed:
            return
        limit = self.config.roll_max  # a lowered roll_max applies to the held target too
        target = self._roll_target = min(max(target, -limit), limit)
        setpoint += max(-step, min(step, target - setpoint))
        self._roll_setpoint = setpoint
        if self._sent_roll != setpoint and now - self._last_roll_send >= SETPOINT_PERIOD:
            self._last_roll_send, self._sent_roll = now, setpoint
            self._send(SetRoll(setpoint))

    # --- status ------------------------------------------------------------------------------
    def _status(self, now: float) -> DriverStatus:
        latest = self._latest
        if self._link is LinkState.DISCONNECTED:
            level, text = Level.ERROR, (f"disconnected ({self._link_error}); retry in "
                                        f"{max(0.0, self._next_attempt - now):.1f} s")
        elif self._link is LinkState.HANDSHAKING:
            level, text = Level.WARN, f"waiting for the banner on {self.config.port}"
        elif now - self._last_rx > self.config.stale_timeout:
            level, text = Level.STALE, f"no telemetry for {now - self._last_rx:.2f} s"
        elif latest is not None and latest.faults:
            level, text = Level.ERROR, f"device fault {fault_names(latest.faults)}; tendon released"
        elif not self._armed:
            level, text = Level.WARN, (f"disarmed ({self._disarm_reason}): tendon held released; "
                                       f"call clear_faults to arm, then a new setpoint")
        elif latest is not None:
            mode = "tensioning" if latest.mode is Mode.TENSION else "released"
            level, text = Level.OK, (f"{mode}: tension {latest.tension:.3f} N, setpoint "
                                     f"{self._setpoint:.3f} N")
        else:
            level, text = Level.WARN, "connected, no telemetry yet"
        return DriverStatus(link=self._link, level=level, message=text, target=self._target,
                            setpoint=self._setpoint, enabled=self._enabled, armed=self._armed,
                            disarm_reason=self._disarm_reason, telemetry=latest,
                            banner=self._banner, reconnects=self._reconnects,
                            rejected_lines=self._rejected, nacks=self._nacks,
                            disarms=self._disarms, roll=self._roll,
                            roll_target=self._roll_target, roll_setpoint=self._roll_setpoint)
