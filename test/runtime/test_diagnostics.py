"""The diagnostics helper every node uses: one status per component, event windows that
forget, the roll-up of components into one status."""

from __future__ import annotations

from typing import Any

from tdcm_ros.runtime.diagnostics import (
    DiagnosticLevel,
    Diagnostics,
    EventWindow,
    Status,
    summary,
)
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.port import NodeLogic, NodePort

OK, WARN, ERROR, STALE = list(DiagnosticLevel)


def test_an_event_window_counts_only_recent_events() -> None:
    window = EventWindow(5.0, start_ns=0)
    assert window.recent(0, 1 * 10**9) == 0
    assert window.recent(2, 2 * 10**9) == 2           # two events since the start
    assert window.recent(2, 6 * 10**9) == 2           # still within 5 s of them
    assert window.recent(3, 8 * 10**9) == 1           # the first two left the window
    assert window.recent(3, 20 * 10**9) == 0


class Pump(NodeLogic):
    """Two components; the pump warns while ``errors`` grew within the window."""

    default_name = "pump"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.errors = 0
        self.diagnostics = Diagnostics(port, 1.0)
        self.window = self.diagnostics.window()
        self.diagnostics.add("motor", "pump-7", lambda: Status(OK, "spinning", {"rpm": 1200}))
        self.diagnostics.add("valve", "pump-7", self.valve)

    def valve(self) -> Status:
        recent = self.window.recent(self.errors, self.port.now_ns())
        return Status(WARN, f"{recent} sticking", {"sticks": self.errors}) if recent \
            else Status(OK, "ok", {"sticks": self.errors})


def _levels(array: Any) -> list[tuple[str, str, int]]:
    return [(s.name, s.hardware_id, s.level) for s in array.status]


def test_components_publish_together_and_recover() -> None:
    port = MemoryPort(name="pump")
    node = Pump(port)
    port.advance(1.0)
    node.errors = 1
    port.advance(3.0)
    node.errors = 1
    port.advance(5.0)
    levels = [_levels(a) for a in port.messages("/diagnostics")]
    assert levels[0] == [("pump: motor", "pump-7", OK), ("pump: valve", "pump-7", OK)]
    assert [row[1][2] for row in levels] == [OK, WARN, WARN, WARN, WARN, WARN, OK, OK, OK]
    assert port.messages("/diagnostics")[-1].status[1].values[0].value == "1"


def test_summary_takes_the_worst_level_and_every_value() -> None:
    parts = [{"level": OK, "message": "fine", "values": [{"key": "a", "value": "1"}]},
             {"level": ERROR, "message": "broken", "values": [{"key": "b", "value": "2"}]},
             {"level": ERROR, "message": "also", "values": []}]
    rolled = summary(parts, "node", "hw")
    assert (rolled["level"], rolled["message"]) == (ERROR, "broken; also")
    assert rolled["values"] == [{"key": "a", "value": "1"}, {"key": "b", "value": "2"}]
    assert summary([], "node", "hw")["level"] == STALE
