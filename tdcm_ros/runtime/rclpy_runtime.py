"""The rclpy adapter: node logic as a real ROS 2 node, with no per-type code.

Message classes come from ``rosidl_runtime_py.utilities.get_message``; subscriptions are raw
(CDR) and decoded with rosbags; publishing hands rclpy the CDR bytes. Parameters are declared
with ``ParameterDescriptor`` ranges from the same :class:`ParamSpec`, and an on-set callback runs
the same checks as the zenoh runtime. rclpy is imported only inside functions, so this module
imports where ROS is absent.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from typing import Any

from tdcm_ros.bagio import BagError, deserialize, normalize_type_name, serialize
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.parameters import (
    ParameterStore,
    ParamSpec,
    ParamValue,
    SetCallback,
    Validator,
)
from tdcm_ros.runtime.port import DEFAULT_QOS, NodeLogic, QoS


def _plain(value: Any) -> Any:
    """rclpy array values (``array.array``, tuples) as lists; scalars unchanged."""
    return list(value) if not isinstance(value, str | bytes) and hasattr(value, "__iter__") else value


class _Logger:
    """%-style facade over an rclpy logger."""

    def __init__(self, logger: Any) -> None:
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
    """``ParameterDescriptor`` with the spec's description, read-only flag and range."""
    from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor

    desc = ParameterDescriptor(name=spec.name, description=spec.description,
                               read_only=spec.read_only)
    if spec.range is not None and spec.kind in ("float", "list[float]"):
        desc.floating_point_range = [FloatingPointRange(
            from_value=float(spec.range[0]), to_value=float(spec.range[1]), step=0.0)]
    elif spec.range is not None and spec.kind in ("int", "list[int]"):
        desc.integer_range = [IntegerRange(
            from_value=int(spec.range[0]), to_value=int(spec.range[1]), step=0)]
    return desc


class _Publisher:
    """Publishes CDR bytes through an rclpy publisher."""

    def __init__(self, node: Any, topic: str, type_name: str, qos: QoS) -> None:
        from rosidl_runtime_py.utilities import get_message

        self.type_name = normalize_type_name(type_name)
        self._publisher = node.create_publisher(get_message(self.type_name), topic,
                                                qos_profile(qos))
        self.topic = self._publisher.topic_name

    def publish(self, message: Any) -> None:
        """Serialise with rosbags and publish the bytes."""
        self._publisher.publish(serialize(message, self.type_name))

    def publish_cdr(self, data: bytes) -> None:
        """Publish CDR bytes."""
        self._publisher.publish(bytes(data))


class RclpyNodePort:
    """:class:`tdcm_ros.runtime.port.NodePort` on an ``rclpy.node.Node``."""

    def __init__(self, node: Any) -> None:
        self.node = node
        self.node_name = node.get_name()
        self.namespace = node.get_namespace()
        self.logger = _Logger(node.get_logger())
        self._params = ParameterStore()
        node.add_on_set_parameters_callback(self._on_set)

    def declare_parameter(self, name: str, default: ParamValue, *, description: str = "",
                          range: tuple[float, float] | None = None,
                          validator: Validator | None = None,
                          read_only: bool = False) -> ParamValue:
        """Declare on the rclpy node (which applies YAML overrides), then check the value."""
        spec = ParamSpec(name, default, description, range, validator, read_only)
        value = self.node.declare_parameter(name, default, descriptor(spec)).value
        return self._params.declare(spec, _plain(value))

    def get_parameter(self, name: str) -> ParamValue:
        """Current value."""
        return self._params.get(name)

    def add_on_set_parameters(self, callback: SetCallback) -> None:
        """Add a node-level check of runtime changes."""
        self._params.add_on_set(callback)

    def _on_set(self, parameters: list[Any]) -> Any:
        from rcl_interfaces.msg import SetParametersResult

        changes = {p.name: _plain(p.value) for p in parameters if p.name in self._params.specs}
        if not changes:
            return SetParametersResult(successful=True)
        try:
            accepted = self._params.validate(changes)
        except InputError as error:
            return SetParametersResult(successful=False, reason=str(error))
        self._params.commit(accepted)
        return SetParametersResult(successful=True)

    def create_publisher(self, topic: str, type_name: str, qos: QoS = DEFAULT_QOS) -> _Publisher:
        """Declare a publisher of ``type_name`` found by name."""
        return _Publisher(self.node, topic, type_name, qos)

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: QoS = DEFAULT_QOS) -> None:
        """Raw subscription; the CDR bytes are decoded with rosbags before ``callback``."""
        from rosidl_runtime_py.utilities import get_message

        name = normalize_type_name(type_name)

        def decode(data: bytes) -> None:
            try:
                message = deserialize(data, name)
            except BagError as error:
                self.logger.warning("dropped message on %s: %s", topic, error)
                return
            callback(message)

        self.node.create_subscription(get_message(name), topic, decode, qos_profile(qos),
                                      raw=True)

    def create_timer(self, period: float, callback: Callable[[], None]) -> Any:
        """rclpy timer of ``period`` s."""
        if not period > 0:
            raise InputError(f"timer period = {period!r} s must be > 0", parameter="period",
                             value=period, allowed="> 0 s")
        return self.node.create_timer(period, callback)

    def now_ns(self) -> int:
        """The node clock (ROS time if ``use_sim_time``), ns."""
        return int(self.node.get_clock().now().nanoseconds)


def run_rclpy(node_class: type[NodeLogic], *, name: str, namespace: str = "/",
              params_file: str | None = None, ros_args: Sequence[str] = ()) -> int:
    """Run ``node_class`` as an rclpy node until shutdown (Ctrl-C); returns the exit status."""
    import rclpy
    from rclpy.executors import ExternalShutdownException

    args = list(ros_args) or ["--ros-args"]
    if params_file:
        args += ["--params-file", params_file]
    rclpy.init(args=[sys.argv[0], *args])
    node = rclpy.create_node(name, namespace=namespace)
    logic: NodeLogic | None = None
    try:
        logic = node_class(RclpyNodePort(node))
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if logic is not None:
            logic.close()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0
