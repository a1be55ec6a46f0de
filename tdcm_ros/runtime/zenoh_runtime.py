"""The embedded runtime: node logic on Zenoh, speaking rmw_zenoh's Jazzy conventions.

One :class:`ZenohContext` per process = one zenoh session (peer mode, connected to a router at
``TDCM_ZENOH_ENDPOINT``, default ``tcp/127.0.0.1:7447``; multicast scouting off, listening on
loopback only). ``TDCM_ZENOH_CONFIG`` names a zenoh JSON5 config file (TLS, authentication, access
control) whose settings stand, with the role's mode and endpoints set on top of it
(:mod:`tdcm_ros.runtime.zenoh_config`).
``ROS_DOMAIN_ID`` selects the domain (default 0). Callbacks of every node run one at a time on the
thread that calls :meth:`ZenohContext.spin`.

Services are rmw_zenoh's (:mod:`tdcm_ros.runtime.wire`): a queryable and an ``SS`` token per
server, queries with rmw_zenoh's attachment from :meth:`ZenohContext.call_service`.
Every node serves the six ``rcl_interfaces`` parameter services and publishes
``/parameter_events`` as an rclpy node does (:mod:`tdcm_ros.runtime.param_services`), so
``ros2 param`` and ``tdcm param`` (:mod:`tdcm_ros.runtime.param_client`) reach it.
Each node's logger also goes to ``/rosout`` (:mod:`tdcm_ros.runtime.rosout`), as a ROS node's.
"""

from __future__ import annotations

import heapq
import itertools
import logging
import os
import queue
import threading
import time
from collections import deque
from collections.abc import Callable, Collection
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass, field
from typing import Any

import zenoh
import zenoh.ext

from tdcm_ros.bagio import (
    BagError,
    deserialize,
    from_dict,
    normalize_service_type,
    normalize_type_name,
    prepare_codec,
    serialize,
    service_type_hash,
    type_hash,
)
from tdcm_ros.errors import InputError
from tdcm_ros.runtime import wire
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.guard import CallbackGuard
from tdcm_ros.runtime.names import (
    fully_qualified_node_name,
    normalize_namespace,
    resolve_topic,
)
from tdcm_ros.runtime.param_services import (
    PARAMETER_EVENT_TYPE,
    PARAMETER_EVENTS_QOS,
    PARAMETER_EVENTS_TOPIC,
    PARAMETER_SERVICES_QOS,
    ParameterServices,
)
from tdcm_ros.runtime.parameters import (
    P,
    ParameterStore,
    ParamSpec,
    ParamValue,
    SetCallback,
    Validator,
)
from tdcm_ros.runtime.port import (
    CLOCK_QOS,
    CLOCK_TOPIC,
    CLOCK_TYPE,
    DEFAULT_QOS,
    SERVICE_TIMEOUT_S,
    NodePort,
    QoS,
)
from tdcm_ros.runtime.rosout import ROSOUT_QOS, ROSOUT_TOPIC, RosoutHandler
from tdcm_ros.runtime.spec_params import NODE_COMMON, declare_specs
from tdcm_ros.runtime.throttle import Throttled
from tdcm_ros.runtime.wire import RawSample
from tdcm_ros.runtime.zenoh_query import gather, graph_tokens, servers_of

ENDPOINT_ENV = "TDCM_ZENOH_ENDPOINT"
CONFIG_ENV = "TDCM_ZENOH_CONFIG"
DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
HEARTBEAT_PERIOD_S = 0.5
"""Sporadic heartbeat of a reliable transient-local publisher (s): rmw_zenoh's
``SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD`` (``rmw_publisher_data.cpp``)."""
#: Longest time (s) a service handler may take on the executor before the query fails.
SERVICE_HANDLER_TIMEOUT_S = 5.0


def _reliability(qos: QoS) -> zenoh.Reliability:
    return (zenoh.Reliability.RELIABLE if qos.reliability == "reliable"
            else zenoh.Reliability.BEST_EFFORT)


def domain_id() -> int:
    """``ROS_DOMAIN_ID`` (default 0)."""
    raw = os.environ.get("ROS_DOMAIN_ID", "0") or "0"
    if not raw.isdigit() or int(raw) > 232:
        raise InputError(f"ROS_DOMAIN_ID = {raw!r} is out of range; allowed: 0..232",
                         parameter="ROS_DOMAIN_ID", value=raw, allowed="0..232")
    return int(raw)


def endpoint() -> str:
    """The router endpoint: ``TDCM_ZENOH_ENDPOINT`` or ``tcp/127.0.0.1:7447``."""
    return os.environ.get(ENDPOINT_ENV) or DEFAULT_ENDPOINT


