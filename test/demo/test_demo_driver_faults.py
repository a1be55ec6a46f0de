"""The demo and the driver's device faults and disarms: one latched while the graph started is
cleared once before the schedule or the first target; one latched during the run stops the run."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

import pytest

from tdcm_ros.demo.run import CLEAR_SERVICE, Progress, clear_start_up_fault, fault_free
from tdcm_ros.runtime import RuntimePortError


class FakeGraph:
    """Statuses the driver publishes, one per turn of the demo's loop; records service calls."""

    def __init__(self, progress: Progress, faults: list[str | tuple[str, bool]], *,
                 clears: bool = True) -> None:
        self.progress, self.faults, self.clears = progress, faults, clears
        self.calls: list[str] = []
        self.turns = 0

    def turn(self, deadline: float, late: Callable[[], str], seconds: float = 0.1) -> None:
        self.turns += 1
        if self.turns > 50:
            raise RuntimePortError(late())
        if self.faults:  # a status: its faults, and whether the driver is armed (default yes)
            status = self.faults.pop(0)
            faults, armed = status if isinstance(status, tuple) else (status, True)
            self.progress.faults, self.progress.armed = faults, armed
            self.progress.disarm_reason = "" if armed else "device silent for 0.67 s (frozen?)"
            self.progress.actuator_statuses += 1

    def call_service(self, name: str, type_name: str, *, timeout: float) -> Any:
        self.calls.append(name)
        return SimpleNamespace(success=self.clears, message="" if self.clears else "link down")


def run(faults: list[str | tuple[str, bool]], *, clears: bool = True) -> tuple[FakeGraph, list[str]]:
    progress = Progress()
    graph = FakeGraph(progress, faults, clears=clears)
    said: list[str] = []
    clear_start_up_fault(graph, graph, progress, said.append)  # type: ignore[arg-type]
    return graph, said


def test_no_fault_at_start_calls_nothing() -> None:
    graph, said = run([""])
    assert graph.calls == [] and said == []


def test_a_start_up_fault_is_cleared_once_and_said() -> None:
    graph, said = run(["WATCHDOG", "WATCHDOG", ""])
    assert graph.calls == [CLEAR_SERVICE]
    assert len(said) == 1 and "WATCHDOG" in said[0] and "no target sent" in said[0]


def test_a_start_up_disarm_is_cleared_once_and_said_with_its_reason() -> None:
    graph, said = run([("", False), ("", False), ("", True)])
    assert graph.calls == [CLEAR_SERVICE]
    assert len(said) == 1 and "disarmed (device silent for 0.67 s (frozen?))" in said[0]


def test_a_disarm_still_held_after_clear_faults_stops_the_run() -> None:
    with pytest.raises(RuntimePortError, match=r"disarmed \(device silent .* after clear_faults"):
        run([("", False), ("", False)])


def test_a_fault_still_latched_after_clear_faults_stops_the_run() -> None:
    with pytest.raises(RuntimePortError, match="WATCHDOG is still latched .* after clear_faults"):
        run(["WATCHDOG", "WATCHDOG"])


def test_a_refused_clear_stops_the_run_with_the_drivers_reason() -> None:
    with pytest.raises(RuntimePortError, match="refused clear_faults: link down"):
        run(["ESTOP"], clears=False)


def test_no_status_at_all_is_an_error_naming_it() -> None:
    with pytest.raises(RuntimePortError, match="tension_driver: actuator"):
        run([])


def test_a_fault_during_the_run_stops_it() -> None:
    progress = Progress()
    fault_free(progress)
    progress.faults = "WATCHDOG"
    with pytest.raises(RuntimePortError, match="device fault WATCHDOG during the run"):
        fault_free(progress)


def test_a_disarm_during_the_run_stops_it_with_the_reason() -> None:
    """A driver that disarmed (e.g. its device silent past the watchdog time) holds the tendon
    released: the tracking run stops instead of reporting the tracking of a released tendon."""
    progress = Progress(armed=True, actuator_statuses=1)
    fault_free(progress)
    progress.armed, progress.disarm_reason = False, "device silent for 0.54 s (frozen?)"
    progress.twin_pauses = "caught up 1 late turn(s) and paused 2 time(s), 0.563 s in all"
    with pytest.raises(RuntimePortError, match=r"disarmed \(device silent for 0.54 s \(frozen\?\)\) "
                                               r"during the run.*paused 2 time\(s\)"):
        fault_free(progress)


def test_only_faults_that_release_the_tendon_count() -> None:
    from tdcm_ros.demo.run import TRIP_FAULT_NAMES

    assert TRIP_FAULT_NAMES == {"OVER_TENSION", "WATCHDOG", "ESTOP", "SENSOR"}
