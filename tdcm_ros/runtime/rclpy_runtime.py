"""The rclpy runtime: node logic as real ROS 2 nodes, with no per-type code.

A message class is ``importlib.import_module("<pkg>.msg").<Name>`` (what
``rosidl_runtime_py.utilities.get_message`` does, without needing that package). Subscriptions
are raw (CDR) and decoded with rosbags; publishing hands rclpy the CDR bytes. Parameters are
declared on the rclpy node with typed ``ParameterDescriptor`` ranges from the same
:class:`ParamSpec`, so ``ros2 param`` (the six rcl_interfaces services rclpy serves) lists, gets and
sets them; an on-set callback runs the same checks as the zenoh runtime.

One :class:`RclpyContext` per process: its own ``rclpy`` context (domain from ``ROS_DOMAIN_ID``,
discovery range from ``ROS_AUTOMATIC_DISCOVERY_RANGE``), one single-threaded executor for every
node it creates, and no rclpy signal handlers: the caller stops it with :meth:`request_stop`, so
nodes close (and log) while the context is still up. rclpy is imported only inside this module's
functions and classes, so the module imports where ROS is absent.
"""

from __future__ import annotations

import importlib
import logging
import os
import threading
import time
from collections import deque
from collections.abc import Callable, Collection, Mapping, Sequence
from typing import Any

from tdcm_ros.bagio import (
    BagError,
    deserialize,
    from_dict,
    normalize_service_type,
    normalize_type_name,
    prepare_codec,
    serialize,
)
from tdcm_ros.errors import InputError
from tdcm_ros.runtime import param_services, wire
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.guard import CallbackGuard
from tdcm_ros.runtime.names import resolve_topic
from tdcm_ros.runtime.parameters import (
    P,
    ParameterStore,
    ParamSpec,
    ParamValue,
    SetCallback,
    Validator,
)
from tdcm_ros.runtime.params import node_parameters, sources_in_order
from tdcm_ros.runtime.port import DEFAULT_QOS, SERVICE_TIMEOUT_S, NodePort, QoS
from tdcm_ros.runtime.wire import RawSample

_NO_GID = bytes(wire.GID_SIZE)
#: rclpy's own parameter that puts the node clock on ``/clock``.
SIM_TIME = "use_sim_time"
#: The name rclpy's graph gives an endpoint whose node it has not heard of yet.
UNKNOWN_NODE_NAME = "_NODE_NAME_UNKNOWN_"
#: Longest wait (s) in :meth:`RclpyContext.close` for another thread's executor wake-up to end.
CLOSE_SPIN_WAIT_S = 10.0


def message_class(type_name: str) -> Any:
    """The rclpy message class of ``pkg/msg/Name``; ``RuntimePortError`` if it is not installed."""
    package, _, name = normalize_type_name(type_name).partition("/msg/")
    try:
        return getattr(importlib.import_module(f"{package}.msg"), name)
    except (ImportError, AttributeError) as error:
        raise RuntimePortError(
            f"message type {type_name} is not importable for rclpy ({error}); build and source "
            f"its interface package (see doc/howto/ros_by_apt.md)") from error


def service_class(type_name: str) -> Any:
    """The rclpy service class of ``pkg/srv/Name``; ``RuntimePortError`` if not installed."""
    package, _, name = normalize_service_type(type_name).partition("/srv/")
    try:
        return getattr(importlib.import_module(f"{package}.srv"), name)
    except (ImportError, AttributeError) as error:
        raise RuntimePortError(f"service type {type_name} is not importable for rclpy ({error}); "
                               f"install its interface package") from error


def to_rosbags(native: Any, type_name: str) -> Any:
    """A rosidl message as the rosbags message of ``type_name`` (through its CDR bytes; rclpy
    may pad them past the message)."""
    from rclpy.serialization import serialize_message

    return deserialize(serialize_message(native), type_name, exact=False)


def to_native(message: Any, type_name: str, native_class: Any) -> Any:
    """A rosbags message as an instance of rosidl class ``native_class`` (through CDR)."""
    from rclpy.serialization import deserialize_message

    return deserialize_message(serialize(message, type_name), native_class)