def session_config(*, mode: str = "peer", router_endpoint: str | None = None) -> zenoh.Config:
    """Zenoh config of a ``peer`` or ``router`` session: loopback defaults like rmw_zenoh's, or
    the ``TDCM_ZENOH_CONFIG`` file (a router: ``TDCM_ZENOH_ROUTER_CONFIG`` first) with ``mode``
    and the endpoints of the role on top; see :func:`tdcm_ros.runtime.zenoh_config.build`.
    """
    from tdcm_ros.runtime import zenoh_config

    return zenoh_config.build(mode=mode, endpoint=router_endpoint or endpoint(),
                              path=os.environ.get(CONFIG_ENV))


def open_session(*, mode: str = "peer", router_endpoint: str | None = None) -> zenoh.Session:
    """Open a zenoh session with :func:`session_config`; a file the config names (certificates,
    users) must be readable. A peer configured by a file
    (``TDCM_ZENOH_CONFIG``: TLS, passwords) must reach its router within
    :data:`~tdcm_ros.runtime.zenoh_diagnosis.ROUTER_WAIT_S` s, else ``RuntimePortError`` says
    why (a missing file, the certificate, the password): a misconfiguration fails closed."""
    from tdcm_ros.runtime.zenoh_diagnosis import missing_files, require_router

    config = session_config(mode=mode, router_endpoint=router_endpoint)
    if missing := missing_files(config):
        raise RuntimePortError(f"cannot open zenoh session ({mode}): its config names files "
                               f"that cannot be read: {'; '.join(missing)}")
    try:
        session = zenoh.open(config)
    except zenoh.ZError as error:
        raise RuntimePortError(f"cannot open zenoh session ({mode}, "
                               f"{router_endpoint or endpoint()}): {error}") from error
    if mode == "peer" and os.environ.get(CONFIG_ENV):
        try:
            require_router(session, config, router_endpoint or endpoint())
        except RuntimePortError:
            session.close()
            raise
    return session


@dataclass(order=True)
class _Timer:
    due_ns: int
    seq: int
    period_ns: int = field(compare=False)
    callback: Callable[[], None] = field(compare=False)
    cancelled: bool = field(default=False, compare=False)

    def cancel(self) -> None:
        self.cancelled = True


