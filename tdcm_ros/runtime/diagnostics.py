"""Diagnostics the ``diagnostic_updater`` way, one implementation for every node.

A node adds one check per hardware component (:meth:`Diagnostics.add`); every ``period_s`` the
checks run and ``/diagnostics`` (``diagnostic_msgs/msg/DiagnosticArray``) gets one
``DiagnosticStatus`` per component, named ``<node>: <component>`` with a stable ``hardware_id``.
A check reports the component as it is now, so its level recovers when the problem goes away;
problems that are events (a dropped input, a clamped setpoint) count over a sliding window
(:class:`EventWindow`, like diagnostic_updater's frequency status) instead of latching.
"""

from __future__ import annotations

import enum
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from tdcm_ros.runtime.port import NodePort, QoS


class DiagnosticLevel(enum.IntEnum):
    """``diagnostic_msgs/DiagnosticStatus`` levels."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


TOPIC = "/diagnostics"
ARRAY_TYPE = "diagnostic_msgs/msg/DiagnosticArray"
STATUS_TYPE = "diagnostic_msgs/msg/DiagnosticStatus"
#: Updates an event window spans (diagnostic_updater's FrequencyStatus default window).
WINDOW_UPDATES = 5


@dataclass(frozen=True)
class Status:
    """What a check found: level, message and key/values."""

    level: DiagnosticLevel
    message: str
    values: Mapping[str, object] = field(default_factory=dict)


@dataclass(frozen=True)
class Check:
    """A named component check: ``<node>: <name>``, its ``hardware_id`` and the function."""

    name: str
    hardware_id: str
    run: Callable[[], Status]


def status_dict(node_name: str, check: Check, status: Status) -> dict[str, Any]:
    """A ``DiagnosticStatus`` as a dict (values as strings)."""
    return {"level": int(status.level), "name": f"{node_name}: {check.name}",
            "message": status.message, "hardware_id": check.hardware_id,
            "values": [{"key": k, "value": str(v)} for k, v in status.values.items()]}


def summary(statuses: list[dict[str, Any]], name: str, hardware_id: str) -> dict[str, Any]:
    """One status over several (as diagnostic_aggregator rolls up): the worst level, the
    messages at that level, every key/value."""
    worst = max((int(s["level"]) for s in statuses), default=int(DiagnosticLevel.STALE))
    message = "; ".join(s["message"] for s in statuses if int(s["level"]) == worst)
    values = {kv["key"]: kv["value"] for s in statuses for kv in s["values"]}
    return {"level": worst, "name": name, "message": message, "hardware_id": hardware_id,
            "values": [{"key": k, "value": v} for k, v in values.items()]}


class Diagnostics:
    """The components of one node on ``/diagnostics``, published every ``period_s`` (s)."""

    def __init__(self, port: NodePort, period_s: float) -> None:
        self.port, self.period_s = port, period_s
        self.checks: list[Check] = []
        self._publisher = port.create_publisher(TOPIC, ARRAY_TYPE, QoS(depth=10))
        port.create_timer(period_s, self.publish)

    def add(self, name: str, hardware_id: str, run: Callable[[], Status]) -> None:
        """Check component ``name`` (published as ``<node>: <name>``) with ``run``."""
        self.checks.append(Check(name, hardware_id, run))

    def statuses(self) -> list[dict[str, Any]]:
        """Run every check; their ``DiagnosticStatus`` dicts in the order added."""
        return [status_dict(self.port.node_name, check, check.run()) for check in self.checks]

    def publish(self) -> None:
        """Publish one ``DiagnosticArray`` with every component's status (rosbags is imported
        here, not with the runtime face)."""
        from tdcm_ros.bagio import from_dict

        stamp = self.port.now_ns()
        self._publisher.publish(from_dict(ARRAY_TYPE, {
            "header": {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9}},
            "status": self.statuses()}))

    def window(self) -> EventWindow:
        """An event window of :data:`WINDOW_UPDATES` periods on the node's clock."""
        return EventWindow(WINDOW_UPDATES * self.period_s, self.port.now_ns())


class EventWindow:
    """Events of a running count that happened in the last ``window_s`` (s); ``start_ns`` is
    when the count was 0 (ns, the node's clock)."""

    def __init__(self, window_s: float, start_ns: int) -> None:
        self.window_ns = round(window_s * 1e9)
        self._samples: deque[tuple[int, int]] = deque([(start_ns, 0)])

    def recent(self, total: int, now_ns: int) -> int:
        """Events among the running count ``total`` within the window ending ``now_ns``."""
        self._samples.append((now_ns, total))
        while len(self._samples) > 1 and self._samples[1][0] <= now_ns - self.window_ns:
            self._samples.popleft()
        return total - self._samples[0][1]
