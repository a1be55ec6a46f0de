"""Byte transports to the device: a serial device, a pty path or any pyserial URL.

Everything goes through :func:`serial.serial_for_url`, so ``/dev/ttyACM0``, ``/dev/pts/7``,
a symlink to either, ``loop://`` and ``socket://host:port`` all work. Neither reads nor writes
wait on the port (:class:`SerialTransport`).
Failures (port missing, cable pulled, pty closed, the port held by another driver) raise
:class:`.PortError`.
"""

from __future__ import annotations

import os
import select
import threading
from pathlib import Path
from typing import Protocol

import serial

from tdcm_ros.device import constants as c
from tdcm_ros.device.errors import PortError

#: s the reader thread waits for bytes before it looks whether it should stop.
READ_WAIT_S = 0.05


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
    """A :class:`Transport` over a pyserial port; a reader thread takes its bytes as they arrive.

    The caller never waits on the port: :meth:`read` hands over what the thread has read, and on a
    port with a file descriptor (a tty or pty) :meth:`write` is one non-blocking ``os.write``.
    Linux's tty poll and read wait for the tty's buffer-flush kernel worker when no input is
    queued (``n_tty_poll`` -> ``tty_buffer_flush_work``), and pyserial polls in ``read`` and after
    each ``write``; on a loaded machine that worker went unscheduled for up to 1.1 s (measured on
    the driver's step: kernel stack ``__flush_work <- n_tty_poll <- do_select``), and the
    driver's heartbeats waited with it until the device's watchdog tripped. Ports without a file
    descriptor (``loop://``, ``socket://``) are read by the thread through pyserial.
    """

    def __init__(self, port: serial.Serial, url: str) -> None:
        self._port = port
        self.url = url
        try:
            self._fd: int | None = port.fileno()
        except (AttributeError, OSError, serial.SerialException):
            self._fd = None
        self._poll = select.poll()
        if self._fd is None:
            port.timeout = READ_WAIT_S
        else:
            self._poll.register(self._fd, select.POLLIN)
        self._received = bytearray()
        self._error: Exception | None = None
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._reader = threading.Thread(target=self._read_until_stopped, daemon=True,
                                        name=f"tdcm-serial-{url}")
        self._reader.start()

    def _receive(self) -> bytes:
        """Wait up to ``READ_WAIT_S`` for bytes; what arrived (b"" if none)."""
        if self._fd is None:
            return bytes(self._port.read(max(1, self._port.in_waiting)))
        if not self._poll.poll(READ_WAIT_S * 1000):
            return b""
        data = os.read(self._fd, 4096)
        if not data:
            raise PortError("end of file: the device hung up (unplugged, or its pty closed)")
        return data

    def _read_until_stopped(self) -> None:
        while not self._stop.is_set():
            try:
                data = self._receive()
            except (serial.SerialException, OSError, ValueError, PortError) as error:
                if not self._stop.is_set():
                    with self._lock:
                        self._error = error
                return
            if data:
                with self._lock:
                    self._received += data

    def read(self) -> bytes:
        """The bytes read since the last call; after them, the reader's error as a
        :class:`.PortError`."""
        with self._lock:
            data, error = bytes(self._received), self._error
            self._received.clear()
        if not data and error is not None:
            raise PortError(f"port {self.url!r}: read failed: {error}") from error
        return data

    def write(self, data: bytes) -> None:
        """Send ``data`` now; a port that takes no more bytes (its output buffer full: nothing
        reads at the other end) is a :class:`.PortError`."""
        try:
            if self._fd is None:
                self._port.write(data)
                return
            view = memoryview(data)
            while view:
                view = view[os.write(self._fd, view):]
        except BlockingIOError as error:
            raise PortError(f"port {self.url!r}: write failed: the output buffer is full (the "
                            "device reads nothing)") from error
        except (serial.SerialException, OSError) as error:
            raise PortError(f"port {self.url!r}: write failed: {error}") from error

    def close(self) -> None:
        """Stop the reader (within ``READ_WAIT_S``) and close the port."""
        self._stop.set()
        self._reader.join()
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
    (``flock``) against a second driver on the same device: that one gets a :class:`.PortError`
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