class _Executor:
    """Single-threaded callback loop fed by zenoh threads (tasks) and timers; ``clock`` gives
    the time its timers run on (ns, monotonic)."""

    def __init__(self, clock: Callable[[], int] = time.monotonic_ns) -> None:
        self._clock = clock
        # queue.Queue, not SimpleQueue: CPython's SimpleQueue.get(timeout) blocks until the next
        # put when a signal interrupts it and its handler outlasts the remaining timeout (it
        # recomputes a negative timeout, which means "forever"); a player stopped by Ctrl-C
        # then hung, as nothing else is queued there. Queue waits on threading locks, which
        # treat an expired deadline as a timeout.
        self._tasks: queue.Queue[Callable[[], None]] = queue.Queue()
        self._timers: list[_Timer] = []
        self._seq = itertools.count()
        self.stop = threading.Event()

    def post(self, task: Callable[[], None]) -> None:
        self._tasks.put(task)

    def call(self, task: Callable[[], Any], timeout: float) -> Any:
        """Run ``task`` on the executor thread and wait for its result."""
        future: Future[Any] = Future()

        def run() -> None:
            try:
                future.set_result(task())
            except Exception as error:  # noqa: BLE001 - handed to the waiting thread, which re-raises it
                future.set_exception(error)

        self.post(run)
        try:
            return future.result(timeout)
        except FutureTimeout as error:
            raise RuntimePortError(f"executor busy for more than {timeout} s") from error

    def add_timer(self, period_s: float, callback: Callable[[], None]) -> _Timer:
        period_ns = int(period_s * 1e9)
        timer = _Timer(self._clock() + period_ns, next(self._seq), period_ns, callback)
        heapq.heappush(self._timers, timer)
        self.post(lambda: None)
        return timer

    def spin_once(self, timeout: float) -> None:
        """Run each timer due now once, then wait up to ``timeout`` s (less if a timer falls
        due sooner) for tasks and run those queued. A timer whose callback outlasts its period
        skips the periods it missed (as rcl's timers do): it neither runs again in the same
        call nor keeps the loop from its tasks and from a stop request."""
        now = self._clock()
        due: list[_Timer] = []
        while self._timers and (self._timers[0].cancelled or self._timers[0].due_ns <= now):
            timer = heapq.heappop(self._timers)
            if not timer.cancelled:
                due.append(timer)
        for k, timer in enumerate(due):
            if self.stop.is_set():  # the rest keep their due times
                for left in due[k:]:
                    heapq.heappush(self._timers, left)
                return
            if timer.cancelled:  # by a callback that ran before it here
                continue
            timer.callback()
            timer.due_ns += timer.period_ns
            after = self._clock()
            if timer.due_ns <= after:  # missed periods: the next one after now, on its grid
                timer.due_ns += ((after - timer.due_ns) // timer.period_ns + 1) * timer.period_ns
            heapq.heappush(self._timers, timer)
        now = self._clock()
        wait = timeout
        if self._timers:
            wait = min(wait, max(0.0, (self._timers[0].due_ns - now) / 1e9))
        try:
            task = self._tasks.get(timeout=wait)
        except queue.Empty:
            return
        task()
        for _ in range(self._tasks.qsize()):
            self._tasks.get_nowait()()

    def spin(self) -> None:
        while not self.stop.is_set():
            self.spin_once(0.1)


class _Publisher:
    """A zenoh publisher on an rmw_zenoh key, with its liveliness token and attachment state."""

    def __init__(self, context: ZenohContext, identity: wire.NodeIdentity, topic: str,
                 type_name: str, qos: QoS) -> None:
        self.topic, self.type_name = topic, type_name
        prepare_codec(type_name)  # not on the callback thread at the first publish
        rihs = type_hash(type_name)
        self.key = wire.topic_key(identity.domain_id, topic, type_name, rihs)
        self.token_key = wire.endpoint_token(identity, context.next_id(), wire.PUBLISHER, topic,
                                             type_name, rihs, qos)
        self._gid = wire.gid_of(self.token_key)
        self._seq = 0
        self._lock = threading.Lock()
        # As rmw_zenoh (rmw_publisher_data.cpp): reliability from the QoS, congestion control
        # drop; transient local keeps a cache of ``depth`` samples for late joiners and is
        # detectable, and reliable + transient local also sends sporadic heartbeats (the last
        # sequence number) so that subscribers detect and recover a lost last sample.
        options: dict[str, Any] = {"reliability": _reliability(qos),
                                   "congestion_control": zenoh.CongestionControl.DROP}
        if qos.durability == "transient_local":
            miss = (zenoh.ext.MissDetectionConfig(heartbeat=None,
                                                  sporadic_heartbeat=HEARTBEAT_PERIOD_S)
                    if qos.reliability == "reliable" else None)
            self._pub: Any = zenoh.ext.declare_advanced_publisher(
                context.session, self.key, cache=zenoh.ext.CacheConfig(qos.depth),
                sample_miss_detection=miss, publisher_detection=True, **options)
        else:
            self._pub = context.session.declare_publisher(self.key, **options)
        self._token = context.session.liveliness().declare_token(self.token_key)

    def publish(self, message: Any) -> None:
        """Serialise ``message`` as ``type_name`` and send it."""
        self.publish_cdr(serialize(message, self.type_name))

    def publish_cdr(self, data: bytes) -> None:
        """Send CDR bytes with rmw_zenoh's attachment (sequence number from 1, time, GID)."""
        with self._lock:
            self._seq += 1
            attachment = wire.encode_attachment(self._seq, time.time_ns(), self._gid)
            self._pub.put(data, attachment=attachment)

    def matched(self) -> bool:
        """True when at least one subscriber's key matches."""
        return bool(self._pub.matching_status.matching)

    def close(self) -> None:
        self._token.undeclare()
        self._pub.undeclare()


class _Subscription:
    """A zenoh subscriber whose samples reach the executor through a keep-last queue."""

    def __init__(self, context: ZenohContext, identity: wire.NodeIdentity, topic: str,
                 type_name: str, callback: Callable[[RawSample], None], qos: QoS,
                 any_type: bool = False) -> None:
        self.topic, self.type_name = topic, type_name
        self._callback = callback
        self._executor = context.executor
        self._queue: deque[RawSample] = deque(maxlen=qos.depth)
        self.refused = 0
        self._refusals = Throttled()
        domain = identity.domain_id
        if any_type:
            self.key = f"{domain}/{topic.strip('/')}/*/*"
            self._token = None
        else:
            prepare_codec(type_name)  # not on the callback thread at the first sample
            rihs = type_hash(type_name)
            self.key = wire.topic_key(domain, topic, type_name, rihs)
            token = wire.endpoint_token(identity, context.next_id(), wire.SUBSCRIPTION, topic,
                                        type_name, rihs, qos)
            self._token = context.session.liveliness().declare_token(token)
        if qos.durability == "transient_local":
            # As rmw_zenoh (rmw_subscription_data.cpp): detectable, the late publishers'
            # history of ``depth`` samples, and (reliable) recovery of a missed last sample
            # from the publishers' heartbeats.
            recovery = (zenoh.ext.RecoveryConfig(periodic_queries=None, heartbeat=True)
                        if qos.reliability == "reliable" else None)
            self._sub: Any = zenoh.ext.declare_advanced_subscriber(
                context.session, self.key, self._on_sample,
                history=zenoh.ext.HistoryConfig(detect_late_publishers=True,
                                                max_samples=qos.depth),
                recovery=recovery, subscriber_detection=True)
        else:
            self._sub = context.session.declare_subscriber(self.key, self._on_sample)

    def _on_sample(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if self._token is not None and (key != self.key or sample.attachment is None):
            # not what an rmw_zenoh publisher sends: a put on a wildcard key overlapping this
            # topic (which a router's access list may not match), or a sample without the
            # attachment every rmw_zenoh publisher adds
            self.refused += 1
            suffix = self._refusals.admit("refused")
            if suffix is not None:
                logging.getLogger("tdcm.zenoh").warning(
                    "refused a sample on %s: %s%s", self.topic, "no rmw_zenoh attachment"
                    if key == self.key else f"key {key!r} is not the topic's key", suffix)
            return
        chunks = key.rsplit("/", 2)
        try:
            type_name = wire.ros_type_name(chunks[1])
            attachment = (wire.decode_attachment(sample.attachment.to_bytes())
                          if sample.attachment is not None else None)
        except RuntimePortError:
            logging.getLogger("tdcm.zenoh").warning("dropped sample on %s with a foreign key or "
                                                    "attachment", sample.key_expr)
            return
        self._queue.append(RawSample(self.topic, type_name, sample.payload.to_bytes(), attachment))
        self._executor.post(self._deliver)

    def _deliver(self) -> None:
        if self._queue:
            self._callback(self._queue.popleft())

    def close(self) -> None:
        if self._token is not None:
            self._token.undeclare()
        self._sub.undeclare()


class _Service:
    """A service server in rmw_zenoh's format: a queryable on the service key and an ``SS``
    token; ``answer(request CDR)`` runs on the executor and gives the response CDR or None."""

    def __init__(self, context: ZenohContext, identity: wire.NodeIdentity, name: str,
                 type_name: str, answer: Callable[[bytes], bytes | None],
                 qos: QoS = wire.SERVICE_QOS) -> None:
        self.name, self.type_name = name, type_name
        self._answer, self._executor = answer, context.executor
        rihs = service_type_hash(type_name)
        self.key = wire.topic_key(identity.domain_id, name, type_name, rihs)
        token = wire.endpoint_token(identity, context.next_id(), wire.SERVICE, name, type_name,
                                    rihs, qos)
        self.refused = 0
        self._refusals = Throttled()
        self._queryable = context.session.declare_queryable(self.key, self._on_query,
                                                            complete=True)
        self._token = context.session.liveliness().declare_token(token)

    def _refuse(self, query: zenoh.Query, reason: str) -> None:
        """Answer with an error, count and warn (throttled): not what an rmw_zenoh client sends."""
        self.refused += 1
        suffix = self._refusals.admit("refused")
        if suffix is not None:
            logging.getLogger("tdcm.zenoh").warning("refused a request of %s: %s%s", self.name,
                                                    reason, suffix)
        query.reply_err(f"{self.name}: refused: {reason}")

    def _on_query(self, query: zenoh.Query) -> None:
        key = str(query.key_expr)
        if key != self.key:  # a wildcard query overlapping this service (an ACL may not match)
            self._refuse(query, f"key {key!r} is not the service's key")
            return
        if query.attachment is None:
            self._refuse(query, "no rmw_zenoh attachment")
            return
        try:
            request = wire.decode_attachment(query.attachment.to_bytes())
            payload = query.payload.to_bytes() if query.payload is not None else b""
            response = self._executor.call(lambda: self._answer(payload),
                                           SERVICE_HANDLER_TIMEOUT_S)
        except RuntimePortError as error:
            query.reply_err(f"{self.name}: {error}")
            return
        if response is None:
            query.reply_err(f"{self.name}: no response: the request was undecodable or the "
                            f"handler failed; see the node's log")
            return
        query.reply(self.key, response, attachment=wire.encode_attachment(
            request.sequence_number, time.time_ns(), request.gid))

    def close(self) -> None:
        self._token.undeclare()
        self._queryable.undeclare()


class _Client:
    """A service client in rmw_zenoh's format: an ``SC`` token, sequence numbers from 1."""

    def __init__(self, context: ZenohContext, identity: wire.NodeIdentity, name: str,
                 type_name: str) -> None:
        self.name, self.type_name = name, type_name
        self._context = context
        rihs = service_type_hash(type_name)
        self.key = wire.topic_key(identity.domain_id, name, type_name, rihs)
        token = wire.endpoint_token(identity, context.next_id(), wire.CLIENT, name, type_name,
                                    rihs, wire.SERVICE_QOS)
        self._gid = wire.gid_of(token)
        self._seq = itertools.count(1)
        self._token = context.session.liveliness().declare_token(token)

    def _server_up(self) -> bool:
        return any(t.kind == wire.SERVICE and t.topic == self.name and t.type_name == self.type_name
                   for t in graph_tokens(self._context.session, self._context.domain_id, 0.5,
                                         servers_of(self.name, self.type_name)))

    def call(self, request: bytes, timeout: float) -> bytes:
        """Wait up to ``timeout`` s for a server, send ``request`` (CDR), return the response."""
        end = time.monotonic() + timeout
        while not self._server_up():
            if time.monotonic() > end:
                raise RuntimePortError(
                    f"service {self.name} ({self.type_name}) has no server after {timeout:g} s; "
                    f"is its node running on domain {self._context.domain_id}?")
            time.sleep(0.05)
        seq = next(self._seq)
        attachment = wire.encode_attachment(seq, time.time_ns(), self._gid)
        errors = []
        left = max(0.1, end - time.monotonic())
        replies = gather(lambda handler: self._context.session.get(
            self.key, handler, payload=request, attachment=attachment,
            target=zenoh.QueryTarget.ALL_COMPLETE, consolidation=zenoh.ConsolidationMode.NONE,
            timeout=left), left)
        for reply in replies.kept:
            if reply.ok is None:
                errors.append(reply.err.payload.to_string() if reply.err is not None else "?")
                continue
            if reply.ok.attachment is not None:
                answer = wire.decode_attachment(reply.ok.attachment.to_bytes())
                if answer.sequence_number != seq or answer.gid != self._gid:
                    continue  # not the answer to this request
            return bytes(reply.ok.payload.to_bytes())
        raise RuntimePortError(f"service {self.name} did not answer within {timeout:g} s"
                               + (f": {'; '.join(errors)}" if errors else ""))

    def close(self) -> None:
        self._token.undeclare()


class ZenohNodePort:
    """:class:`tdcm_ros.runtime.port.NodePort` on a zenoh session."""

    def __init__(self, context: ZenohContext, name: str, namespace: str = "/",
                 overrides: dict[str, Any] | None = None) -> None:
        self.namespace = normalize_namespace(namespace)
        self.fqn = fully_qualified_node_name(self.namespace, name)
        self.node_name = name
        self.logger = logging.getLogger(self.fqn)
        self._context = context
        self._params = ParameterStore(overrides, warn=self.logger.warning)
        node_id = context.next_id()
        self.identity = wire.NodeIdentity(context.domain_id, context.zid, node_id,
                                          self.namespace, name)
        self._entities: list[_Publisher | _Subscription | _Service | _Client] = []
        self._clients: dict[tuple[str, str], _Client] = {}
        self._clients_lock = threading.Lock()
        self.guard = CallbackGuard(self.fqn, self.logger, self.create_publisher, self.now_ns)
        self._name_watch = self._watch_name(context)
        self._token = context.session.liveliness().declare_token(wire.node_token(self.identity))
        self._clock_ns, self.use_sim_time = 0, False
        self._parameter_services = ParameterServices(
            self._params, self.fqn, self.logger, self.now_ns,
            self.create_publisher(PARAMETER_EVENTS_TOPIC, PARAMETER_EVENT_TYPE,
                                  PARAMETER_EVENTS_QOS).publish)
        for service, (service_type, handler) in self._parameter_services.handlers().items():
            self._serve(f"~/{service}", service_type, handler, PARAMETER_SERVICES_QOS)
        self._rosout = RosoutHandler(self.fqn, self.create_publisher(
            ROSOUT_TOPIC, "rcl_interfaces/msg/Log", ROSOUT_QOS))
        self.logger.addHandler(self._rosout)
        self.use_sim_time = bool(declare_specs(self, NODE_COMMON, read_only=True)["use_sim_time"])
        if self.use_sim_time:
            self.create_subscription(CLOCK_TOPIC, CLOCK_TYPE, self._on_clock, CLOCK_QOS)

    # parameters
    def _watch_name(self, context: ZenohContext) -> Any:
        """Warn whenever another session's node of this name is in the graph, already or later
        (a liveliness subscriber with history: no wait at start, no miss on a slow router):
        ROS tools, parameter clients and remapping cannot tell two nodes of one name apart."""
        own = wire.node_token(self.identity).split("/")
        selector = "/".join([*own[:2], "*", "*", "*", wire.NODE, *own[6:]])

        def seen(sample: zenoh.Sample) -> None:
            zid = str(sample.key_expr).split("/")[2]
            if sample.kind == zenoh.SampleKind.PUT and zid != context.zid:
                self.logger.warning("another node named %s is in the graph (session %s); "
                                    "tools and parameter clients cannot tell the two apart",
                                    self.fqn, zid)

        return context.session.liveliness().declare_subscriber(selector, seen, history=True)

    def declare_parameter(self, name: str, default: P, *, description: str = "",
                          range: tuple[float, float] | None = None,
                          validator: Validator | None = None,
                          read_only: bool = False, formerly: tuple[str, ...] = ()) -> P:
        """Declare a parameter; returns the YAML override or the default, validated, and
        announces it on ``/parameter_events`` as a new parameter."""
        value = self._params.declare(ParamSpec(name, default, description, range, validator,
                                               read_only, formerly))
        self._parameter_services.publish(new=[name])
        return value

    def get_parameter(self, name: str) -> ParamValue:
        """Current value of a declared parameter."""
        return self._params.get(name)

    def unused_overrides(self) -> list[str]:
        """Names the parameter file sets that no declared parameter took."""
        return self._params.unused_overrides()

    def add_on_set_parameters(self, callback: SetCallback) -> None:
        """Add a check run on each runtime change; raising ``InputError`` rejects it."""
        self._params.add_on_set(callback)

    # endpoints
    def create_publisher(self, topic: str, type_name: str, qos: QoS = DEFAULT_QOS) -> _Publisher:
        """Declare a publisher on the resolved topic."""
        resolved = resolve_topic(topic, self.namespace, self.node_name)
        publisher = _Publisher(self._context, self.identity, resolved,
                               normalize_type_name(type_name), qos)
        self._entities.append(publisher)
        return publisher

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: QoS = DEFAULT_QOS) -> None:
        """Subscribe; ``callback`` gets rosbags messages (undecodable payloads are logged)."""
        name = normalize_type_name(type_name)

        def decode(sample: RawSample) -> None:
            try:
                message = deserialize(sample.data, name)
            except BagError as error:
                self.logger.warning("dropped message on %s: %s", sample.topic, error)
                return
            callback(message)

        self.create_raw_subscription(topic, name, decode, qos)

    def create_raw_subscription(self, topic: str, type_name: str | None,
                                callback: Callable[[RawSample], None], qos: QoS = DEFAULT_QOS) -> None:
        """Subscribe to CDR samples; ``type_name=None`` accepts any type (no liveliness token)."""
        resolved = resolve_topic(topic, self.namespace, self.node_name)
        name = normalize_type_name(type_name) if type_name else ""
        self._entities.append(_Subscription(self._context, self.identity, resolved, name,
                                            self.guard.wrap(f"subscription {resolved}", callback),
                                            qos, any_type=type_name is None))

    def create_service(self, name: str, type_name: str,
                       handler: Callable[[Any], Any]) -> None:
        """Serve ``type_name`` on the resolved ``name`` (queryable and ``SS`` token)."""
        self._serve(name, type_name, handler, wire.SERVICE_QOS)

    def _serve(self, name: str, type_name: str, handler: Callable[[Any], Any], qos: QoS) -> None:
        """:meth:`create_service` with the ``qos`` its token announces."""
        resolved = resolve_topic(name, self.namespace, self.node_name)
        service = normalize_service_type(type_name)
        request_type, response_type = f"{service}_Request", f"{service}_Response"

        guarded = self.guard.wrap(f"service {resolved}",
                                  lambda request: serialize(handler(request), response_type))

        def answer(data: bytes) -> bytes | None:
            try:  # a request that is no CDR of its type is the caller's fault, not a node bug
                request = deserialize(data, request_type)
            except BagError as error:
                self.logger.warning("service %s: request dropped: %s", resolved, error)
                return None
            return guarded(request)

        self._entities.append(_Service(self._context, self.identity, resolved, service, answer,
                                       qos))

    def create_client(self, name: str, type_name: str) -> _Client:
        """A client of service ``name`` (resolved like a topic) of ``type_name``."""
        resolved = resolve_topic(name, self.namespace, self.node_name)
        client = _Client(self._context, self.identity, resolved, normalize_service_type(type_name))
        self._entities.append(client)
        return client

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = SERVICE_TIMEOUT_S) -> Any:
        """Call service ``name`` (resolved like a topic) of ``type_name`` with ``request``
        (default: an empty request); the decoded response. ``RuntimePortError`` if no server
        answers within ``timeout`` s. Blocks the calling thread (any thread but a callback's
        is fine: the answer comes on zenoh's threads)."""
        service = normalize_service_type(type_name)
        with self._clients_lock:
            if (name, service) not in self._clients:
                self._clients[(name, service)] = self.create_client(name, service)
            client = self._clients[(name, service)]
        if request is None:
            request = from_dict(f"{service}_Request", {})
        data = client.call(serialize(request, f"{service}_Request"), timeout)
        return deserialize(data, f"{service}_Response")

    def create_timer(self, period: float, callback: Callable[[], None]) -> _Timer:
        """Call ``callback`` every ``period`` s on the executor thread."""
        if not period > 0:
            raise InputError(f"timer period = {period!r} s must be > 0", parameter="period",
                             value=period, allowed="> 0 s")
        return self._context.executor.add_timer(period, self.guard.wrap(
            f"timer {getattr(callback, '__qualname__', period)}", callback))

    def call_soon(self, callback: Callable[[], None]) -> None:
        """Queue ``callback`` on the executor thread behind the tasks queued already (each
        sample received posts its delivery as it arrives)."""
        self._context.executor.post(self.guard.wrap(
            f"call_soon {getattr(callback, '__qualname__', callback)}", callback))

    def _on_clock(self, message: Any) -> None:
        self._clock_ns = int(message.clock.sec) * 1_000_000_000 + int(message.clock.nanosec)

    def now_ns(self) -> int:
        """System time, ns since the UNIX epoch; with ``use_sim_time`` the latest ``/clock``."""
        return self._clock_ns if self.use_sim_time else time.time_ns()

    def graph_hubs(self) -> frozenset[str]:
        """The ids of the zenoh routers connected to the session (the graph's hubs)."""
        return self._context.router_ids()

    def close(self) -> None:
        """Detach the ``/rosout`` handler; undeclare every endpoint (parameter services
        included) and the node token."""
        self.logger.removeHandler(self._rosout)
        for entity in self._entities:
            entity.close()
        self._entities.clear()
        self._name_watch.undeclare()
        self._token.undeclare()


