"""An in-memory NodePort with a manual clock, for running node logic in-process."""

from __future__ import annotations

import logging
from collections import defaultdict
from collections.abc import Callable
from typing import Any

from tdcm_ros.bagio import deserialize, serialize
from tdcm_ros.runtime.parameters import ParameterStore, ParamSpec
from tdcm_ros.runtime.port import DEFAULT_QOS, QoS


class _Publisher:
    def __init__(self, port: MemoryPort, topic: str, type_name: str, qos: QoS) -> None:
        self.port, self.topic, self.type_name, self.qos = port, topic, type_name, qos

    def publish(self, message: Any) -> None:
        """Store the message after a CDR round trip (as a transport would deliver it)."""
        data = serialize(message, self.type_name)
        self.port.published[self.topic].append((self.port.clock_ns,
                                                deserialize(data, self.type_name)))

    def publish_cdr(self, data: bytes) -> None:
        self.port.published[self.topic].append((self.port.clock_ns,
                                                deserialize(data, self.type_name)))


class _Timer:
    def __init__(self, period: float, callback: Callable[[], None], now_ns: int) -> None:
        self.period_ns = round(period * 1e9)
        self.callback = callback
        self.due_ns = now_ns + self.period_ns
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class MemoryPort:
    """NodePort of one node: parameters from ``overrides``, messages kept per topic."""

    def __init__(self, overrides: dict[str, Any] | None = None, *, name: str = "mocap_node",
                 namespace: str = "/", start_ns: int = 1_700_000_000_000_000_000) -> None:
        self.node_name, self.namespace = name, namespace
        self.logger = logging.getLogger(f"test.{name}")
        self.store = ParameterStore(overrides)
        self.clock_ns = start_ns
        self.published: defaultdict[str, list[tuple[int, Any]]] = defaultdict(list)
        self.publishers: dict[str, _Publisher] = {}
        self.subscriptions: dict[str, tuple[str, Callable[[Any], None], QoS]] = {}
        self.timers: list[_Timer] = []

    def declare_parameter(self, name: str, default: Any, *, description: str = "",
                          range: tuple[float, float] | None = None, validator: Any = None,
                          read_only: bool = False) -> Any:
        return self.store.declare(ParamSpec(name, default, description, range, validator,
                                            read_only))

    def get_parameter(self, name: str) -> Any:
        return self.store.get(name)

    def add_on_set_parameters(self, callback: Any) -> None:
        self.store.add_on_set(callback)

    def create_publisher(self, topic: str, type_name: str, qos: QoS = DEFAULT_QOS) -> _Publisher:
        self.publishers[topic] = _Publisher(self, topic, type_name, qos)
        return self.publishers[topic]

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: QoS = DEFAULT_QOS) -> None:
        self.subscriptions[topic] = (type_name, callback, qos)

    def create_timer(self, period: float, callback: Callable[[], None]) -> _Timer:
        timer = _Timer(period, callback, self.clock_ns)
        self.timers.append(timer)
        return timer

    def now_ns(self) -> int:
        return self.clock_ns

    def deliver(self, topic: str, message: Any) -> None:
        """Hand ``message`` to the subscription on ``topic`` (after a CDR round trip)."""
        type_name, callback, _ = self.subscriptions[topic]
        callback(deserialize(serialize(message, type_name), type_name))

    def advance(self, seconds: float) -> None:
        """Move the clock forward, firing timers in due order."""
        end = self.clock_ns + round(seconds * 1e9)
        while True:
            live = [t for t in self.timers if not t.cancelled and t.due_ns <= end]
            if not live:
                break
            timer = min(live, key=lambda t: t.due_ns)
            self.clock_ns = timer.due_ns
            timer.due_ns += timer.period_ns
            timer.callback()
        self.clock_ns = end

    def messages(self, topic: str) -> list[Any]:
        return [message for _, message in self.published[topic]]