def plain_value(value: Any) -> Any:
    """rclpy array values (``array.array``, tuples) as lists; scalars unchanged."""
    return list(value) if not isinstance(value, str | bytes) and hasattr(value, "__iter__") else value


class _Logger:
    """%-style facade over an rclpy logger. rclpy stamps a record (on the console and in the
    ``/rosout`` message) with the first calling frame outside its own files; this file joins
    that list (``rcutils_logger._internal_callers``, kept open for wrappers like this one) so
    the call site is the node's, not this facade's."""

    def __init__(self, logger: Any) -> None:
        from rclpy.impl import rcutils_logger

        here = os.path.realpath(__file__)
        if here not in rcutils_logger._internal_callers:
            rcutils_logger._internal_callers.append(here)
        self._logger = logger

    def debug(self, msg: str, *args: object) -> None:
        self._logger.debug(msg % args if args else msg)

    def info(self, msg: str, *args: object) -> None:
        self._logger.info(msg % args if args else msg)

    def warning(self, msg: str, *args: object) -> None:
        self._logger.warning(msg % args if args else msg)

    def error(self, msg: str, *args: object) -> None:
        self._logger.error(msg % args if args else msg)


def qos_profile(qos: QoS) -> Any:
    """The rclpy ``QoSProfile`` of a port :class:`QoS` (keep-last)."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST, depth=qos.depth,
        reliability=(ReliabilityPolicy.RELIABLE if qos.reliability == "reliable"
                     else ReliabilityPolicy.BEST_EFFORT),
        durability=(DurabilityPolicy.VOLATILE if qos.durability == "volatile"
                    else DurabilityPolicy.TRANSIENT_LOCAL))


def descriptor(spec: ParamSpec) -> Any:
    """rclpy's ``ParameterDescriptor`` of a spec: the one the embedded runtime serves
    (:func:`tdcm_ros.runtime.param_services.descriptor`), crossed through its CDR bytes."""
    from rcl_interfaces.msg import ParameterDescriptor

    return to_native(param_services.descriptor(spec), "rcl_interfaces/msg/ParameterDescriptor",
                     ParameterDescriptor)


class _Publisher:
    """Publishes CDR bytes through an rclpy publisher."""

    def __init__(self, node: Any, topic: str, type_name: str, qos: QoS) -> None:
        self.type_name = normalize_type_name(type_name)
        prepare_codec(self.type_name)  # not on the callback thread at the first publish
        self._publisher = node.create_publisher(message_class(self.type_name), topic,
                                                qos_profile(qos))
        self.topic = self._publisher.topic_name

    def publish(self, message: Any) -> None:
        """Serialise with rosbags and publish the bytes."""
        self._publisher.publish(serialize(message, self.type_name))

    def publish_cdr(self, data: bytes) -> None:
        """Publish CDR bytes."""
        self._publisher.publish(bytes(data))

    def matched(self) -> bool:
        """True when DDS discovery has matched at least one subscription."""
        return bool(self._publisher.get_subscription_count() > 0)


class RclpyNodePort:
    """:class:`tdcm_ros.runtime.port.NodePort` on an ``rclpy.node.Node``.

    ``overrides`` are the node's values from the parameter file, read by the same reader as the
    zenoh runtime, so an ``int`` in YAML widens to a ``float`` parameter instead of failing
    rclpy's static typing. Overrides given on the command line (``-p name:=value``) reach the
    parameter through rclpy itself.
    """

    def __init__(self, node: Any, overrides: Mapping[str, Any] | None = None) -> None:
        self.node = node
        self.node_name = node.get_name()
        self.namespace = node.get_namespace()
        self.logger = _Logger(node.get_logger())
        self._overrides = dict(overrides or {})
        self._params = ParameterStore(self._overrides, warn=self.logger.warning)
        self._clients: dict[tuple[str, str], Any] = {}
        self._clients_lock = threading.Lock()
        self.guard = CallbackGuard(node.get_fully_qualified_name(), self.logger,
                                   self.create_publisher, self.now_ns)
        self._soon: deque[Callable[[], None]] = deque()  # call_soon's, run by _wake
        self._wake = node.create_guard_condition(self._run_soon)
        node.add_pre_set_parameters_callback(self._widen)
        node.add_on_set_parameters_callback(self._on_set)
        if SIM_TIME in self._overrides:  # a --params file is read here, not by rcl
            from rclpy.parameter import Parameter

            node.set_parameters([Parameter(SIM_TIME, value=bool(self._overrides[SIM_TIME]))])

    def declare_parameter(self, name: str, default: P, *, description: str = "",
                          range: tuple[float, float] | None = None,
                          validator: Validator | None = None,
                          read_only: bool = False, formerly: tuple[str, ...] = ()) -> P:
        """Declare on the rclpy node with the checked override or default; returns the value."""
        from rclpy.exceptions import (
            InvalidParameterTypeException,
            InvalidParameterValueException,
        )

        spec = ParamSpec(name, default, description, range, validator, read_only, formerly)
        spec.coerce(default)
        from_file, file_value = self._params.override(spec)
        initial = spec.coerce(file_value) if from_file else default
        try:
            value = self.node.declare_parameter(name, initial, descriptor(spec),
                                                ignore_override=from_file).value
        except (InvalidParameterTypeException, InvalidParameterValueException) as error:
            raise InputError(f"{name}: {error}", parameter=name, allowed=spec.kind) from error
        return self._params.declare(spec, plain_value(value))

    def get_parameter(self, name: str) -> ParamValue:
        """Current value."""
        return self._params.get(name)

    def unused_overrides(self) -> list[str]:
        """Names the parameter file sets that neither the node nor rclpy declared."""
        return [name for name in self._params.unused_overrides()
                if not self.node.has_parameter(name)]

    def add_on_set_parameters(self, callback: SetCallback) -> None:
        """Add a node-level check of runtime changes."""
        self._params.add_on_set(callback)

    def _widen(self, parameters: list[Any]) -> list[Any]:
        """Pre-set hook: an integer (array) for a float (list) parameter becomes floats, as on
        zenoh; every other value goes on unchanged to rclpy's and the node's checks."""
        from rclpy.parameter import Parameter

        specs = self._params.specs
        widened = []
        for parameter in parameters:
            spec = specs.get(parameter.name)
            kind = spec.kind if spec is not None else ""
            if kind == "float" and parameter.type_ == Parameter.Type.INTEGER:
                parameter = Parameter(parameter.name, value=float(parameter.value))
            elif kind == "list[float]" and parameter.type_ == Parameter.Type.INTEGER_ARRAY:
                parameter = Parameter(parameter.name, value=[float(v) for v in parameter.value])
            widened.append(parameter)
        return widened

    def _on_set(self, parameters: list[Any]) -> Any:
        from rcl_interfaces.msg import SetParametersResult

        changes = {p.name: plain_value(p.value) for p in parameters if p.name in self._params.specs}
        if not changes:
            return SetParametersResult(successful=True)
        try:
            accepted = self._params.validate(changes)
        except InputError as error:
            self.logger.warning("parameter change rejected: %s", error)
            return SetParametersResult(successful=False, reason=str(error))
        self._params.commit(accepted)
        return SetParametersResult(successful=True)

    def create_publisher(self, topic: str, type_name: str, qos: QoS = DEFAULT_QOS) -> _Publisher:
        """Declare a publisher of ``type_name`` found by name."""
        return _Publisher(self.node, topic, type_name, qos)

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: QoS = DEFAULT_QOS) -> None:
        """Raw subscription; the CDR bytes are decoded with rosbags before ``callback``."""
        name = normalize_type_name(type_name)

        def decode(sample: RawSample) -> None:
            try:
                message = deserialize(sample.data, name)
            except BagError as error:
                self.logger.warning("dropped message on %s: %s", sample.topic, error)
                return
            callback(message)

        self.create_raw_subscription(topic, name, decode, qos)

    def create_raw_subscription(self, topic: str, type_name: str,
                                callback: Callable[[RawSample], None],
                                qos: QoS = DEFAULT_QOS) -> None:
        """Subscribe to CDR samples with the sender's timestamp and sequence number.

        rclpy's executor takes one message per subscription per wake-up; at 1 kHz that alone
        let model_node's queue fill (100 ms behind). So each wake-up also drains what is
        already queued, up to ``qos.depth`` messages, in order, through the same callback.
        """
        name = normalize_type_name(type_name)
        holder: list[Any] = []
        callback = self.guard.wrap(f"subscription {self.node.resolve_topic_name(topic)}",
                                   callback)

        def deliver(data: bytes, info: Mapping[str, Any]) -> None:
            attachment = wire.Attachment(int(info.get("publication_sequence_number", 0)),
                                         int(info.get("source_timestamp", 0)), _NO_GID)
            callback(RawSample(holder[0].topic_name, name, bytes(data), attachment))

        def on_message(data: bytes, info: Mapping[str, Any]) -> None:
            deliver(data, info)
            subscription = holder[0]
            for _ in range(qos.depth):
                with subscription.handle:
                    taken = subscription.handle.take_message(subscription.msg_type, True)
                if taken is None:
                    return
                deliver(*taken)

        holder.append(self.node.create_subscription(message_class(name), topic, on_message,
                                                    qos_profile(qos), raw=True))

    def create_service(self, name: str, type_name: str,
                       handler: Callable[[Any], Any]) -> None:
        """An rclpy service; requests and responses cross to rosbags through their CDR bytes.
        A failing handler is logged and answered with a default response."""
        service = normalize_service_type(type_name)
        native = service_class(service)

        def answer(request: Any) -> Any:
            return to_native(handler(to_rosbags(request, f"{service}_Request")),
                             f"{service}_Response", native.Response)

        guarded = self.guard.wrap(f"service {self.node.resolve_service_name(name)}", answer)

        def on_request(request: Any, response: Any) -> Any:
            answered = guarded(request)
            return response if answered is None else answered

        self.node.create_service(native, name, on_request)

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = SERVICE_TIMEOUT_S) -> Any:
        """Call service ``name`` with an rclpy client of this node (``request`` default:
        empty); the response as a rosbags message. ``RuntimePortError`` if the service does not
        appear or answer within ``timeout`` s. Waits on the calling thread while the context's
        executor (spinning elsewhere) delivers the answer: never call it from a callback."""
        service = normalize_service_type(type_name)
        native = service_class(service)
        with self._clients_lock:
            if (name, service) not in self._clients:
                self._clients[(name, service)] = self.node.create_client(native, name)
            client = self._clients[(name, service)]
        end = time.monotonic() + timeout
        while not client.service_is_ready():
            if time.monotonic() > end:
                raise RuntimePortError(f"service {name} ({service}) has no server after "
                                       f"{timeout:g} s")
            time.sleep(0.05)
        if request is None:
            request = from_dict(f"{service}_Request", {})
        answered = threading.Event()
        future = client.call_async(to_native(request, f"{service}_Request", native.Request))
        future.add_done_callback(lambda _: answered.set())
        if not answered.wait(max(0.1, end - time.monotonic())):
            client.remove_pending_request(future)
            raise RuntimePortError(f"service {name} ({service}) did not answer within "
                                   f"{timeout:g} s")
        return to_rosbags(future.result(), f"{service}_Response")

    def create_timer(self, period: float, callback: Callable[[], None]) -> Any:
        """rclpy timer of ``period`` s."""
        if not period > 0:
            raise InputError(f"timer period = {period!r} s must be > 0", parameter="period",
                             value=period, allowed="> 0 s")
        return self.node.create_timer(period, self.guard.wrap(
            f"timer {getattr(callback, '__qualname__', period)}", callback))

    def call_soon(self, callback: Callable[[], None]) -> None:
        """Queue ``callback`` and trigger the node's guard condition: the executor runs it on
        its next wait, after the subscriptions ready in that wait (rclpy takes a node's
        subscriptions before its guard conditions)."""
        self._soon.append(self.guard.wrap(
            f"call_soon {getattr(callback, '__qualname__', callback)}", callback))
        self._wake.trigger()

    def _run_soon(self) -> None:
        """The callbacks queued before this wake-up, in order (later ones trigger another)."""
        for _ in range(len(self._soon)):
            self._soon.popleft()()

    def now_ns(self) -> int:
        """The node clock (ROS time if ``use_sim_time``), ns."""
        return int(self.node.get_clock().now().nanoseconds)

    def graph_hubs(self) -> frozenset[str]:
        """Always ``{"dds"}``: DDS discovery has no router whose loss could be seen."""
        return DDS_HUBS


#: What :meth:`RclpyNodePort.graph_hubs` answers.
DDS_HUBS = frozenset({"dds"})
#: The type checker holds the port to the protocol every node is written against.
_CONTRACT: type[NodePort] = RclpyNodePort


class RclpyContext:
    """An rclpy context with one executor for the nodes it creates; see the module docstring.

    ``args`` are rclpy command-line arguments (``--ros-args ...``), applied to every node.
    Each port's overrides are read by the package's own reader, which reads as rcl does
    (:mod:`tdcm_ros.runtime.params`; the port then widens an ``int`` to a ``float`` parameter),
    looked up by the node's final (remapped) name, from ``params_files`` (never handed to rcl),
    then the ``--params-file`` files and ``-p [node:]name:=value`` items of ``args`` in order.
    """

    def __init__(self, args: Sequence[str] = (), params_files: Sequence[str] = ()) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor, TimeoutObject
        from rclpy.signals import SignalHandlerOptions

        self.context = Context()
        try:
            rclpy.init(args=["tdcm", *args], context=self.context,
                       signal_handler_options=SignalHandlerOptions.NO)
        except rclpy.exceptions.RCLError as error:
            raise InputError(f"ROS arguments {' '.join(args)!r} are refused by rcl: {error}",
                             parameter="--ros-args", value=" ".join(args)) from error
        self.executor = SingleThreadedExecutor(context=self.context)
        # One timeout object for every wake-up: rclpy keeps the ready entities of its last wait
        # only while ``spin_once`` gets the same arguments; a new float each time (spin_for's
        # time left) made every wake-up run just the first ready entity, so a busy subscription
        # or timer starved the ones after it.
        self._timeout = TimeoutObject(0.0)
        self.domain_id = int(self.context.get_domain_id())
        self.param_sources = sources_in_order(params_files, args)
        self._stop = threading.Event()
        self._nodes: list[Any] = []
        self._client_node: Any = None
        self._clients: dict[tuple[str, str], Any] = {}
        self._spinners: dict[int, int] = {}  # thread id -> spin calls under way on it
        self._spinning = threading.Condition()
        self._closed = False

    def create_port(self, name: str, namespace: str = "/",
                    overrides: Mapping[str, Any] | None = None) -> RclpyNodePort:
        """A node port on a new rclpy node ``namespace/name``; ``overrides`` default to the
        node's values from the parameter files and ``-p`` arguments (see the class docstring)."""
        node = self.create_node(name, namespace)
        if overrides is None:
            overrides = node_parameters(self.param_sources, node.get_fully_qualified_name())
        return RclpyNodePort(node, overrides)

    def create_node(self, name: str, namespace: str = "/") -> Any:
        """A plain ``rclpy.node.Node`` spun by this context's executor."""
        from rclpy.node import Node

        node = Node(name, namespace=namespace, context=self.context)
        self._nodes.append(node)
        self.executor.add_node(node)
        return node

    def _spin_once(self, timeout_sec: float) -> None:
        """One executor wake-up, counted so that :meth:`close` can wait for it to end."""
        me = threading.get_ident()
        with self._spinning:
            if self._closed:  # checked under the lock close() takes: no wake-up starts after
                return
            self._spinners[me] = self._spinners.get(me, 0) + 1
        try:
            self._timeout.timeout = timeout_sec
            self.executor.spin_once(timeout_sec=self._timeout)
        finally:
            with self._spinning:
                self._spinners[me] -= 1
                if not self._spinners[me]:
                    del self._spinners[me]
                self._spinning.notify_all()

    def spin(self) -> None:
        """Run callbacks until :meth:`request_stop` (or rclpy shuts down)."""
        while not self._stop.is_set() and self.context.ok():
            self._spin_once(0.1)

    def spin_for(self, seconds: float) -> None:
        """Run callbacks for ``seconds`` s."""
        end = time.monotonic() + seconds
        while ((left := end - time.monotonic()) > 0 and not self._stop.is_set()
               and self.context.ok()):
            self._spin_once(min(left, 0.05))

    def subscribed_nodes(self, topics: Collection[str]) -> dict[str, set[str]]:
        """Topic -> fully qualified names of the nodes (not this context's) subscribed to it
        now, as DDS discovery shows them. An endpoint seen before its node's name (rclpy's
        ``_NODE_NAME_UNKNOWN_``) is not one yet."""
        node = self._nodes[0] if self._nodes else self.create_node(f"_tdcm_graph_{os.getpid()}")
        own = {n.get_fully_qualified_name() for n in self._nodes}
        return {topic: {f"{info.node_namespace.rstrip('/')}/{info.node_name}"
                        for info in node.get_subscriptions_info_by_topic(resolve_topic(topic))
                        if info.node_name != UNKNOWN_NODE_NAME} - own for topic in topics}

    def spin_until_future(self, future: Any, timeout: float) -> Any:
        """Spin until ``future`` is done; its result, or ``RuntimePortError`` after ``timeout``."""
        end = time.monotonic() + timeout
        while not future.done():
            if time.monotonic() > end or not self.context.ok() or self._closed:
                raise RuntimePortError(f"no answer within {timeout:g} s")
            self._spin_once(0.05)
        return future.result()

    def request_stop(self) -> None:
        """Make :meth:`spin` return (safe from signal handlers and other threads)."""
        self._stop.set()

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = SERVICE_TIMEOUT_S) -> Any:
        """Call service ``name`` with an rclpy client (``request`` default: empty); the
        response as a rosbags message. ``RuntimePortError`` if the service does not appear or
        answer within ``timeout`` s. Spins this context while waiting (not inside a callback)."""
        service = normalize_service_type(type_name)
        native = service_class(service)
        key = (name, service)
        if key not in self._clients:
            if self._client_node is None:
                self._client_node = self.create_node(f"_tdcm_client_{id(self):x}")
            self._clients[key] = self._client_node.create_client(native, name)
        client = self._clients[key]
        end = time.monotonic() + timeout
        while not client.service_is_ready():
            if time.monotonic() > end:
                raise RuntimePortError(f"service {name} ({service}) has no server after "
                                       f"{timeout:g} s; is its node running on ROS domain "
                                       f"{self.domain_id}?")
            self.spin_for(0.05)
        if request is None:
            request = from_dict(f"{service}_Request", {})
        future = client.call_async(to_native(request, f"{service}_Request", native.Request))
        response = self.spin_until_future(future, max(0.1, end - time.monotonic()))
        return to_rosbags(response, f"{service}_Response")

    def service_names(self, timeout: float = 1.0) -> list[tuple[str, str]]:
        """``(name, type)`` of every service in the graph, sorted (after ``timeout`` s of
        discovery)."""
        if self._client_node is None:
            self._client_node = self.create_node(f"_tdcm_client_{id(self):x}")
        self.spin_for(timeout)
        return sorted((name, kind) for name, kinds in
                      self._client_node.get_service_names_and_types() for kind in kinds)

    def close(self) -> None:
        """Stop spinning, wait (at most :data:`CLOSE_SPIN_WAIT_S` s, else leave the nodes alone)
        for a wake-up under way on another thread to end, shut the executor down, destroy every
        node, then the context.

        The order matters: destroying a node while another thread is inside the executor's
        wait on that node's entities (``spin_once``) is the classic cause of a segfault in
        ``destroy_node``; so no node is destroyed before every other thread has left
        ``spin_once`` and the executor is shut down (which also waits for callbacks under way).
        """
        self._stop.set()
        me = threading.get_ident()
        with self._spinning:
            self._closed = True
            if not self._spinning.wait_for(lambda: not set(self._spinners) - {me},
                                           CLOSE_SPIN_WAIT_S):
                # leaking the nodes of a process that is ending beats a segfault
                logging.getLogger("tdcm.rclpy").warning(
                    "another thread still spins the executor after %g s; its nodes are left "
                    "undestroyed", CLOSE_SPIN_WAIT_S)
                return
        self.executor.shutdown()
        for node in self._nodes:
            node.destroy_node()
        self._nodes.clear()
        self.context.try_shutdown()

