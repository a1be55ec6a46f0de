"""Opening the device: one driver per port (an ``flock``), the second refused naming the holder;
the caller never waits on the port (its reads and polls run on the transport's reader thread)."""

from __future__ import annotations

import os
import pty
import select
import threading
from collections.abc import Iterator
from typing import Any

import pytest
import serial

from tdcm_ros.device.errors import PortError
from tdcm_ros.device.transport import SerialTransport, lock_holders, open_transport
from test.support.waiting import eventually


@pytest.fixture
def pty_path() -> Iterator[str]:
    """The path of a fresh pty's device end (what ``tdcm_ros.device.twin`` offers)."""
    primary, secondary = pty.openpty()
    yield os.ttyname(secondary)
    os.close(secondary)
    os.close(primary)


def test_a_second_open_of_a_held_port_is_refused_naming_the_holder(pty_path: str) -> None:
    """Issue 25: a second driver opened the port the first held and the tension fell to 0 N."""
    first = open_transport(pty_path)
    try:
        assert lock_holders(pty_path) == [lock_holders(pty_path)[0]]
        with pytest.raises(PortError) as refused:
            open_transport(pty_path)
        message = str(refused.value)
        assert f"port {pty_path!r} is in use by pid {os.getpid()} (" in message
        assert message.endswith("one driver per device")
    finally:
        first.close()
    assert lock_holders(pty_path) == []
    open_transport(pty_path).close()  # free again once the first is closed


def test_urls_without_a_file_still_open() -> None:
    open_transport("loop://").close()


def _received(transport: SerialTransport, size: int) -> bytes:
    """What ``transport.read`` gives until ``size`` bytes came (the reader thread takes them)."""
    got = bytearray()

    def complete() -> bool:
        got.extend(transport.read())
        return len(got) >= size

    eventually(complete, 5.0, f"{size} bytes from the port")
    return bytes(got)


def test_the_caller_never_polls_or_reads_the_tty(monkeypatch: pytest.MonkeyPatch) -> None:
    """The driver's heartbeat stalled up to 1.1 s on a loaded machine: pyserial polled the tty in
    every read and after every write, and Linux's tty poll waits for the tty's buffer-flush
    kernel worker (``n_tty_poll`` -> ``tty_buffer_flush_work``). Every poll and read of the port
    must run on the reader thread; the caller only writes."""
    callers: list[tuple[str, int]] = []
    real_poll, real_select, real_read = select.poll, select.select, os.read

    class RecordingPoll:
        def __init__(self) -> None:
            self._poll = real_poll()

        def register(self, fd: int, mask: int) -> None:
            self._poll.register(fd, mask)

        def poll(self, timeout: float) -> Any:
            callers.append(("poll", threading.get_ident()))
            return self._poll.poll(timeout)

    def recording_select(*args: Any) -> Any:
        callers.append(("select", threading.get_ident()))
        return real_select(*args)

    def recording_read(fd: int, size: int) -> bytes:
        callers.append(("read", threading.get_ident()))
        return real_read(fd, size)

    monkeypatch.setattr(select, "poll", RecordingPoll)
    monkeypatch.setattr(select, "select", recording_select)
    monkeypatch.setattr(os, "read", recording_read)
    primary, secondary = pty.openpty()
    transport = open_transport(os.ttyname(secondary))
    try:
        transport.write(b"$1,H*79\n")
        assert real_read(primary, 64) == b"$1,H*79\n"
        os.write(primary, b"telemetry\n")
        assert _received(transport, 10) == b"telemetry\n"
    finally:
        transport.close()
        os.close(secondary)
        os.close(primary)
    me = threading.get_ident()
    assert [kind for kind, thread in callers if thread == me] == []
    assert {"poll", "read"} <= {kind for kind, _ in callers}  # the reader thread did both


class StuckPort(serial.Serial):
    """A port without a file descriptor whose reads wait until :attr:`release` is set, as a tty
    read waits for a kernel worker that is not scheduled; a read on the test's own thread fails
    at once instead of hanging the test."""

    def __init__(self) -> None:
        super().__init__()
        self.release = threading.Event()
        self.pending = b""
        self.written = bytearray()
        self.test_thread = threading.get_ident()

    def fileno(self) -> int:
        raise OSError("no file descriptor")

    @property
    def in_waiting(self) -> int:
        return len(self.pending)

    def read(self, size: int = 1) -> bytes:
        assert threading.get_ident() != self.test_thread, "the caller waited on the port's read"
        self.release.wait()
        data, self.pending = self.pending, b""
        return data

    def write(self, data: Any) -> int:
        self.written += data
        return len(data)

    def close(self) -> None:
        self.release.set()


def test_a_read_stuck_in_the_port_delays_neither_read_nor_write() -> None:
    port = StuckPort()
    transport = SerialTransport(port, "stuck://")
    try:
        port.pending = b"late frame\n"
        assert transport.read() == b""          # the port's read is stuck: nothing yet, no wait
        transport.write(b"$1,H*79\n")           # the heartbeat goes out meanwhile
        assert bytes(port.written) == b"$1,H*79\n"
        port.release.set()
        assert _received(transport, 11) == b"late frame\n"
    finally:
        transport.close()


def test_a_hang_up_is_a_port_error_after_the_bytes_before_it() -> None:
    primary, secondary = pty.openpty()
    path = os.ttyname(secondary)
    transport = open_transport(path)
    try:
        os.write(primary, b"last words\n")
        assert _received(transport, 11) == b"last words\n"
        os.close(primary)
        error = eventually(lambda: _error_of(transport), 5.0, "the hang-up as a PortError")
        assert "hung up" in error and path in error
    finally:
        transport.close()
        os.close(secondary)
    assert not [t for t in threading.enumerate() if t.name.startswith("tdcm-serial-")]


def _error_of(transport: SerialTransport) -> str:
    try:
        transport.read()
    except PortError as error:
        return str(error)
    return ""


def test_a_full_output_buffer_is_a_port_error_not_a_wait(pty_path: str) -> None:
    """Nothing reads the other end: the write fails at once, naming the port."""
    transport = open_transport(pty_path)
    try:
        with pytest.raises(PortError, match="output buffer is full"):
            for _ in range(100_000):
                transport.write(b"x" * 64)
    finally:
        transport.close()
