"""Leaving a process for sure: a close with a time limit, and an exit no thread can hold up."""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable


def close_within(close: Callable[[], None], timeout: float, *, name: str = "close") -> bool:
    """Run ``close`` on a daemon thread; True if it returned within ``timeout`` s (an error it
    raised is raised here). A close that blocks is left behind: the daemon thread does not hold
    the process, which should then leave with :func:`exit_now`."""
    done = threading.Event()
    failed: list[BaseException] = []

    def run() -> None:
        try:
            close()
        except BaseException as error:  # noqa: BLE001 - re-raised on the caller's thread
            failed.append(error)
        finally:
            done.set()

    threading.Thread(target=run, name=name, daemon=True).start()
    if not done.wait(timeout):
        return False
    if failed:
        raise failed[0]
    return True


def exit_now(status: int) -> None:
    """Flush stdout and stderr, then leave at once (``os._exit``): no thread, no finaliser and
    no native library's exit hook can keep the process alive."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, RuntimeError):  # RuntimeError: reentrant call from a
            pass  # signal handler that interrupted a write of the same stream
    os._exit(status)