#: The type checker holds the port to the protocol every node is written against.
_CONTRACT: type[NodePort] = ZenohNodePort


class ZenohContext:
    """One zenoh session, its executor and the node/entity id counter of this process."""

    def __init__(self, session: zenoh.Session | None = None) -> None:
        self.session = session or open_session()
        self.domain_id = domain_id()
        self.zid = str(self.session.zid())
        self.executor = _Executor()
        self._ids = itertools.count()
        self._ports: list[ZenohNodePort] = []
        self._watch: GraphWatch | None = None  # the graph as subscribed_nodes sees it

    def next_id(self) -> int:
        """Next node/entity id (one counter per context, as in rmw_zenoh)."""
        return next(self._ids)

    def router_ids(self) -> frozenset[str]:
        """The ids of the zenoh routers connected to the session (empty: none)."""
        return frozenset(str(zid) for zid in self.session.info.routers_zid())

    def require_router(self) -> None:
        """``RuntimePortError`` saying why if the session reaches no router at the endpoint
        within :data:`~tdcm_ros.runtime.zenoh_diagnosis.ROUTER_WAIT_S` s (at once if nothing
        listens there)."""
        from tdcm_ros.runtime.zenoh_diagnosis import require_router

        require_router(self.session, session_config(), endpoint())

    def create_port(self, name: str, namespace: str = "/",
                    overrides: dict[str, Any] | None = None) -> ZenohNodePort:
        """A node port named ``name`` in ``namespace``."""
        port = ZenohNodePort(self, name, namespace, overrides)
        self._ports.append(port)
        return port

    def spin(self) -> None:
        """Run callbacks until :meth:`request_stop`."""
        self.executor.spin()

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = SERVICE_TIMEOUT_S) -> Any:
        """Call service ``name`` (absolute) of ``type_name`` with ``request`` (default: an empty
        request); the decoded response. ``RuntimePortError`` if no server answers within
        ``timeout`` s. Blocks the calling thread (not for use inside a callback)."""
        if not self._ports:
            self.create_port(f"_tdcm_client_{os.getpid()}")
        return self._ports[0].call_service(resolve_topic(name), type_name, request, timeout)

    def service_names(self, timeout: float = 1.0) -> list[tuple[str, str]]:
        """``(name, type)`` of every service with a server on the domain, sorted: the tokens
        a :class:`GraphWatch` sees within ``timeout`` s."""
        watch = GraphWatch(self)
        try:
            time.sleep(timeout)
            services = watch.topics(kinds=(wire.SERVICE,))
        finally:
            watch.close()
        return sorted((name, kind) for name, kinds in services.items() for kind in kinds)

    def subscribed_nodes(self, topics: Collection[str]) -> dict[str, set[str]]:
        """Topic -> fully qualified names of the nodes of other sessions subscribed to it now,
        as this context's :class:`GraphWatch` (opened at the first call, closed with the
        context) has seen them so far."""
        if self._watch is None:
            self._watch = GraphWatch(self)
        nodes = self._watch.nodes((wire.SUBSCRIPTION,), ignore_zid=self.zid)
        return {topic: nodes.get(resolve_topic(topic), set()) for topic in topics}

    def spin_for(self, seconds: float) -> None:
        """Run callbacks for ``seconds`` s."""
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0 and not self.executor.stop.is_set():
            self.executor.spin_once(min(left, 0.1))

    def request_stop(self) -> None:
        """Make :meth:`spin` return within 0.1 s (safe from signal handlers and other threads).

        It only sets the stop event, which the loop reads without its lock: posting a wake-up
        task from a signal handler would take the task queue's lock, which the main thread may
        hold inside ``Queue.get`` when the signal lands (a deadlock)."""
        self.executor.stop.set()

    def close(self) -> None:
        """Close every port and the graph watch, then the session."""
        for port in self._ports:
            port.close()
        self._ports.clear()
        if self._watch is not None:
            self._watch.close()
            self._watch = None
        self.session.close()


