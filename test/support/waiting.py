"""The one way a test waits: :func:`eventually`, for an exact condition, never a fixed sleep.

Every timeout is multiplied by :data:`TIME_SCALE` (``TDCM_TEST_TIME_SCALE``, default 1): a slow
or loaded machine raises it once for the whole suite instead of each test guessing its own
margin. A timeout is a generous bound on a condition the product must reach, not a measurement:
speed is measured by the scripts in ``bench/``.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Protocol, TypeVar

T = TypeVar("T")
#: Factor on every timeout of the suite (``TDCM_TEST_TIME_SCALE``).
TIME_SCALE = float(os.environ.get("TDCM_TEST_TIME_SCALE", "1") or "1")
#: s between two checks of a condition (when nothing is spun).
POLL_S = 0.02


class Spinner(Protocol):
    """Anything that can process its callbacks for a while (a zenoh context, plain rclpy)."""

    def spin_for(self, seconds: float) -> None: ...


class Together:
    """Several spinners as one (e.g. a test's zenoh contexts): each spins in turn."""

    def __init__(self, *spinners: Spinner) -> None:
        self.spinners = spinners

    def spin_for(self, seconds: float) -> None:
        for spinner in self.spinners:
            spinner.spin_for(seconds / len(self.spinners))


def scaled(seconds: float) -> float:
    """``seconds`` times :data:`TIME_SCALE`."""
    return seconds * TIME_SCALE


def eventually(predicate: Callable[[], T], timeout: float, what: str, *,
               spin: Spinner | None = None, action: Callable[[], object] | None = None,
               every: float = 0.3, detail: Callable[[], object] | None = None) -> T:
    """Wait until ``predicate()`` is truthy and return its value.

    ``spin`` processes its callbacks while waiting (else this thread sleeps :data:`POLL_S`);
    ``action`` runs first and then every ``every`` s while waiting (e.g. a publish a late
    subscriber may miss). After ``timeout`` s (times :data:`TIME_SCALE`) it fails naming
    ``what`` and, with ``detail``, what ``detail()`` shows of the state then.
    """
    limit = scaled(timeout)
    deadline = time.monotonic() + limit
    next_action = time.monotonic()
    while True:
        value = predicate()
        if value:
            return value
        now = time.monotonic()
        if now > deadline:
            extra = f"; {detail()}" if detail is not None else ""
            raise AssertionError(f"timed out after {limit:g} s waiting for {what}{extra}")
        if action is not None and now >= next_action:
            action()
            next_action = now + every
        if spin is not None:
            spin.spin_for(min(0.05, max(deadline - now, 0.001)))
        else:
            time.sleep(POLL_S)


def holds(predicate: Callable[[], object], seconds: float, what: str, *,
          spin: Spinner | None = None) -> None:
    """Check ``predicate()`` throughout ``seconds`` (not scaled: it is the span the behaviour
    must last); fails naming ``what`` at the first check where it is false."""
    end = time.monotonic() + seconds
    while True:
        assert predicate(), f"{what} stopped holding {seconds - (end - time.monotonic()):.2f} s in"
        now = time.monotonic()
        if now >= end:
            return
        if spin is not None:
            spin.spin_for(min(0.05, end - now))
        else:
            time.sleep(min(POLL_S, end - now))
