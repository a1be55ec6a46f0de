"""The tension device's serial line protocol: pure encode/decode, no I/O.

Wire format (protocol version 1 with the roll extension, 115200 baud 8N1, ASCII)::

    $<version>,<type>[,<field>...]*<HH>\\n

``HH`` is the XOR of every byte between ``$`` and ``*``, as two upper-case hex digits.
A frame is at most 80 bytes from ``$`` through ``HH`` (the ``\\n`` excluded); body bytes are
printable ASCII (0x20-0x7E) other than ``$`` and ``*``. Fields are never empty. Decimal
newtons are written with exactly three decimals (millinewton resolution).

Host -> device (commands):

====  ===================  ==========================================================
type  fields               meaning
====  ===================  ==========================================================
S     newtons              tension setpoint, 0.000 .. 22.000 N
M     R | T                mode: R releases the tendon, T holds the setpoint
H     -                    heartbeat (any valid command also feeds the watchdog)
Z     -                    tare: the current raw reading becomes zero (mode R only)
K     newtons              calibrate: the applied known load, 0.100 .. 100.000 N (mode R)
E     -                    e-stop: release at once and latch the ESTOP fault
C     -                    clear latched faults (not CAL; refused while over the trip)
I     -                    ask for the banner
R     radians              roll servo target, -1.571 .. 1.571 rad (refused with a trip fault)
====  ===================  ==========================================================

Device -> host:

====  ===============================================================================
type  fields
====  ===============================================================================
B     TDCM, firmware version, load cell, control period ms, watchdog ms, setpoint max
      N, trip N -- sent at boot and on ``I``
T     time ms (u32), raw counts (i32), tension N, pulse us, mode R|T, faults (2 hex)
A     command letter -- command accepted (heartbeats are not acknowledged)
N     command letter or ``?``, reason -- command rejected (see :class:`.Reject`)
J     time ms (u32), roll target rad, roll rad, roll pulse us -- after every T once an R
      was accepted since boot (before that the servo holds 0 rad, its boot position)
====  ===============================================================================

The roll extension (R, J) is additive: a host that never sends R sees exactly the stream of a
device without a roll servo, so the version stays 1.

Fault bits (the trip faults 01-08 also stop the roll servo where it is and refuse R until C):
01 over-tension, 02 watchdog, 04 e-stop, 08 sensor, 10 calibration invalid.
A decoded line is either a complete frame or a :class:`~tdcm_ros.device.errors.FrameError`
naming the :class:`.Reject` reason; nothing is ever half-applied. :class:`LineDecoder` frames an
arbitrary byte stream: a ``$`` always starts a new frame, so garbage never hides a valid frame
that follows it.
"""

from __future__ import annotations

import enum
import math
import re
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from tdcm_ros.device import constants as c
from tdcm_ros.device.errors import DeviceInputError, FrameError, Reject
from tdcm_ros.errors import out_of_range


class Mode(enum.Enum):
    """Device mode: RELEASE slackens the tendon, TENSION holds the setpoint."""

    RELEASE = "R"
    TENSION = "T"


class Fault(enum.IntFlag):
    """Latched fault bits reported in telemetry."""

    OVER_TENSION = 0x01
    WATCHDOG = 0x02
    ESTOP = 0x04
    SENSOR = 0x08
    CALIBRATION = 0x10


# --- messages -------------------------------------------------------------------------------

@dataclass(frozen=True)
class SetSetpoint:
    """Command S: tension setpoint in N."""

    newtons: float


@dataclass(frozen=True)
class SetMode:
    """Command M."""

    mode: Mode


@dataclass(frozen=True)
class Heartbeat:
    """Command H."""


@dataclass(frozen=True)
class Tare:
    """Command Z."""


@dataclass(frozen=True)
class Calibrate:
    """Command K: the known load currently applied, in N."""

    newtons: float


@dataclass(frozen=True)
class EStop:
    """Command E."""


@dataclass(frozen=True)
class ClearFaults:
    """Command C."""


@dataclass(frozen=True)
class Info:
    """Command I."""


@dataclass(frozen=True)
class SetRoll:
    """Command R: roll servo target in rad."""

    radians: float


@dataclass(frozen=True)
class Banner:
    """Device B: identity and limits. Times in s, forces in N."""

    firmware: str
    cell: str
    control_period: float
    watchdog: float
    setpoint_max: float
    trip: float


@dataclass(frozen=True)
class Telemetry:
    """Device T: one control tick. ``time`` is device time in s, ``tension`` in N."""

    time: float
    raw: int
    tension: float
    pulse_us: int
    mode: Mode
    faults: Fault


@dataclass(frozen=True)
class RollState:
    """Device J: the roll servo at one control tick. ``time`` in s (the tick's T frame), ``target``
    and ``position`` (where the slew-limited pulse points now) in rad, ``pulse_us`` in us."""

    time: float
    target: float
    position: float
    pulse_us: int


