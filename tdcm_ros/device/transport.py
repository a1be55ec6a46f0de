"""Byte transports to the device: a serial device, a pty path or any pyserial URL.

Everything goes through :func:`serial.serial_for_url`, so ``/dev/ttyACM0``, ``/dev/pts/7``,
a symlink to either, ``loop://`` and ``socket://host:port`` all work. Reads never block.
Failures (port missing, cable pulled, pty closed, the port held by another driver) raise
:class:`PortError`.
"""

from __future__ import annotations

import os
from pathlib import Path
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


def lock_holders(path: str) -> list[str]:
    """``pid N (command line)`` of each process holding an ``flock`` on ``path``, from Linux's
    ``/proc/locks`` (empty where it cannot be read)."""
    try:
        status = os.stat(path)
        file_id = (f"{os.major(status.st_dev):02x}:{os.minor(status.st_dev):02x}:"
                   f"{status.st_ino}")
        pids = [fields[4] for fields in (line.split() for line in
                                         Path("/proc/locks").read_text().splitlines())
                if len(fields) > 5 and fields[1] == "FLOCK" and fields[5] == file_id]
    except OSError:
        return []
    found = []
    for pid in pids:
        try:
            command = Path("/proc", pid, "cmdline").read_bytes().replace(b"\0", b" ").strip()
        except OSError:
            command = b"?"
        found.append(f"pid {pid} ({command.decode(errors='replace')})")
    return found


def open_transport(url: str, *, baudrate: int = c.BAUD_RATE) -> SerialTransport:
    """Open ``url`` (device path, pty path or pyserial URL) 8N1, non-blocking reads, locked
    (``flock``) against a second driver on the same device: that one gets a :class:`PortError`
    naming the process that holds the port."""
    try:
        port = serial.serial_for_url(url, baudrate=baudrate, timeout=0, write_timeout=1.0,
                                     exclusive=True)
    except (serial.SerialException, OSError, ValueError) as error:
        if "exclusively lock" in str(error):
            held_by = ", ".join(lock_holders(url)) or "another process"
            raise PortError(f"port {url!r} is in use by {held_by}; one driver per device")
        raise PortError(f"port {url!r}: cannot open: {error}") from error
    port.reset_input_buffer()
    return SerialTransport(port, url)
