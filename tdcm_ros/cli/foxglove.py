"""``tdcm foxglove``: the live graph of the embedded runtime served to the Foxglove app over the
Foxglove WebSocket protocol (the maintained ``foxglove-sdk``: the ``foxglove`` extra).

Each bridged topic is subscribed for its raw CDR and becomes one channel of the server: message
encoding ``cdr``, schema the type's ``ros2msg`` definition (as in a bag), so Foxglove decodes it
as it decodes a ROS 2 bag. Loopback by default. ``config/foxglove/tdcm_layout.json`` is a layout
for it (3D panel with the body, markers and frames; tension and tip error plotted; diagnostics;
metrics_node's Table I text).
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from tdcm_ros.errors import InputError

DEFAULT_PORT = 8765
#: The bridged topics and their types: the bench's visual and state topics.
TOPICS: dict[str, str] = {
    "/midline": "nav_msgs/msg/Path",
    "/tip_pose": "geometry_msgs/msg/PoseStamped",
    "/body_markers": "visualization_msgs/msg/MarkerArray",
    "/predicted_markers": "geometry_msgs/msg/PoseArray",
    "/markers_poses": "geometry_msgs/msg/PoseArray",
    "/tension": "geometry_msgs/msg/WrenchStamped",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
    "/metrics/table": "std_msgs/msg/String",
    "/metrics/tip_error": "geometry_msgs/msg/Vector3Stamped",
}
#: Topics whose publishers keep their last message for late subscribers (transient local).
LATCHED = frozenset({"/tf_static", "/metrics/table"})
TOOL_NODE = "_tdcm_foxglove"
INSTALL_HINT = "pip install 'tdcm_ros[foxglove]'"


def register(subparsers: Any) -> None:
    """Add the ``foxglove`` subcommand."""
    parser = subparsers.add_parser(
        "foxglove", help="serve the live graph to the Foxglove app (WebSocket, embedded runtime)",
        description="Bridge the bench's topics (" + ", ".join(TOPICS) + ") of the embedded "
                    "runtime's graph to a Foxglove WebSocket server, until Ctrl-C; open "
                    "ws://HOST:PORT in Foxglove and load config/foxglove/tdcm_layout.json. Needs "
                    f"the foxglove extra: {INSTALL_HINT}.",
        epilog="examples:\n"
               "  tdcm foxglove                     # ws://127.0.0.1:8765\n"
               "  tdcm foxglove --port 9000 --topics /tip_pose,/tf")
    parser.add_argument("--host", default="127.0.0.1",
                        help="address to listen on (default 127.0.0.1: this machine only)")
    parser.add_argument("--port", type=int, default=DEFAULT_PORT,
                        help=f"TCP port (default {DEFAULT_PORT}; 0: any free one, printed)")
    parser.add_argument("--topics", metavar="T,T,...",
                        help="bridge only these of the bench's topics (default: all)")
    parser.set_defaults(handler=run)


def _topics(text: str | None) -> dict[str, str]:
    if text is None:
        return TOPICS
    chosen = ["/" + t.strip().lstrip("/") for t in text.split(",") if t.strip()]
    unknown = [t for t in chosen if t not in TOPICS]
    if unknown or not chosen:
        raise InputError(f"--topics = {text!r} names {', '.join(unknown) or 'none'}; allowed: "
                         + ", ".join(TOPICS), parameter="--topics", value=text,
                         allowed=", ".join(TOPICS))
    return {t: TOPICS[t] for t in chosen}


def run(args: argparse.Namespace) -> int:
    """Serve until Ctrl-C (exit 130 by ``tdcm``'s handler)."""
    if not 0 <= args.port <= 65535:
        raise InputError(f"--port = {args.port} is out of range; allowed: [0, 65535]",
                         parameter="--port", value=args.port, allowed="[0, 65535]")
    topics = _topics(args.topics)
    try:
        import foxglove
    except ImportError as error:
        raise InputError(f"tdcm foxglove needs foxglove-sdk ({error}); {INSTALL_HINT}",
                         parameter="foxglove", value=None, allowed=INSTALL_HINT) from None
    from tdcm_ros.bagio import message_definition
    from tdcm_ros.runtime import QoS
    from tdcm_ros.runtime.run_node import open_context

    context = open_context("zenoh", require_graph=True)
    server = None
    try:
        port = context.create_port(TOOL_NODE)
        for topic, type_name in topics.items():
            schema = foxglove.Schema(name=type_name, encoding="ros2msg",
                                     data=message_definition(type_name).encode())
            channel = foxglove.Channel(topic, schema=schema, message_encoding="cdr")
            qos = QoS(depth=1, durability="transient_local") if topic in LATCHED else \
                QoS(depth=10)
            port.create_raw_subscription(topic, type_name, _forward(channel), qos)
        # every channel exists before the server listens: a client's first advertise has them all
        server = foxglove.start_server(host=args.host, port=args.port, name="tdcm_ros")
        print(f"serving {len(topics)} topics on ws://{args.host}:{server.port} (Ctrl-C stops)",
              flush=True)
        context.spin()
    finally:
        if server is not None:
            server.stop()
        context.close()
    return 0


def _forward(channel: Any) -> Any:
    """A raw subscription's callback logging each sample's CDR on ``channel`` (receive time)."""
    def forward(sample: Any) -> None:
        channel.log(sample.data, log_time=time.time_ns())
    return forward