@dataclass(frozen=True)
class Ack:
    """Device A: the command with this letter was accepted."""

    command: str


@dataclass(frozen=True)
class Nack:
    """Device N: a command was rejected; ``command`` is its letter or '?'."""

    command: str
    reason: Reject


Command = (SetSetpoint | SetMode | Heartbeat | Tare | Calibrate | EStop | ClearFaults | Info
           | SetRoll)
DeviceMessage = Banner | Telemetry | RollState | Ack | Nack
Message = Command | DeviceMessage

COMMAND_TYPES = frozenset("SMHZKECIR")
DEVICE_TYPES = frozenset("BTANJ")
_FIELDLESS: dict[str, type] = {"H": Heartbeat, "Z": Tare, "E": EStop, "C": ClearFaults, "I": Info}

# --- field syntax ---------------------------------------------------------------------------

_VERSION = re.compile(r"[1-9][0-9]{0,2}")
_NEWTONS = re.compile(r"(-?)(0|[1-9][0-9]{0,2})\.([0-9]{3})")
_INT = re.compile(r"-?(0|[1-9][0-9]{0,9})")
_HEX2 = re.compile(r"[0-9A-F]{2}")
_WORD = re.compile(r"[A-Za-z0-9._-]{1,12}")
_CMD_LETTER = re.compile(r"[A-Z?]")


def checksum(body: bytes) -> int:
    """XOR of the body bytes (between '$' and '*')."""
    value = 0
    for byte in body:
        value ^= byte
    return value


def _mn(newtons: float, parameter: str, low_mn: int, high_mn: int, unit: str = "N") -> int:
    """Newtons (or radians) -> integer thousandths, range-checked for encoding."""
    mn = round(newtons * 1000.0) if math.isfinite(newtons) else None
    if mn is None or not low_mn <= mn <= high_mn:
        raise out_of_range(parameter, newtons, f"[{low_mn / 1000:.3f}, {high_mn / 1000:.3f}]",
                           unit=unit, error=DeviceInputError)
    return mn


def _fmt_mn(mn: int) -> str:
    sign = "-" if mn < 0 else ""
    return f"{sign}{abs(mn) // 1000}.{abs(mn) % 1000:03d}"


def _fields(message: Message) -> list[str]:
    match message:
        case SetSetpoint(newtons=n):
            return ["S", _fmt_mn(_mn(n, "setpoint", 0, c.SETPOINT_MAX_MN))]
        case SetMode(mode=m):
            return ["M", m.value]
        case SetRoll(radians=r):
            return ["R", _fmt_mn(_mn(r, "roll", -c.ROLL_MAX_MRAD, c.ROLL_MAX_MRAD, "rad"))]
        case Calibrate(newtons=n):
            return ["K", _fmt_mn(_mn(n, "known_load", c.CAL_LOAD_MIN_MN, c.CAL_LOAD_MAX_MN))]
        case Heartbeat() | Tare() | EStop() | ClearFaults() | Info():
            return [next(k for k, v in _FIELDLESS.items() if v is type(message))]
        case Banner():
            return ["B", "TDCM", message.firmware, message.cell,
                    str(round(message.control_period * 1000)), str(round(message.watchdog * 1000)),
                    _fmt_mn(round(message.setpoint_max * 1000)), _fmt_mn(round(message.trip * 1000))]
        case Telemetry():
            return ["T", str(round(message.time * 1000)), str(message.raw),
                    _fmt_mn(round(message.tension * 1000)), str(message.pulse_us),
                    message.mode.value, f"{int(message.faults):02X}"]
        case RollState():
            return ["J", str(round(message.time * 1000)), _fmt_mn(round(message.target * 1000)),
                    _fmt_mn(round(message.position * 1000)), str(message.pulse_us)]
        case Ack(command=letter):
            return ["A", letter]
        case Nack(command=letter, reason=reason):
            return ["N", letter, reason.value]
    raise DeviceInputError(f"message = {message!r} is not a protocol message",
                           parameter="message", value=message, allowed="a protocol.Message")


def encode(message: Message, *, version: int = c.PROTOCOL_VERSION) -> bytes:
    """Encode one message as a complete line, '\\n' included."""
    body = ",".join([str(version), *_fields(message)]).encode("ascii")
    line = b"$" + body + b"*" + f"{checksum(body):02X}".encode("ascii")
    if len(line) > c.MAX_LINE:
        raise DeviceInputError(f"encoded line is {len(line)} bytes; allowed: <= {c.MAX_LINE}",
                               parameter="message", value=message, allowed=f"<= {c.MAX_LINE} bytes")
    return line + b"\n"


