"""An in-memory :class:`~tdcm_ros.runtime.port.NodePort` with a manual clock: node logic runs
in-process, with no zenoh and no rclpy (tests, examples, offline replays).

Parameters are checked by the same :class:`ParameterStore` as both runtimes. Messages make a CDR
round trip on the way in (:meth:`MemoryPort.deliver`) and out (``publish``), as a transport
would carry them, and are kept per topic as the node names it (not resolved). Timers fire only
when the clock is moved with :meth:`MemoryPort.advance`. A callback queued with ``call_soon``
runs when the callback under way returns, as on an idle executor; messages delivered inside
:meth:`MemoryPort.burst` arrive together, as while the node is busy, and those callbacks run
after them::

    port = MemoryPort({"period": 0.1}, name="talker")
    node = Talker(port)
    port.advance(1.0)                      # ten ticks
    port.messages("chatter")
    port.call("~/reset")                   # a service the node serves, as the node names it
    with port.burst():                     # (a node subscribing to "in") both arrive
        port.deliver("in", first)          # while the node is busy
        port.deliver("in", second)
"""

from __future__ import annotations

import logging
from collections import defaultdict, deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from tdcm_ros.bagio import deserialize, from_dict, normalize_service_type, serialize
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.names import fully_qualified_node_name
from tdcm_ros.runtime.parameters import (
    P,
    ParameterStore,
    ParamSpec,
    ParamValue,
    SetCallback,
    Validator,
)
from tdcm_ros.runtime.port import DEFAULT_QOS, SERVICE_TIMEOUT_S, NodePort, QoS


class MemoryPublisher:
    """A publisher whose messages land in its port's :attr:`MemoryPort.published`."""

    def __init__(self, port: MemoryPort, topic: str, type_name: str, qos: QoS) -> None:
        self.port, self.topic, self.type_name, self.qos = port, topic, type_name, qos

    def publish(self, message: Any) -> None:
        """Keep the message after a CDR round trip, stamped with the port's clock."""
        self.publish_cdr(serialize(message, self.type_name))

    def publish_cdr(self, data: bytes) -> None:
        """Keep the decoded CDR bytes, stamped with the port's clock."""
        self.port.published[self.topic].append(deserialize(data, self.type_name))
        self.port.sent_ns[self.topic].append(self.port.clock_ns)

    def matched(self) -> bool:
        """Always: the port keeps every message published."""
        return True


class MemoryTimer:
    """A periodic timer due every ``period_ns`` of the port's clock."""

    def __init__(self, period_ns: int, callback: Callable[[], None], now_ns: int) -> None:
        self.period_ns, self.callback = period_ns, callback
        self.due_ns = now_ns + period_ns
        self.cancelled = False

    def cancel(self) -> None:
        """Stop the timer; it does not fire again."""
        self.cancelled = True


def _answer(type_name: str, handler: Callable[[Any], Any], request: Any) -> Any:
    """``handler``'s response to ``request`` (an empty one if ``None``) of service
    ``type_name``, both through a CDR round trip as a transport would carry them."""
    request_type, response_type = f"{type_name}_Request", f"{type_name}_Response"
    if request is None:
        request = from_dict(request_type, {})
    response = handler(deserialize(serialize(request, request_type), request_type))
    return deserialize(serialize(response, response_type), response_type)


