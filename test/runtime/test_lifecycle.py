"""The lifecycle protocol on an in-memory port: rcl's default state machine, its services and
transition events, success, failure and error paths (lifecycle_msgs ids as rcl gives them)."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.lifecycle import Lifecycle, TransitionFailed
from tdcm_ros.runtime.memory_port import MemoryPort


def managed(**callbacks: Callable[[], None]) -> tuple[MemoryPort, Lifecycle, list[str]]:
    """A port with a Lifecycle whose callbacks also log their names in ``called``."""
    port = MemoryPort(name="managed")
    called: list[str] = []

    def logged(name: str) -> Callable[[], None]:
        def run() -> None:
            called.append(name)
            callbacks.get(name, lambda: None)()
        return run

    names = ("on_configure", "on_cleanup", "on_activate", "on_deactivate", "on_shutdown",
             "on_error")
    return port, Lifecycle(port, {name: logged(name) for name in names}), called


def change(port: MemoryPort, *, id: int = 0, label: str = "") -> bool:
    request = from_dict("lifecycle_msgs/srv/ChangeState_Request",
                        {"transition": {"id": id, "label": label}})
    return bool(port.call("~/change_state", request).success)


def state(port: MemoryPort) -> tuple[int, str]:
    current = port.call("~/get_state").current_state
    return int(current.id), str(current.label)


def events(port: MemoryPort) -> list[tuple[int, str, str]]:
    return [(int(e.transition.id), str(e.start_state.label), str(e.goal_state.label))
            for e in port.messages("~/transition_event")]


def available(port: MemoryPort) -> list[tuple[int, str, str, str]]:
    return [(int(t.transition.id), str(t.transition.label), str(t.start_state.label),
             str(t.goal_state.label))
            for t in port.call("~/get_available_transitions").available_transitions]


def test_a_node_starts_unconfigured_and_walks_the_primary_states() -> None:
    port, _, called = managed()
    assert state(port) == (1, "unconfigured")
    assert available(port) == [(1, "configure", "unconfigured", "configuring"),
                               (5, "shutdown", "unconfigured", "shuttingdown")]
    assert change(port, id=1) and state(port) == (2, "inactive")
    assert change(port, label="activate") and state(port) == (3, "active")
    assert change(port, id=4) and change(port, label="cleanup")
    assert state(port) == (1, "unconfigured")
    assert called == ["on_configure", "on_activate", "on_deactivate", "on_cleanup"]
    assert events(port) == [
        (1, "unconfigured", "configuring"), (10, "configuring", "inactive"),
        (3, "inactive", "activating"), (30, "activating", "active"),
        (4, "active", "deactivating"), (40, "deactivating", "inactive"),
        (2, "inactive", "cleaningup"), (20, "cleaningup", "unconfigured")]
    assert [s.label for s in port.call("~/get_available_states").available_states] == [
        "unconfigured", "inactive", "active", "finalized", "configuring", "cleaningup",
        "shuttingdown", "activating", "deactivating", "errorprocessing"]
    assert len(port.call("~/get_transition_graph").available_transitions) == 7


def test_a_transition_not_available_is_refused_and_changes_nothing() -> None:
    port, lifecycle, called = managed()
    assert not change(port, label="activate")
    assert "not available in state unconfigured; available: configure, shutdown" in \
        lifecycle.last_failure
    assert not change(port, id=99)
    assert state(port) == (1, "unconfigured") and called == [] and events(port) == []


def test_a_failed_callback_goes_back_to_where_it_started() -> None:
    def refuse() -> None:
        raise TransitionFailed("port /dev/ttyACM0 does not open")

    port, lifecycle, _ = managed(on_configure=refuse)
    assert not change(port, label="configure")
    assert state(port) == (1, "unconfigured")
    assert lifecycle.last_failure == "configure failed: port /dev/ttyACM0 does not open"
    assert events(port)[-1] == (11, "configuring", "unconfigured")


@pytest.mark.parametrize(("on_error", "end"), [(None, (1, "unconfigured")),
                                               ("raise", (4, "finalized"))])
def test_an_error_runs_the_error_callback(on_error: str | None, end: tuple[int, str]) -> None:
    def broken() -> None:
        raise RuntimeError("bus fault")

    def error_too() -> None:
        if on_error == "raise":
            raise OSError("cannot release")

    port, lifecycle, called = managed(on_activate=broken, on_error=error_too)
    assert change(port, label="configure")
    assert not change(port, label="activate")
    assert lifecycle.last_failure == "activate raised RuntimeError: bus fault"
    assert called == ["on_configure", "on_activate", "on_error"]
    assert state(port) == end
    assert events(port)[-2:] == [(32, "activating", "errorprocessing"),
                                 (60 if on_error is None else 62, "errorprocessing", end[1])]


def test_shutdown_from_any_primary_state_finalizes_even_when_it_fails() -> None:
    def refuse() -> None:
        raise TransitionFailed("device did not answer")

    port, _, _ = managed()
    assert change(port, label="configure") and change(port, label="activate")
    assert change(port, label="shutdown") and state(port) == (4, "finalized")
    assert events(port)[-2:] == [(7, "active", "shuttingdown"), (50, "shuttingdown", "finalized")]
    assert available(port) == [] and not change(port, label="configure")
    port, _, _ = managed(on_shutdown=refuse)
    assert not change(port, id=5) and state(port) == (4, "finalized")
