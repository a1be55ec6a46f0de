"""Errors of :mod:`tdcm_ros.device`.

``DeviceError`` is the root of the subpackage; every specific error also derives from one of the
categories in :mod:`tdcm_ros.errors` so the CLI maps it to the right exit status.
"""

from __future__ import annotations

import enum

from tdcm_ros.errors import InputError, TdcmError


class DeviceError(TdcmError):
    """Root of every error raised by :mod:`tdcm_ros.device`."""


class DeviceInputError(DeviceError, InputError):
    """A bad parameter or value given to the device layer (names parameter, value and range)."""


class Reject(enum.Enum):
    """Why a line was rejected; the value is the code sent in a NACK."""

    NOISE = "NOISE"        #: bytes outside any frame (counted, never NACKed)
    PARTIAL = "PARTIAL"    #: a frame cut short by the next '$'
    LONG = "LONG"          #: longer than MAX_LINE
    CHARS = "CHARS"        #: a byte outside printable ASCII
    FRAME = "FRAME"        #: ``*HH`` missing or misplaced, or no version field
    CKSUM = "CKSUM"        #: checksum mismatch
    VER = "VER"            #: unsupported protocol version
    TYPE = "TYPE"          #: unknown message type (or wrong direction)
    FIELDS = "FIELDS"      #: wrong number or syntax of fields
    RANGE = "RANGE"        #: a value outside its range
    MODE = "MODE"          #: command not allowed in the current mode (device reply)
    FAULT = "FAULT"        #: command refused because of a fault (device reply)


class FrameError(DeviceInputError):
    """A protocol line was rejected for ``reason``.

    ``command`` is the command letter when the type was recognised (else ``None``); ``version``
    is the protocol version the line claimed, when it could be read.
    """

    def __init__(self, message: str, *, reason: Reject, command: str | None = None,
                 version: int | None = None) -> None:
        super().__init__(message, parameter="line", value=None, allowed=None)
        self.reason = reason
        self.command = command
        self.version = version


class ProtocolVersionError(DeviceInputError):
    """The device speaks a protocol version this host does not support."""


class PortError(DeviceError):
    """The serial port could not be opened, read or written (device gone, wrong path ...)."""
