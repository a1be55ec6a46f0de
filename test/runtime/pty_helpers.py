"""Running a child process on a pseudo-terminal, as a user's shell would (shared by the CLI tests
of progress bars, exit statuses and ``bag play``'s progress line)."""

from __future__ import annotations

import fcntl
import os
import pty
import struct
import subprocess
import termios
import threading
from collections.abc import Mapping, Sequence
from pathlib import Path


def run_on_terminal(command: Sequence[str], *, env: Mapping[str, str], cwd: Path | str,
                    stdout_on_terminal: bool = False, timeout: float = 300.0,
                    columns: int | None = 100) -> tuple[int, str, str]:
    """Run ``command`` with stderr (and, with ``stdout_on_terminal``, stdout too) on a
    pseudo-terminal ``columns`` wide (None: a fresh pty's 0 x 0, where tqdm draws empty bars),
    stdin closed; its exit status, its stdout (captured from a pipe, empty when on the
    terminal) and what the terminal received."""
    leader, follower = pty.openpty()
    if columns is not None:
        fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    child = subprocess.Popen(command, stdin=subprocess.DEVNULL,
                             stdout=follower if stdout_on_terminal else subprocess.PIPE,
                             stderr=follower, env=dict(env), cwd=cwd, text=True)
    os.close(follower)
    chunks: list[bytes] = []

    def drain() -> None:
        while True:
            try:
                data = os.read(leader, 65536)
            except OSError:  # EIO: the child closed the terminal
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=drain)
    reader.start()
    out, _ = child.communicate(timeout=timeout)
    reader.join(timeout=30)
    os.close(leader)
    return child.returncode, out or "", b"".join(chunks).decode(errors="replace")
