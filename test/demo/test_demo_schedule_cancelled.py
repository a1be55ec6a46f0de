"""The staircase demo and a driver that disarms mid-run: the run stops at once with the driver's
reason and the device twin's simulation pauses, instead of waiting a minute for a
``schedule_done`` that cannot come (issue 24: "the schedule cancelled" under CPU load)."""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

import pytest

from tdcm_ros.demo.run import (
    DEVICE_TWIN,
    DRIVER_ACTUATOR,
    Progress,
    _watch,
    fault_free,
    schedule_not_cancelled,
)
from tdcm_ros.runtime import RuntimePortError


class Port:
    """Keeps the demo's subscription callbacks by topic."""

    def __init__(self) -> None:
        self.callbacks: dict[str, Callable[[Any], None]] = {}

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: object) -> None:
        self.callbacks[topic] = callback


def status(name: str, **values: str) -> SimpleNamespace:
    return SimpleNamespace(name=name, values=[SimpleNamespace(key=k, value=v)
                                              for k, v in values.items()])


def diagnostics(port: Port, *statuses: SimpleNamespace) -> None:
    port.callbacks["/diagnostics"](SimpleNamespace(status=list(statuses)))


@pytest.fixture
def watched() -> tuple[Port, Progress]:
    port, progress = Port(), Progress()
    _watch(port, progress)
    return port, progress


def test_a_schedule_cancelled_after_it_ran_stops_the_run_naming_the_reason_and_the_pauses(
        watched: tuple[Port, Progress]) -> None:
    port, progress = watched
    diagnostics(port, status(DRIVER_ACTUATOR, schedule="running", disarm_reason=""),
                status(DEVICE_TWIN, sim_pauses="0", sim_paused_s="0.000"))
    schedule_not_cancelled(progress)
    diagnostics(port, status(DRIVER_ACTUATOR, schedule="cancelled",
                             disarm_reason="device silent for 0.62 s (frozen?)"),
                status(DEVICE_TWIN, sim_late_turns="3", sim_pauses="2", sim_paused_s="0.517"))
    with pytest.raises(RuntimePortError) as raised:
        schedule_not_cancelled(progress)
    assert str(raised.value) == (
        "the driver cancelled the schedule: disarmed (device silent for 0.62 s (frozen?)); the "
        "tendon is released until clear_faults (the bag so far is kept); the device twin "
        "caught up 3 late turn(s) and paused 2 time(s), 0.517 s in all so far (its thread not "
        "scheduled on time: a loaded machine)")


def test_a_cancelled_state_before_the_schedule_ran_is_left_to_the_start(
        watched: tuple[Port, Progress]) -> None:
    """Before a status said "running", "cancelled" is an earlier schedule's: starting the new
    one (refused while disarmed) decides."""
    port, progress = watched
    diagnostics(port, status(DRIVER_ACTUATOR, schedule="cancelled", disarm_reason="e-stop"))
    schedule_not_cancelled(progress)
    assert progress.disarm_reason == "e-stop" and not progress.schedule_ran


def test_a_fault_during_the_run_names_the_twin_pauses_once_the_twin_said_them(
        watched: tuple[Port, Progress]) -> None:
    port, progress = watched
    diagnostics(port, status(DRIVER_ACTUATOR, faults="WATCHDOG"))
    with pytest.raises(RuntimePortError, match=r"device fault WATCHDOG during the run: .*kept\)$"):
        fault_free(progress)
    diagnostics(port, status(DEVICE_TWIN, sim_late_turns="0", sim_pauses="0", sim_paused_s="0.000"))
    with pytest.raises(RuntimePortError, match=r"caught up 0 late turn\(s\) and paused 0 time\(s\), "
                                               r"0.000 s in all"):
        fault_free(progress)
