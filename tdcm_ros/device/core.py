"""The device's control and protocol logic in Python: a line-for-line twin of the firmware core.

``firmware/tdcm_tension/tension_core.cpp`` is the C++ original; both run the shared transcripts in
``test/device/transcripts``. All arithmetic is in integers (mN, us, ms, 1e-3 us for the integral)
with C's truncating division, so both sides produce identical telemetry.

Control (every ``CONTROL_PERIOD_MS``): tension = (raw - tare) * 1e6 / scale [mN]; checks for a
stale load cell, over-tension and host silence latch faults and release; in mode T a PI law
``pulse = PULSE_RELEASE + KP*e + I`` is clamped to the pulse range and slew-limited, and the
integral is frozen while the output is limited in the direction of the error (anti-windup).
The roll servo's position slews toward its target by at most ``ROLL_SLEW_MRAD_PER_TICK`` per
tick; a trip fault stops it where it is (target = position) and R is refused until C.
"""

from __future__ import annotations

from collections.abc import Callable

from tdcm_ros.device import constants as c
from tdcm_ros.device.errors import FrameError
from tdcm_ros.device.protocol import (
    COMMAND_TYPES,
    Ack,
    Banner,
    Calibrate,
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
    Tare,
    Telemetry,
    encode,
)

TRIP_FAULTS = Fault.OVER_TENSION | Fault.WATCHDOG | Fault.ESTOP | Fault.SENSOR


def cdiv(a: int, b: int) -> int:
    """Integer division truncating toward zero, as in C."""
    q = abs(a) // abs(b)
    return q if (a < 0) == (b < 0) else -q


def clamp(value: int, low: int, high: int) -> int:
    """``value`` limited to ``[low, high]``."""
    return max(low, min(value, high))


def crc8(data: bytes) -> int:
    """CRC-8, polynomial 0x07, initial value 0 (the EEPROM record's check byte)."""
    crc = 0
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = ((crc << 1) ^ 0x07) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def pack_calibration(tare: int, scale_mcpn: int) -> bytes:
    """The EEPROM calibration record: magic, tare, scale (little endian), CRC-8."""
    payload = (c.EEPROM_MAGIC.to_bytes(2, "little") + tare.to_bytes(4, "little", signed=True)
               + scale_mcpn.to_bytes(4, "little", signed=True))
    return payload + bytes([crc8(payload)])


def unpack_calibration(record: bytes) -> tuple[int, int] | None:
    """``(tare, scale_mcpn)`` from a record, or ``None`` if it is blank or corrupt."""
    if len(record) != c.EEPROM_RECORD_SIZE or crc8(record[:-1]) != record[-1] \
            or int.from_bytes(record[:2], "little") != c.EEPROM_MAGIC:
        return None
    scale = int.from_bytes(record[6:10], "little", signed=True)
    if not c.SCALE_MIN_MCPN <= scale <= c.SCALE_MAX_MCPN:
        return None
    return int.from_bytes(record[2:6], "little", signed=True), scale


