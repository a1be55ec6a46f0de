"""Nodes ``tdcm up`` can start, by name. Add a node with one line: ``"name": "module:Class"``."""

from __future__ import annotations

from tdcm_ros.errors import InputError

NODES: dict[str, str] = {
    "talker": "tdcm_ros.nodes.talker:Talker",
    "model_node": "tdcm_ros.nodes.model_node:ModelNode",
    "metrics_node": "tdcm_ros.nodes.metrics_node:MetricsNode",
    "mocap_node": "tdcm_ros.nodes.mocap_node:MocapNode",
    "tension_driver": "tdcm_ros.nodes.tension_driver:TensionDriverNode",
    "device_twin": "tdcm_ros.nodes.device_twin:DeviceTwinNode",
    "shape_controller": "tdcm_ros.nodes.shape_controller:ShapeControllerNode",
}

DEFAULT_NODE_SET: tuple[str, ...] = ("model_node",)
#: The nodes that name frames of the robot and take ``frame_prefix`` (``tdcm up --frame-prefix``).
FRAMED_NODES: frozenset[str] = frozenset(NODES) - {"talker"}


def node_target(name: str) -> str:
    """``module:Class`` of a registered node."""
    if name not in NODES:
        raise InputError(f"unknown node {name!r}; registered: {', '.join(sorted(NODES))}",
                         parameter="nodes", value=name, allowed=", ".join(sorted(NODES)))
    return NODES[name]