class GraphWatch:
    """The endpoints of a context's domain from rmw_zenoh liveliness tokens: a liveliness
    subscriber with history collects the present ones and those that show up while it runs (a
    one-shot liveliness query right after the session opens can come back empty)."""

    def __init__(self, context: ZenohContext) -> None:
        self._alive: set[str] = set()
        self._lock = threading.Lock()
        self._subscriber = context.session.liveliness().declare_subscriber(
            f"{wire.ADMIN_SPACE}/{context.domain_id}/**", self._seen, history=True)

    def _seen(self, sample: zenoh.Sample) -> None:
        """Zenoh thread: a token appeared or went away."""
        key = str(sample.key_expr)
        with self._lock:
            if sample.kind == zenoh.SampleKind.DELETE:
                self._alive.discard(key)
            else:
                self._alive.add(key)

    def _endpoints(self, kinds: Collection[str], ignore_zid: str) -> list[wire.TokenInfo]:
        """The present endpoints of ``kinds``, leaving out those of the session ``ignore_zid``."""
        with self._lock:
            keys = sorted(self._alive)
        found = []
        for key in keys:
            try:
                token = wire.parse_token(key)
            except (RuntimePortError, ValueError):
                continue
            if token.kind in kinds and token.zid != ignore_zid:
                found.append(token)
        return found

    def topics(self, kinds: Collection[str] = (wire.PUBLISHER, wire.SUBSCRIPTION),
               ignore_zid: str = "") -> dict[str, set[str]]:
        """Topic (or service) name -> types of the endpoints of ``kinds`` (``MP``, ``MS``,
        ``SS``, ``SC``), leaving out those of the session ``ignore_zid``."""
        topics: dict[str, set[str]] = {}
        for token in self._endpoints(kinds, ignore_zid):
            topics.setdefault(token.topic, set()).add(token.type_name)
        return topics

    def publisher_durabilities(self, topic: str) -> set[str]:
        """The durabilities (``transient_local``, ``volatile``) the publishers of ``topic``
        (fully qualified) declare; empty while none is seen."""
        return {wire.durability_of(token.qos) for token in self._endpoints((wire.PUBLISHER,), "")
                if token.topic == topic}

    def nodes(self, kinds: Collection[str], ignore_zid: str = "") -> dict[str, set[str]]:
        """Topic (or service) name -> fully qualified names of the nodes with an endpoint of
        ``kinds`` on it, leaving out those of the session ``ignore_zid``."""
        nodes: dict[str, set[str]] = {}
        for token in self._endpoints(kinds, ignore_zid):
            nodes.setdefault(token.topic, set()).add(
                fully_qualified_node_name(token.namespace, token.node_name))
        return nodes

    def close(self) -> None:
        """Stop collecting."""
        self._subscriber.undeclare()
