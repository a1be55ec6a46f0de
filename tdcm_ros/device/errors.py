"""Errors of :mod:`tdcm_ros.device`.

``DeviceError`` is the root of the subpackage; every specific error also derives from one of the
categories in :mod:`tdcm_ros.errors` so the CLI maps it to the right exit status.
"""

from __future__ import annotations

from tdcm_ros.errors import InputError, TdcmError


class DeviceError(TdcmError):
    """Root of every error raised by :mod:`tdcm_ros.device`."""


class DeviceInputError(DeviceError, InputError):
    """A bad parameter or value given to the device layer (names parameter, value and range)."""


class FrameError(DeviceInputError):
    """A protocol line was rejected; ``reason`` is a :class:`~tdcm_ros.device.protocol.Reject`.

    ``command`` is the command letter when the type was recognised (else ``None``); ``version``
    is the protocol version the line claimed, when it could be read.
    """

    def __init__(self, message: str, *, reason: object, command: str | None = None,
                 version: int | None = None) -> None:
        super().__init__(message, parameter="line", value=None, allowed=None)
        self.reason = reason
        self.command = command
        self.version = version


class ProtocolVersionError(DeviceInputError):
    """The device speaks a protocol version this host does not support."""


class PortError(DeviceError):
    """The serial port could not be opened, read or written (device gone, wrong path ...)."""
