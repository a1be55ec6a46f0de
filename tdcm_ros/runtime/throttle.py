"""Warnings about single messages, at most one per key and period: a 10 kHz flood of refused
setpoints must not become 10,000 log lines a second (49,694 lines in 10 s were seen)."""

from __future__ import annotations

import re
import time
from collections.abc import Callable

from tdcm_ros.runtime.port import Logger

#: Shortest time between two warnings of one key (s).
PERIOD_S = 5.0
_NUMBER = re.compile(r"[-+]?(?:(?:\d+\.?\d*|\.\d+)(?:e[-+]?\d+)?|\b(?:nan|inf)\b)",
                     re.IGNORECASE)


def template(text: str) -> str:
    """``text`` with its numbers replaced by ``#``: one key for one kind of warning, whatever
    the values (``tension_setpoint = 30 N is out of range`` and ``... = 31 N ...`` alike)."""
    return _NUMBER.sub("#", text)


class Throttled:
    """``warn(key, text)`` logs the first warning of ``key`` at once, then at most one per
    ``period_s`` s, saying how many were left out since the last one; :attr:`counts` holds every
    warning's count by key, shown or not."""

    def __init__(self, logger: Logger, period_s: float = PERIOD_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._logger, self._period_s, self._clock = logger, period_s, clock
        self._last: dict[str, float] = {}
        self._held: dict[str, int] = {}
        self.counts: dict[str, int] = {}

    def warn(self, key: str, text: str) -> bool:
        """Count a warning of ``key``; log ``text`` if the key's period is over. True if logged."""
        self.counts[key] = self.counts.get(key, 0) + 1
        now = self._clock()
        last = self._last.get(key)
        if last is not None and now - last < self._period_s:
            self._held[key] = self._held.get(key, 0) + 1
            return False
        held = self._held.pop(key, 0)
        self._last[key] = now
        suffix = f" ({held} more like it in the last {now - last:.1f} s)" if held and last is not None else ""
        self._logger.warning("%s%s", text, suffix)
        return True