class TensionCore:
    """Protocol + control state machine of the tension device, driven with times in ms.

    ``storage`` is the EEPROM (a mutable byte buffer of ``EEPROM_RECORD_SIZE``); ``send`` gets
    every line the device writes. Call :meth:`boot` once, then :meth:`receive`, :meth:`sample`
    and :meth:`tick` as bytes, load-cell readings and time arrive.
    """

    def __init__(self, storage: bytearray, *, cell: str, send: Callable[[bytes], None]) -> None:
        self.storage = storage
        self.cell = cell
        self.send = send
        self.decoder = LineDecoder(accept=COMMAND_TYPES, on_reject=self._on_reject)
        self.mode = Mode.RELEASE
        self.faults = Fault(0)
        self.setpoint_mn = 0
        self.pulse_us = c.PULSE_RELEASE_US
        self.integral_mus = 0
        self.raw = 0
        self.tension_mn = 0
        self.roll_target_mrad = 0   #: where the roll servo is going
        self.roll_mrad = 0          #: where its pulse points now (slew-limited)
        self.roll_engaged = False   #: an R was accepted since boot: J frames follow every T
        self.have_sample = False
        self.sample_ms = 0
        self.last_rx_ms = 0
        self.last_control_ms = 0
        self.tare = c.DEFAULT_TARE
        self.scale_mcpn = c.DEFAULT_SCALE_MCPN

    # --- life cycle -----------------------------------------------------------------------
    def boot(self, now_ms: int) -> None:
        """Load calibration, release, and send the banner."""
        calibration = unpack_calibration(bytes(self.storage))
        if calibration is None:
            self.faults |= Fault.CALIBRATION
        else:
            self.tare, self.scale_mcpn = calibration
        self.sample_ms = self.last_rx_ms = self.last_control_ms = now_ms
        self._banner()

    def _banner(self) -> None:
        self.send(encode(Banner(firmware=c.FIRMWARE_VERSION, cell=self.cell,
                                control_period=c.CONTROL_PERIOD_MS / 1000,
                                watchdog=c.WATCHDOG_MS / 1000,
                                setpoint_max=c.SETPOINT_MAX_MN / 1000, trip=c.TRIP_MN / 1000)))

    def _release(self) -> None:
        self.mode = Mode.RELEASE
        self.pulse_us = c.PULSE_RELEASE_US
        self.integral_mus = 0

    # --- inputs ---------------------------------------------------------------------------
    def sample(self, raw: int, now_ms: int) -> None:
        """A fresh load-cell reading in counts."""
        self.raw = raw
        self.have_sample = True
        self.sample_ms = now_ms

    def receive(self, data: bytes, now_ms: int) -> None:
        """Bytes from the host."""
        for message in self.decoder.feed(data):
            self.last_rx_ms = now_ms
            if isinstance(message, Command):  # always: the decoder accepts commands only
                self._execute(message)

    def _on_reject(self, error: FrameError) -> None:
        if error.reason is not Reject.NOISE:
            self.send(encode(Nack(error.command or "?", error.reason)))

    def _refuse(self, letter: str, reason: Reject) -> None:
        self.send(encode(Nack(letter, reason)))

    def _execute(self, command: Command) -> None:
        match command:
            case Heartbeat():
                return
            case Info():
                self._banner()
                return
            case SetSetpoint(newtons=n):
                self.setpoint_mn = round(n * 1000)
            case SetMode(mode=Mode.TENSION):
                if self.faults:
                    return self._refuse("M", Reject.FAULT)
                if self.mode is Mode.RELEASE:
                    self.mode = Mode.TENSION
                    self.integral_mus = 0
            case SetMode(mode=Mode.RELEASE):
                self._release()
            case SetRoll(radians=r):
                if self.faults & TRIP_FAULTS:
                    return self._refuse("R", Reject.FAULT)
                self.roll_target_mrad = round(r * 1000)
                self.roll_engaged = True
            case EStop():
                self._release()
                self.faults |= Fault.ESTOP
            case ClearFaults():
                if self.tension_mn > c.TRIP_MN:
                    return self._refuse("C", Reject.FAULT)
                self.faults &= Fault.CALIBRATION
            case Tare() | Calibrate():
                letter = "Z" if isinstance(command, Tare) else "K"
                if self.mode is Mode.TENSION:
                    return self._refuse(letter, Reject.MODE)
                if not self.have_sample or self.faults & Fault.SENSOR:
                    return self._refuse(letter, Reject.FAULT)
                if isinstance(command, Tare):
                    self.tare = self.raw
                else:
                    scale = cdiv((self.raw - self.tare) * 1_000_000, round(command.newtons * 1000))
                    if not c.SCALE_MIN_MCPN <= scale <= c.SCALE_MAX_MCPN:
                        return self._refuse(letter, Reject.RANGE)
                    self.scale_mcpn = scale
                    self.faults &= ~Fault.CALIBRATION
                self.storage[:] = pack_calibration(self.tare, self.scale_mcpn)
        self.send(encode(Ack(_LETTER[type(command)])))

    # --- time -----------------------------------------------------------------------------
    def tick(self, now_ms: int) -> None:
        """Run the control step if a period has elapsed since the last one."""
        if (now_ms - self.last_control_ms) & 0xFFFFFFFF < c.CONTROL_PERIOD_MS:
            return
        self.last_control_ms = now_ms
        self.tension_mn = clamp(cdiv((self.raw - self.tare) * 1_000_000, self.scale_mcpn),
                                -c.TENSION_LIMIT_MN, c.TENSION_LIMIT_MN)
        if (now_ms - self.sample_ms) & 0xFFFFFFFF > c.SENSOR_TIMEOUT_MS:
            self.faults |= Fault.SENSOR
        if self.tension_mn > c.TRIP_MN:
            self.faults |= Fault.OVER_TENSION
        if self.mode is Mode.TENSION and (now_ms - self.last_rx_ms) & 0xFFFFFFFF >= c.WATCHDOG_MS:
            self.faults |= Fault.WATCHDOG
        if self.faults & TRIP_FAULTS:
            self._release()
            self.roll_target_mrad = self.roll_mrad  # the roll servo holds where it is
        if self.mode is Mode.TENSION:
            self._control()
        self.roll_mrad += clamp(self.roll_target_mrad - self.roll_mrad,
                                -c.ROLL_SLEW_MRAD_PER_TICK, c.ROLL_SLEW_MRAD_PER_TICK)
        stamp = (now_ms & 0xFFFFFFFF) / 1000
        self.send(encode(Telemetry(time=stamp, raw=self.raw, tension=self.tension_mn / 1000,
                                   pulse_us=self.pulse_us, mode=self.mode, faults=self.faults)))
        if self.roll_engaged:
            self.send(encode(RollState(time=stamp, target=self.roll_target_mrad / 1000,
                                       position=self.roll_mrad / 1000,
                                       pulse_us=self.roll_pulse_us)))

    @property
    def roll_pulse_us(self) -> int:
        """The roll servo's pulse for the current roll, in us."""
        return clamp(c.ROLL_PULSE_CENTER_US + cdiv(self.roll_mrad * c.ROLL_US_PER_RAD, 1000),
                     c.ROLL_PULSE_MIN_US, c.ROLL_PULSE_MAX_US)

    def _control(self) -> None:
        error = self.setpoint_mn - self.tension_mn
        proportional = cdiv(error * c.KP_US_PER_N, 1000)
        integral = clamp(self.integral_mus + cdiv(error * c.KI_US_PER_NS * c.CONTROL_PERIOD_MS, 1000),
                         -c.INTEGRAL_LIMIT_MUS, c.INTEGRAL_LIMIT_MUS)
        wanted = c.PULSE_RELEASE_US + proportional + cdiv(integral, 1000)
        limited = clamp(clamp(wanted, c.PULSE_MIN_US, c.PULSE_MAX_US),
                        self.pulse_us - c.SLEW_US_PER_TICK, self.pulse_us + c.SLEW_US_PER_TICK)
        if not ((wanted > limited and error > 0) or (wanted < limited and error < 0)):
            self.integral_mus = integral
        self.pulse_us = limited


_LETTER: dict[type, str] = {SetSetpoint: "S", SetMode: "M", Tare: "Z", Calibrate: "K",
                            EStop: "E", ClearFaults: "C", SetRoll: "R"}