# --- decoding -------------------------------------------------------------------------------

def _reject(reason: Reject, detail: str, *, command: str | None = None,
            version: int | None = None) -> FrameError:
    return FrameError(f"line rejected ({reason.value}): {detail}", reason=reason,
                      command=command, version=version)


def _parse_mn(text: str, name: str, low: int, high: int, letter: str, unit: str = "N") -> int:
    match = _NEWTONS.fullmatch(text)
    if match is None:
        raise _reject(Reject.FIELDS, f"{name} = {text!r} is not a decimal with 3 decimals",
                      command=letter)
    mn = int(match[2]) * 1000 + int(match[3])
    if match[1]:
        if mn == 0:
            raise _reject(Reject.FIELDS, f"{name} = {text!r}: negative zero", command=letter)
        mn = -mn
    if not low <= mn <= high:
        raise _reject(Reject.RANGE, f"{name} = {text} {unit} is out of range; allowed: "
                      f"[{_fmt_mn(low)}, {_fmt_mn(high)}] {unit}", command=letter)
    return mn


def _parse_int(text: str, name: str, low: int, high: int, letter: str) -> int:
    if _INT.fullmatch(text) is None or text == "-0":
        raise _reject(Reject.FIELDS, f"{name} = {text!r} is not an integer", command=letter)
    value = int(text)
    if not low <= value <= high:
        raise _reject(Reject.RANGE, f"{name} = {value} is out of range; allowed: [{low}, {high}]",
                      command=letter)
    return value


def _expect(fields: list[str], count: int, letter: str) -> None:
    if len(fields) != count:
        raise _reject(Reject.FIELDS, f"type {letter} takes {count} field(s), got {len(fields)}",
                      command=letter)


def _decode_command(letter: str, f: list[str]) -> Command:
    if letter in _FIELDLESS:
        _expect(f, 0, letter)
        return _FIELDLESS[letter]()
    _expect(f, 1, letter)
    if letter == "S":
        return SetSetpoint(_parse_mn(f[0], "setpoint", 0, c.SETPOINT_MAX_MN, letter) / 1000)
    if letter == "R":
        return SetRoll(_parse_mn(f[0], "roll", -c.ROLL_MAX_MRAD, c.ROLL_MAX_MRAD, letter,
                                 "rad") / 1000)
    if letter == "K":
        return Calibrate(_parse_mn(f[0], "known_load", c.CAL_LOAD_MIN_MN, c.CAL_LOAD_MAX_MN,
                                   letter) / 1000)
    if f[0] not in ("R", "T"):
        raise _reject(Reject.FIELDS, f"mode = {f[0]!r}; allowed: R, T", command=letter)
    return SetMode(Mode(f[0]))


def _decode_device(letter: str, f: list[str]) -> DeviceMessage:
    if letter == "T":
        _expect(f, 6, letter)
        if f[4] not in ("R", "T") or _HEX2.fullmatch(f[5]) is None:
            raise _reject(Reject.FIELDS, f"mode/faults = {f[4]!r}/{f[5]!r}", command=letter)
        return Telemetry(time=_parse_int(f[0], "time_ms", 0, 2**32 - 1, letter) / 1000,
                         raw=_parse_int(f[1], "raw", -2**31, 2**31 - 1, letter),
                         tension=_parse_mn(f[2], "tension", -c.TENSION_LIMIT_MN,
                                           c.TENSION_LIMIT_MN, letter) / 1000,
                         pulse_us=_parse_int(f[3], "pulse_us", 0, 9999, letter),
                         mode=Mode(f[4]), faults=Fault(int(f[5], 16)))
    if letter == "J":
        _expect(f, 4, letter)
        return RollState(time=_parse_int(f[0], "time_ms", 0, 2**32 - 1, letter) / 1000,
                         target=_parse_mn(f[1], "roll_target", -c.ROLL_MAX_MRAD,
                                          c.ROLL_MAX_MRAD, letter, "rad") / 1000,
                         position=_parse_mn(f[2], "roll", -c.ROLL_MAX_MRAD, c.ROLL_MAX_MRAD,
                                            letter, "rad") / 1000,
                         pulse_us=_parse_int(f[3], "roll_pulse_us", 0, 9999, letter))
    if letter == "B":
        _expect(f, 7, letter)
        if f[0] != "TDCM" or _WORD.fullmatch(f[1]) is None or _WORD.fullmatch(f[2]) is None:
            raise _reject(Reject.FIELDS, f"banner identity {f[:3]!r}", command=letter)
        return Banner(firmware=f[1], cell=f[2],
                      control_period=_parse_int(f[3], "period_ms", 1, 60000, letter) / 1000,
                      watchdog=_parse_int(f[4], "watchdog_ms", 1, 60000, letter) / 1000,
                      setpoint_max=_parse_mn(f[5], "setpoint_max", 0, c.TENSION_LIMIT_MN,
                                             letter) / 1000,
                      trip=_parse_mn(f[6], "trip", 0, c.TENSION_LIMIT_MN, letter) / 1000)
    if letter == "A":
        _expect(f, 1, letter)
        if f[0] not in COMMAND_TYPES:
            raise _reject(Reject.FIELDS, f"acked command {f[0]!r}", command=letter)
        return Ack(f[0])
    _expect(f, 2, letter)
    if _CMD_LETTER.fullmatch(f[0]) is None or f[1] not in Reject.__members__:
        raise _reject(Reject.FIELDS, f"nack fields {f!r}", command=letter)
    return Nack(f[0], Reject(f[1]))


