"""Test-side peers on rclpy: plain rclpy nodes, as a user's own node would be.

They subscribe and publish the rosidl-generated message classes (so every message crosses
rosidl's own typesupport, not rosbags; the class lookup and QoS mapping are the package's small
helpers, which hold no transport logic), and reach node parameters through
``rclpy.parameter_client.AsyncParameterClient`` (what ``ros2 param`` uses). The port shape
(``create_subscription``/``create_publisher``/``spin_for``) matches the zenoh context, so one
probe class serves both runtimes.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from tdcm_ros.bagio import serialize
from tdcm_ros.runtime.port import DEFAULT_QOS, QoS
from tdcm_ros.runtime.rclpy_runtime import message_class as native_class
from tdcm_ros.runtime.rclpy_runtime import plain_value
from tdcm_ros.runtime.rclpy_runtime import qos_profile as profile


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


class PlainRclpyContext:
    """An rclpy context of plain nodes spun by one executor (domain from ``ROS_DOMAIN_ID``)."""

    def __init__(self) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor

        self.context = Context()
        rclpy.init(context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.nodes: list[Any] = []

    def create_port(self, name: str, namespace: str = "/") -> PlainPort:
        from rclpy.node import Node

        node = Node(name, namespace=namespace, context=self.context)
        self.nodes.append(node)
        self.executor.add_node(node)
        return PlainPort(node)

    def spin_for(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            self.executor.spin_once(timeout_sec=min(left, 0.05))

    def wait(self, future: Any, timeout: float) -> Any:
        end = time.monotonic() + timeout
        while not future.done():
            assert time.monotonic() < end, f"no answer within {timeout} s"
            self.executor.spin_once(timeout_sec=0.05)
        return future.result()

    def close(self) -> None:
        self.executor.shutdown()
        for node in self.nodes:
            node.destroy_node()
        self.context.try_shutdown()


class PlainParameterClient:
    """``AsyncParameterClient`` calls, answered in the zenoh client's shapes."""

    def __init__(self, ctx: PlainRclpyContext, node_fqn: str, timeout: float = 15.0) -> None:
        from rclpy.parameter_client import AsyncParameterClient

        if not ctx.nodes:
            ctx.create_port("param_probe")
        self.ctx = ctx
        self.timeout = timeout
        self.client = AsyncParameterClient(ctx.nodes[0], node_fqn)
        end = time.monotonic() + timeout
        while not self.client.services_are_ready():
            assert time.monotonic() < end, f"parameter services of {node_fqn} never appeared"
            ctx.spin_for(0.1)

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
