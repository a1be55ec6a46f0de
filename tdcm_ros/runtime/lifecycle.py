"""The managed (lifecycle) node protocol of ROS 2 on any port, so one implementation serves
both runtimes: the services ``~/change_state``, ``~/get_state``, ``~/get_available_states``,
``~/get_available_transitions``, ``~/get_transition_graph`` and the topic
``~/transition_event`` of ``lifecycle_msgs`` (what ``ros2 lifecycle`` and a lifecycle manager
call), with rcl's default state machine
(https://design.ros2.org/articles/node_lifecycle.html).

The node starts ``unconfigured``. A transition runs its callback on the node's thread:
returning is success (the goal state), raising :class:`TransitionFailed` is failure (back to
the start state; shutdown goes on to ``finalized``), any other exception is an error: the
error callback runs (success: ``unconfigured``, else ``finalized``). Every step is published
on ``~/transition_event``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import TdcmError
from tdcm_ros.runtime.port import NodePort, QoS

UNCONFIGURED, INACTIVE, ACTIVE, FINALIZED = 1, 2, 3, 4
CONFIGURING, CLEANINGUP, SHUTTINGDOWN, ACTIVATING, DEACTIVATING, ERRORPROCESSING = range(10, 16)
#: lifecycle_msgs/msg/State ids and labels, as rcl names them.
STATES = {UNCONFIGURED: "unconfigured", INACTIVE: "inactive", ACTIVE: "active",
          FINALIZED: "finalized", CONFIGURING: "configuring", CLEANINGUP: "cleaningup",
          SHUTTINGDOWN: "shuttingdown", ACTIVATING: "activating",
          DEACTIVATING: "deactivating", ERRORPROCESSING: "errorprocessing"}
PRIMARY_STATES = (UNCONFIGURED, INACTIVE, ACTIVE, FINALIZED)


@dataclass(frozen=True)
class _Transition:
    """A transition a client asks for: its lifecycle_msgs/msg/Transition id and label, the
    primary state it starts from, the transition state it goes through, the callback and the
    goal on success; ``result_ids``: the ids rcl gives its success, failure and error."""

    id: int
    label: str
    start: int
    through: int
    callback: str
    goal: int
    result_ids: tuple[int, int, int]


TRANSITIONS = (
    _Transition(1, "configure", UNCONFIGURED, CONFIGURING, "on_configure", INACTIVE, (10, 11, 12)),
    _Transition(2, "cleanup", INACTIVE, CLEANINGUP, "on_cleanup", UNCONFIGURED, (20, 21, 22)),
    _Transition(3, "activate", INACTIVE, ACTIVATING, "on_activate", ACTIVE, (30, 31, 32)),
    _Transition(4, "deactivate", ACTIVE, DEACTIVATING, "on_deactivate", INACTIVE, (40, 41, 42)),
    _Transition(5, "shutdown", UNCONFIGURED, SHUTTINGDOWN, "on_shutdown", FINALIZED,
                (50, 51, 52)),
    _Transition(6, "shutdown", INACTIVE, SHUTTINGDOWN, "on_shutdown", FINALIZED, (50, 51, 52)),
    _Transition(7, "shutdown", ACTIVE, SHUTTINGDOWN, "on_shutdown", FINALIZED, (50, 51, 52)),
)
#: The error callback's transitions out of ``errorprocessing`` (success, failure, error).
ERROR_RESULT_IDS = (60, 61, 62)
_RESULT_LABELS = ("transition_success", "transition_failure", "transition_error")


class TransitionFailed(TdcmError):
    """Raised by a transition callback that did not do its job: the node goes back to the
    state it started from (shutdown: on to ``finalized``); the message says why."""


class Lifecycle:
    """The lifecycle protocol of one node; ``callbacks`` maps ``on_configure``,
    ``on_cleanup``, ``on_activate``, ``on_deactivate``, ``on_shutdown`` and ``on_error`` to
    functions of no argument (a missing one succeeds doing nothing)."""

    def __init__(self, port: NodePort, callbacks: Mapping[str, Callable[[], None]]) -> None:
        self.port = port
        self.callbacks = dict(callbacks)
        self.state = UNCONFIGURED
        self.last_failure = ""
        self.events = port.create_publisher("~/transition_event",
                                            "lifecycle_msgs/msg/TransitionEvent", QoS(depth=10))
        for name, type_name, handler in (
                ("change_state", "ChangeState", self._on_change_state),
                ("get_state", "GetState", self._on_get_state),
                ("get_available_states", "GetAvailableStates", self._on_available_states),
                ("get_available_transitions", "GetAvailableTransitions",
                 self._on_available_transitions),
                ("get_transition_graph", "GetAvailableTransitions", self._on_graph)):
            port.create_service(f"~/{name}", f"lifecycle_msgs/srv/{type_name}", handler)

    @property
    def label(self) -> str:
        """The current state's label."""
        return STATES[self.state]

    def trigger(self, transition: int | str) -> bool:
        """Run ``transition`` (an id or a label) from the current state; False, with
        :attr:`last_failure` saying why, if it is not available there or did not succeed."""
        chosen = [t for t in TRANSITIONS if t.start == self.state
                  and (t.id == transition or t.label == transition)]
        if not chosen:
            self.last_failure = (f"transition {transition!r} is not available in state "
                                 f"{self.label}; available: "
                                 f"{', '.join(t.label for t in self._available()) or 'none'}")
            self.port.logger.warning("lifecycle: %s", self.last_failure)
            return False
        return self._run(chosen[0])

    def _run(self, transition: _Transition) -> bool:
        start = self.state
        self._step(transition.id, transition.label, start, transition.through)
        success, failure, error = transition.result_ids
        try:
            self.callbacks.get(transition.callback, _nothing)()
        except TransitionFailed as failed:
            self.last_failure = f"{transition.label} failed: {failed}"
            self.port.logger.warning("lifecycle: %s", self.last_failure)
            goal = FINALIZED if transition.goal == FINALIZED else start
            self._step(failure, _RESULT_LABELS[1], transition.through, goal)
            return False
        except Exception as raised:  # noqa: BLE001 -- an error of any kind is rcl's "error"
            self.last_failure = f"{transition.label} raised {type(raised).__name__}: {raised}"
            self.port.logger.error("lifecycle: %s", self.last_failure)
            self._step(error, _RESULT_LABELS[2], transition.through, ERRORPROCESSING)
            self._process_error()
            return False
        self._step(success, _RESULT_LABELS[0], transition.through, transition.goal)
        self.last_failure = ""
        return True

    def _process_error(self) -> None:
        """The error callback: success leaves the node ``unconfigured``, else ``finalized``."""
        success, _, error = ERROR_RESULT_IDS
        try:
            self.callbacks.get("on_error", _nothing)()
        except Exception as raised:  # noqa: BLE001 -- as rcl: any failure finalizes
            self.port.logger.error("lifecycle: on_error raised %s: %s", type(raised).__name__,
                                   raised)
            self._step(error, _RESULT_LABELS[2], ERRORPROCESSING, FINALIZED)
            return
        self._step(success, _RESULT_LABELS[0], ERRORPROCESSING, UNCONFIGURED)

    def _step(self, transition_id: int, label: str, start: int, goal: int) -> None:
        self.state = goal
        self.port.logger.info("lifecycle: %s -> %s", STATES[start], STATES[goal])
        self.events.publish(from_dict("lifecycle_msgs/msg/TransitionEvent", {
            "timestamp": self.port.now_ns(), "transition": {"id": transition_id, "label": label},
            "start_state": _state(start), "goal_state": _state(goal)}))

    def _available(self) -> list[_Transition]:
        return [t for t in TRANSITIONS if t.start == self.state]

    # --- services -------------------------------------------------------------------------
    def _on_change_state(self, request: Any) -> Any:
        wanted = request.transition
        ok = self.trigger(str(wanted.label) if wanted.label else int(wanted.id))
        return from_dict("lifecycle_msgs/srv/ChangeState_Response", {"success": ok})

    def _on_get_state(self, _request: Any) -> Any:
        return from_dict("lifecycle_msgs/srv/GetState_Response",
                         {"current_state": _state(self.state)})

    def _on_available_states(self, _request: Any) -> Any:
        return from_dict("lifecycle_msgs/srv/GetAvailableStates_Response",
                         {"available_states": [_state(s) for s in STATES]})

    def _on_available_transitions(self, _request: Any) -> Any:
        return _descriptions(self._available())

    def _on_graph(self, _request: Any) -> Any:
        return _descriptions(list(TRANSITIONS))


def _nothing() -> None:
    """A transition callback a node did not give: it succeeds."""


def _state(state: int) -> dict[str, Any]:
    return {"id": state, "label": STATES[state]}


def _descriptions(transitions: list[_Transition]) -> Any:
    return from_dict("lifecycle_msgs/srv/GetAvailableTransitions_Response", {
        "available_transitions": [{"transition": {"id": t.id, "label": t.label},
                                   "start_state": _state(t.start),
                                   "goal_state": _state(t.through)} for t in transitions]})
