"""Warnings about single messages, at most one per key and period: a 10 kHz flood of refused
setpoints must not become 10,000 log lines a second (49,694 lines in 10 s were seen)."""

from __future__ import annotations

import re
import time
from collections.abc import Callable

#: Shortest time between two warnings of one key (s).
PERIOD_S = 5.0
_NUMBER = re.compile(r"[-+]?(?:(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?|\b(?:nan|inf)\b)",
                     re.IGNORECASE)


def template(text: str) -> str:
    """``text`` with its numbers replaced by ``#``: one key for one kind of warning, whatever
    the values (``tension_setpoint = 30 N is out of range`` and ``... = 31 N ...`` alike)."""
    return _NUMBER.sub("#", text)


class Throttled:
    """Which warnings to log: the first of a key at once, then at most one per ``period_s`` s.
    The caller logs (so that the record names the caller's file and line); :attr:`counts` holds
    every warning's count by key, logged or not."""

    def __init__(self, period_s: float = PERIOD_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._period_s, self._clock = period_s, clock
        self._last: dict[str, float] = {}
        self._held: dict[str, int] = {}
        self.counts: dict[str, int] = {}

    def admit(self, key: str) -> str | None:
        """Count a warning of ``key``: ``None`` to hold it back, else the text to append to it
        (empty, or how many were held back since the last one of ``key``)."""
        self.counts[key] = self.counts.get(key, 0) + 1
        now = self._clock()
        last = self._last.get(key)
        if last is not None and now - last < self._period_s:
            self._held[key] = self._held.get(key, 0) + 1
            return None
        held = self._held.pop(key, 0)
        self._last[key] = now
        return f" ({held} more like it in the last {now - last:.1f} s)" if held and last is not None \
            else ""
