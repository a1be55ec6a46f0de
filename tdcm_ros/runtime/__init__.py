"""Runtimes for transport-agnostic nodes: the port, the zenoh runtime, the rclpy adapter.

Importing this package imports neither zenoh nor rclpy. Run a graph of nodes with :func:`launch`.

Separate entry points, kept out of this face: :mod:`tdcm_ros.runtime.run_node` (a script,
``python -m tdcm_ros.runtime.run_node``: ``main_for``, ``open_context``, ``RUNTIMES``),
:mod:`tdcm_ros.runtime.wire` (the rmw_zenoh wire format, used as a namespace), and, because they
import their transport, :mod:`tdcm_ros.runtime.zenoh_runtime`, :mod:`tdcm_ros.runtime.zenoh_config`,
:mod:`tdcm_ros.runtime.router` (zenoh; also a script) and :mod:`tdcm_ros.runtime.rclpy_runtime`
(rclpy).
"""

from tdcm_ros.runtime.diagnostics import (
    DiagnosticLevel,
    Diagnostics,
    EventWindow,
    Status,
    summary,
)
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.graph import NodeGraph
from tdcm_ros.runtime.launcher import launch
from tdcm_ros.runtime.names import (
    normalize_namespace,
    resolve_topic,
    validate_frame_prefix,
)
from tdcm_ros.runtime.parameters import ParamSpec, ParamValue, SetResult
from tdcm_ros.runtime.params import node_parameters, param_file_text, parse_cli_param
from tdcm_ros.runtime.port import (
    CLOCK_QOS,
    CLOCK_TOPIC,
    CLOCK_TYPE,
    DEFAULT_QOS,
    NodeLogic,
    NodePort,
    Publisher,
    QoS,
    Timer,
)
from tdcm_ros.runtime.qos_overrides import overridable_qos
from tdcm_ros.runtime.registry import DEFAULT_NODE_SET, FRAMED_NODES, NODES, node_target
from tdcm_ros.runtime.shutdown import close_within, exit_now
from tdcm_ros.runtime.spec_params import NODE_COMMON, declare_specs, grouped, read_specs
from tdcm_ros.runtime.throttle import Throttled, template

__all__ = [
    "CLOCK_QOS",
    "CLOCK_TOPIC",
    "CLOCK_TYPE",
    "DEFAULT_NODE_SET",
    "DEFAULT_QOS",
    "FRAMED_NODES",
    "NODES",
    "NODE_COMMON",
    "DiagnosticLevel",
    "Diagnostics",
    "EventWindow",
    "NodeGraph",
    "NodeLogic",
    "NodePort",
    "ParamSpec",
    "ParamValue",
    "Publisher",
    "QoS",
    "RuntimePortError",
    "SetResult",
    "Status",
    "Throttled",
    "Timer",
    "close_within",
    "declare_specs",
    "exit_now",
    "grouped",
    "launch",
    "node_parameters",
    "node_target",
    "normalize_namespace",
    "overridable_qos",
    "param_file_text",
    "parse_cli_param",
    "read_specs",
    "resolve_topic",
    "summary",
    "template",
    "validate_frame_prefix",
]