class MemoryPort:
    """NodePort of one node: parameters from ``overrides``, a clock at ``start_ns`` (ns since
    the UNIX epoch), published messages and their send times (ns) per topic."""

    def __init__(self, overrides: dict[str, Any] | None = None, *, name: str = "node",
                 namespace: str = "/", start_ns: int = 1_700_000_000_000_000_000) -> None:
        self.node_name, self.namespace = name, namespace
        self.logger = logging.getLogger(fully_qualified_node_name(namespace, name))
        self.store = ParameterStore(overrides, warn=self.logger.warning)
        self.clock_ns = start_ns
        self.published: defaultdict[str, list[Any]] = defaultdict(list)
        self.sent_ns: defaultdict[str, list[int]] = defaultdict(list)
        self.publishers: dict[str, MemoryPublisher] = {}
        self.subscriptions: dict[str, tuple[str, Callable[[Any], None], QoS]] = {}
        self.timers: list[MemoryTimer] = []
        self.services: dict[str, tuple[str, Callable[[Any], Any]]] = {}
        self.remote_services: dict[str, tuple[str, Callable[[Any], Any]]] = {}
        #: what :meth:`graph_hubs` answers (a test cuts the graph, or restarts its router)
        self.hubs: frozenset[str] = frozenset({"memory"})
        self._soon: deque[Callable[[], None]] = deque()  # queued by call_soon
        self._held = 0  # callbacks (and bursts) under way: call_soon's wait for them

    def declare_parameter(self, name: str, default: P, *, description: str = "",
                          range: tuple[float, float] | None = None,
                          validator: Validator | None = None,
                          read_only: bool = False, formerly: tuple[str, ...] = ()) -> P:
        """Declare a parameter; returns the override or the default, checked."""
        return self.store.declare(ParamSpec(name, default, description, range, validator,
                                            read_only, formerly))

    def get_parameter(self, name: str) -> ParamValue:
        """Current value of a declared parameter."""
        return self.store.get(name)

    def unused_overrides(self) -> list[str]:
        """Names in ``overrides`` no declared parameter took."""
        return self.store.unused_overrides()

    def add_on_set_parameters(self, callback: SetCallback) -> None:
        """Add a check run on each change made with :meth:`ParameterStore.set` on :attr:`store`."""
        self.store.add_on_set(callback)

    def create_publisher(self, topic: str, type_name: str,
                         qos: QoS = DEFAULT_QOS) -> MemoryPublisher:
        """A publisher on ``topic``; its messages go to ``published[topic]``."""
        self.publishers[topic] = MemoryPublisher(self, topic, type_name, qos)
        return self.publishers[topic]

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: QoS = DEFAULT_QOS) -> None:
        """Subscribe; :meth:`deliver` hands ``callback`` the messages."""
        self.subscriptions[topic] = (type_name, callback, qos)

    def create_service(self, name: str, type_name: str,
                       handler: Callable[[Any], Any]) -> None:
        """Serve ``type_name`` on ``name``; :meth:`call` hands ``handler`` the requests."""
        self.services[name] = (normalize_service_type(type_name), handler)

    def call(self, name: str, request: Any = None) -> Any:
        """Call the service ``name`` (an empty request by default), with a CDR round trip of
        the request and of the response, as a transport would carry them."""
        if name not in self.services:
            raise RuntimePortError(f"no service {name!r}; served: {sorted(self.services)}")
        with self.burst():
            return _answer(*self.services[name], request)

    def add_remote_service(self, name: str, type_name: str,
                           handler: Callable[[Any], Any]) -> None:
        """Stand in for another node's service ``name``: :meth:`call_service` hands
        ``handler`` the node's requests."""
        self.remote_services[name] = (normalize_service_type(type_name), handler)

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = SERVICE_TIMEOUT_S) -> Any:
        """The node calls another node's service: the handler given to
        :meth:`add_remote_service`, with CDR round trips; ``RuntimePortError`` if there is
        none (as a runtime after ``timeout`` s without a server)."""
        service = normalize_service_type(type_name)
        if self.remote_services.get(name, ("", None))[0] != service:
            raise RuntimePortError(f"service {name} ({service}) has no server")
        return _answer(*self.remote_services[name], request)

    def create_timer(self, period: float, callback: Callable[[], None]) -> MemoryTimer:
        """Call ``callback`` every ``period`` s of the port's clock (see :meth:`advance`)."""
        if not period > 0:
            raise InputError(f"timer period = {period!r} s must be > 0", parameter="period",
                             value=period, allowed="> 0 s")
        timer = MemoryTimer(round(period * 1e9), callback, self.clock_ns)
        self.timers.append(timer)
        return timer

    def call_soon(self, callback: Callable[[], None]) -> None:
        """Run ``callback`` once the callback (or :meth:`burst`) under way ends; at once if
        none is."""
        self._soon.append(callback)
        self._run_soon()

    @contextmanager
    def burst(self) -> Iterator[None]:
        """Hold the callbacks of :meth:`call_soon` until the block ends, as a busy executor
        would: messages delivered in it all reach their subscriptions first."""
        self._held += 1
        try:
            yield
        finally:
            self._held -= 1
        self._run_soon()

    def _run_soon(self) -> None:
        """The queued :meth:`call_soon` callbacks in order, unless a callback is under way."""
        if self._held:
            return
        self._held += 1  # one queued now waits for the one running
        try:
            while self._soon:
                self._soon.popleft()()
        finally:
            self._held -= 1

    def now_ns(self) -> int:
        """The port's clock, ns since the UNIX epoch."""
        return self.clock_ns

    def graph_hubs(self) -> frozenset[str]:
        """:attr:`hubs`."""
        return self.hubs

    def deliver(self, topic: str, message: Any) -> None:
        """Hand ``message`` to the subscription on ``topic`` after a CDR round trip."""
        if topic not in self.subscriptions:
            raise RuntimePortError(f"no subscription on {topic!r}; subscribed: "
                                   f"{sorted(self.subscriptions)}")
        type_name, callback, _ = self.subscriptions[topic]
        with self.burst():
            callback(deserialize(serialize(message, type_name), type_name))

    def advance(self, seconds: float) -> None:
        """Move the clock forward by ``seconds`` (s), firing the timers due in time order."""
        end = self.clock_ns + round(seconds * 1e9)
        while True:
            live = [t for t in self.timers if not t.cancelled and t.due_ns <= end]
            if not live:
                break
            timer = min(live, key=lambda t: t.due_ns)
            self.clock_ns = timer.due_ns
            timer.due_ns += timer.period_ns
            with self.burst():
                timer.callback()
        self.clock_ns = end

    def messages(self, topic: str) -> list[Any]:
        """The messages published on ``topic`` so far, in order."""
        return list(self.published[topic])

    def sent(self, topic: str) -> list[tuple[int, Any]]:
        """``(send time (ns), message)`` of each message published on ``topic``."""
        return list(zip(self.sent_ns[topic], self.published[topic], strict=True))


#: The type checker holds the port to the protocol every node is written against.
_CONTRACT: type[NodePort] = MemoryPort
