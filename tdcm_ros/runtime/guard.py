"""Callback isolation shared by both runtimes: a failing callback never ends a node's loop.

Every callback a node registers through its port (subscriptions, timers, services) runs inside
:meth:`CallbackGuard.wrap`. An exception is logged with its traceback, counted per callback, and
reported on ``/diagnostics`` (``diagnostic_msgs/DiagnosticArray``, one status named
``<node>: callbacks``, level ERROR, values ``<callback>: <count>`` and the last error), at most
once per :data:`REPORT_PERIOD_S` s while failures go on; the loop carries on with the next
callback. ``KeyboardInterrupt`` and ``SystemExit`` are not caught.
"""

from __future__ import annotations

import time
import traceback
from collections import Counter
from collections.abc import Callable
from typing import Any, ParamSpec, TypeVar

from tdcm_ros.bagio import from_dict

#: Shortest time (s) between two ``/diagnostics`` reports of failing callbacks.
REPORT_PERIOD_S = 1.0
_DIAGNOSTICS_TYPE = "diagnostic_msgs/msg/DiagnosticArray"
_ERROR = 2  # DiagnosticStatus.ERROR
P = ParamSpec("P")
R = TypeVar("R")


class CallbackGuard:
    """Runs callbacks of node ``node_name``; ``publisher_factory(topic, type)`` makes the
    ``/diagnostics`` publisher on first failure; ``now_ns()`` stamps the reports (ns)."""

    def __init__(self, node_name: str, logger: Any,
                 publisher_factory: Callable[[str, str], Any],
                 now_ns: Callable[[], int]) -> None:
        self.node_name = node_name
        self.failures: Counter[str] = Counter()
        self.last_error = ""
        self._logger = logger
        self._publisher_factory = publisher_factory
        self._now_ns = now_ns
        self._publisher: Any = None
        self._next_report = 0.0

    def wrap(self, what: str, callback: Callable[P, R]) -> Callable[P, R | None]:
        """``callback`` that logs, counts and reports an exception instead of raising it."""

        def guarded(*args: P.args, **kwargs: P.kwargs) -> R | None:
            try:
                return callback(*args, **kwargs)
            except Exception as error:  # noqa: BLE001 - the isolation boundary: logged, counted, reported
                self.failed(what, error)
                return None

        return guarded

    def failed(self, what: str, error: BaseException) -> None:
        """Record one failure of callback ``what``."""
        self.failures[what] += 1
        self.last_error = f"{what}: {type(error).__name__}: {error}"
        self._logger.error("callback %s failed (%d so far); the node goes on: %s\n%s", what,
                           self.failures[what], self.last_error,
                           "".join(traceback.format_exception(error)).rstrip())
        if time.monotonic() >= self._next_report:
            self._next_report = time.monotonic() + REPORT_PERIOD_S
            self._report()

    def _report(self) -> None:
        try:
            if self._publisher is None:
                self._publisher = self._publisher_factory("/diagnostics", _DIAGNOSTICS_TYPE)
            stamp = self._now_ns()
            self._publisher.publish(from_dict(_DIAGNOSTICS_TYPE, {
                "header": {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9}},
                "status": [{"level": _ERROR, "name": f"{self.node_name}: callbacks",
                            "message": self.last_error, "hardware_id": "tdcm_runtime",
                            "values": [{"key": k, "value": str(v)}
                                       for k, v in sorted(self.failures.items())]}]}))
        except Exception as error:  # noqa: BLE001 - a report must not fail the guarded loop
            self._logger.error("could not report the failure on /diagnostics: %s", error)
