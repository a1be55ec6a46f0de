"""Runtimes for transport-agnostic nodes: the port, the zenoh runtime, the rclpy adapter.

Importing this package imports neither zenoh nor rclpy; each runtime module does on use.
Run a node with :func:`tdcm_ros.runtime.run_node.run_node`.
"""

from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.parameters import ParamSpec, SetResult
from tdcm_ros.runtime.port import (
    DEFAULT_QOS,
    NodeLogic,
    NodePort,
    Publisher,
    QoS,
    Timer,
)

__all__ = [
    "DEFAULT_QOS",
    "NodeLogic",
    "NodePort",
    "ParamSpec",
    "Publisher",
    "QoS",
    "RuntimePortError",
    "SetResult",
    "Timer",
]
