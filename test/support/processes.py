"""Child processes and loopback ports of the process tier."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import threading
from collections.abc import Mapping
from pathlib import Path

from test.support.waiting import scaled

REPO = Path(__file__).resolve().parents[2]


def child_env(base: Mapping[str, str] | None = None, **extra: str) -> dict[str, str]:
    """``base`` (default this process's environment) with the repository first on
    ``PYTHONPATH``, so a child imports this checkout's ``tdcm_ros`` and ``test`` packages."""
    env = dict(os.environ if base is None else base)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), *filter(None, [env.get("PYTHONPATH")])])
    env.update(extra)
    return env


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def listening(port: int) -> bool:
    """True if something accepts TCP connections on 127.0.0.1:``port``."""
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.2):
            return True
    except OSError:
        return False


def stop(process: subprocess.Popen[bytes], timeout: float = 10.0) -> int:
    """SIGINT, then wait; returns the exit status. A process still running after ``timeout`` s
    (scaled) is killed and the failure shows the end of what it wrote (its stderr, when
    piped), so a hang says where it was."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    try:
        return process.wait(scaled(timeout))
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
        tail = (err or b"")[-3000:].decode(errors="replace")
        raise AssertionError(f"{process.args} did not exit within {scaled(timeout):g} s of "
                             f"SIGINT; killed. Its stderr ends:\n{tail}") from None


class Lines:
    """Lines of a child's ``stdout`` or ``stderr`` pipe, collected by a thread (never blocks
    the test)."""

    def __init__(self, process: subprocess.Popen[bytes], stream: str = "stdout") -> None:
        self.lines: list[str] = []
        pipe = getattr(process, stream)
        assert pipe is not None, f"the child's {stream} is not a pipe"
        self._thread = threading.Thread(
            target=lambda: self.lines.extend(line.decode() for line in pipe), daemon=True)
        self._thread.start()

    def has(self, text: str) -> bool:
        return any(text in line for line in self.lines)

    def tail(self, count: int = 15) -> str:
        """The last ``count`` lines, for a failure's message."""
        return "".join(self.lines[-count:])
