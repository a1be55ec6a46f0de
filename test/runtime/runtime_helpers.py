"""Helpers of the multi-process runtime tests (uniquely named so imports never collide)."""

from __future__ import annotations

import signal
import socket
import subprocess
import time
from collections.abc import Callable
from typing import Any


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def listening(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.2):
            return True
    except OSError:
        return False


def wait_for(predicate: Callable[[], bool], timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)


def stop(process: subprocess.Popen[bytes], timeout: float = 10.0) -> int:
    """SIGINT, then wait; returns the exit status. A process still running after ``timeout`` s
    is killed and the failure shows the end of what it wrote (its stderr, when piped), so a
    hang says where it was."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    try:
        return process.wait(timeout)
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
        tail = (err or b"")[-3000:].decode(errors="replace")
        raise AssertionError(f"{process.args} did not exit within {timeout} s of SIGINT; "
                             f"killed. Its stderr ends:\n{tail}") from None


def spin_until(context: Any, predicate: Callable[[], bool], timeout: float, what: str) -> None:
    """Spin ``context`` (anything with ``spin_for(s)``) until ``predicate()``; AssertionError
    naming ``what`` after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        context.spin_for(0.05)
