"""Test-side peers on rclpy: plain rclpy nodes, as a user's own node would be.

They subscribe and publish the rosidl-generated message classes (so every message crosses
rosidl's own typesupport, not rosbags; the class lookup, the QoS mapping and the context that
spins them are the package's, which hold no node logic), and reach node parameters through
``rclpy.parameter_client.AsyncParameterClient`` (what ``ros2 param`` uses). The port shape
(``create_subscription``/``create_publisher``/``spin_for``) matches the zenoh context, so one
probe class serves both runtimes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from tdcm_ros.bagio import serialize
from tdcm_ros.runtime.port import DEFAULT_QOS, QoS
from tdcm_ros.runtime.rclpy_runtime import RclpyContext, plain_value
from tdcm_ros.runtime.rclpy_runtime import message_class as native_class
from tdcm_ros.runtime.rclpy_runtime import qos_profile as profile
from test.support.waiting import eventually


class NativePublisher:
    """Publishes a rosbags message as the rosidl message with the same CDR bytes."""

    def __init__(self, publisher: Any, type_name: str) -> None:
        self._publisher = publisher
        self._type_name = type_name
        self._class = native_class(type_name)

    def publish(self, message: Any) -> None:
        from rclpy.serialization import deserialize_message

        self._publisher.publish(deserialize_message(serialize(message, self._type_name),
                                                    self._class))


class PlainPort:
    """Endpoints of one plain rclpy node."""

    def __init__(self, node: Any) -> None:
        self.node = node

    def create_subscription(self, topic: str, type_name: str, callback: Callable[[Any], None],
                            qos: QoS = DEFAULT_QOS) -> None:
        self.node.create_subscription(native_class(type_name), topic, callback, profile(qos))

    def create_publisher(self, topic: str, type_name: str, qos: QoS = DEFAULT_QOS) -> NativePublisher:
        return NativePublisher(self.node.create_publisher(native_class(type_name), topic,
                                                          profile(qos)), type_name)


class PlainRclpyContext(RclpyContext):
    """The package's rclpy context (one executor, domain from ``ROS_DOMAIN_ID``) spinning plain
    rclpy nodes: ``create_port`` gives a :class:`PlainPort`, not the package's node port."""

    def create_port(self, name: str, namespace: str = "/",  # type: ignore[override]
                    overrides: Any = None) -> PlainPort:
        return PlainPort(self.create_node(name, namespace))

    @property
    def nodes(self) -> list[Any]:
        """The plain nodes made so far."""
        return self._nodes

    def wait(self, future: Any, timeout: float) -> Any:
        return self.spin_until_future(future, timeout)


class PlainParameterClient:
    """``AsyncParameterClient`` calls, answered in the zenoh client's shapes."""

    def __init__(self, ctx: PlainRclpyContext, node_fqn: str, timeout: float = 15.0) -> None:
        from rclpy.parameter_client import AsyncParameterClient

        if not ctx.nodes:
            ctx.create_port("param_probe")
        self.ctx = ctx
        self.timeout = timeout
        self.client = AsyncParameterClient(ctx.nodes[0], node_fqn)
        eventually(self.client.services_are_ready, timeout,
                   f"the parameter services of {node_fqn}", spin=ctx)

    def get(self, name: str) -> Any:
        from rclpy.parameter import parameter_value_to_python

        response = self.ctx.wait(self.client.get_parameters([name]), self.timeout)
        return plain_value(parameter_value_to_python(response.values[0]))

    def set(self, name: str, value: Any) -> dict[str, Any]:
        from rclpy.parameter import Parameter

        response = self.ctx.wait(self.client.set_parameters([Parameter(name, value=value)]),
                                 self.timeout)
        result = response.results[0]
        return {"successful": result.successful, "reason": result.reason}

    def names(self) -> list[str]:
        response = self.ctx.wait(self.client.list_parameters(), self.timeout)
        return sorted(response.result.names)

    def describe(self, name: str) -> Any:
        response = self.ctx.wait(self.client.describe_parameters([name]), self.timeout)
        return response.descriptors[0]
