"""Byte transports to the device: a serial device, a pty path or any pyserial URL.

Everything goes through :func:`serial.serial_for_url`, so ``/dev/ttyACM0``, ``/dev/pts/7``,
a symlink to either, ``loop://`` and ``socket://host:port`` all work. Reads never block.
Failures (port missing, cable pulled, pty closed) raise :class:`PortError`.
"""

from __future__ import annotations

from typing import Protocol

import serial

from tdcm_ros.device import constants as c
from tdcm_ros.device.errors import PortError


class Transport(Protocol):
    """What the driver needs from a port."""

    def read(self) -> bytes:
        """Whatever bytes are available now (possibly none); never blocks."""
        ...

    def write(self, data: bytes) -> None:
        """Send bytes."""
        ...

    def close(self) -> None:
        """Release the port; further calls are errors."""
        ...


class SerialTransport:
    """A :class:`Transport` over a pyserial port object."""

    def __init__(self, port: serial.Serial, url: str) -> None:
        self._port = port
        self.url = url

    def read(self) -> bytes:
        try:
            return bytes(self._port.read(max(1, self._port.in_waiting)))
        except (serial.SerialException, OSError) as error:
            raise PortError(f"port {self.url!r}: read failed: {error}") from error

    def write(self, data: bytes) -> None:
        try:
            self._port.write(data)
        except (serial.SerialException, OSError) as error:
            raise PortError(f"port {self.url!r}: write failed: {error}") from error

    def close(self) -> None:
        self._port.close()


def open_transport(url: str, *, baudrate: int = c.BAUD_RATE) -> SerialTransport:
    """Open ``url`` (device path, pty path or pyserial URL) 8N1, non-blocking reads."""
    try:
        port = serial.serial_for_url(url, baudrate=baudrate, timeout=0, write_timeout=1.0)
    except (serial.SerialException, OSError, ValueError) as error:
        raise PortError(f"port {url!r}: cannot open: {error}") from error
    port.reset_input_buffer()
    return SerialTransport(port, url)