def decode(line: bytes, *, accept: frozenset[str] = COMMAND_TYPES | DEVICE_TYPES) -> Message:
    """Decode one frame (``$`` through ``HH``, without ``\\n``) or raise :class:`FrameError`.

    ``accept`` lists the message types this end understands; others are rejected as TYPE.
    """
    if len(line) > c.MAX_LINE:
        raise _reject(Reject.LONG, f"{len(line)} bytes; allowed: <= {c.MAX_LINE}")
    if any(b < 0x20 or b > 0x7E for b in line):
        raise _reject(Reject.CHARS, "byte outside printable ASCII")
    if len(line) < 4 or line[0] != 0x24 or line[-3] != 0x2A or line.count(b"*") != 1 \
            or line.count(b"$") != 1 or _HEX2.fullmatch(line[-2:].decode()) is None:
        raise _reject(Reject.FRAME, "expected $<body>*HH")
    body = line[1:-3]
    if checksum(body) != int(line[-2:], 16):
        raise _reject(Reject.CKSUM, f"checksum {line[-2:].decode()} != {checksum(body):02X}")
    head, *rest = body.decode("ascii").split(",")
    if _VERSION.fullmatch(head) is None:
        raise _reject(Reject.FRAME, f"version field {head!r}")
    version = int(head)
    if version != c.PROTOCOL_VERSION:
        raise _reject(Reject.VER, f"version = {version}; allowed: {c.PROTOCOL_VERSION}",
                      version=version)
    if not rest or rest[0] not in accept:
        raise _reject(Reject.TYPE, f"type = {rest[0] if rest else ''!r}; allowed: "
                      f"{''.join(sorted(accept))}")
    letter, fields = rest[0], rest[1:]
    if any(not field for field in fields):
        raise _reject(Reject.FIELDS, "empty field", command=letter)
    if letter in COMMAND_TYPES:
        return _decode_command(letter, fields)
    return _decode_device(letter, fields)


class LineDecoder:
    """Stream framer: feed arbitrary byte chunks, get decoded messages back.

    Every rejected frame is counted in :attr:`rejects` by reason and passed to ``on_reject``.
    A run of bytes outside any frame counts once as NOISE when the next '$' arrives.
    """

    def __init__(self, *, accept: frozenset[str] = COMMAND_TYPES | DEVICE_TYPES,
                 on_reject: Callable[[FrameError], None] | None = None) -> None:
        self.accept = accept
        self.on_reject = on_reject
        #: Rejected frames counted by reason (:class:`.Reject`).
        self.rejects: Counter[Reject] = Counter()
        self.frames = 0
        self._buffer = bytearray()
        self._in_frame = False
        self._skipping = False
        self._noise = False

    def _fail(self, error: FrameError) -> None:
        self.rejects[error.reason] += 1
        if self.on_reject is not None:
            self.on_reject(error)

    def feed(self, data: Iterable[int]) -> list[Message]:
        """Consume bytes; return every complete valid message, in order."""
        out: list[Message] = []
        for byte in data:
            if byte == 0x24:  # '$'
                if self._in_frame:
                    self._fail(_reject(Reject.PARTIAL, "frame cut by '$'"))
                elif self._noise:
                    self._fail(_reject(Reject.NOISE, "bytes outside a frame"))
                self._buffer = bytearray(b"$")
                self._in_frame, self._skipping, self._noise = True, False, False
            elif byte == 0x0A:  # '\n'
                if self._in_frame:
                    self._in_frame = False
                    try:
                        out.append(decode(bytes(self._buffer), accept=self.accept))
                        self.frames += 1
                    except FrameError as error:
                        self._fail(error)
                elif not self._skipping:
                    self._noise = True
                self._skipping = False
            elif self._in_frame:
                if len(self._buffer) >= c.MAX_LINE:
                    self._fail(_reject(Reject.LONG, f"more than {c.MAX_LINE} bytes"))
                    self._in_frame, self._skipping = False, True
                else:
                    self._buffer.append(byte)
            elif not self._skipping:
                self._noise = True
        return out
