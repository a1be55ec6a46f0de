"""``tdcm up``: start the node set, each node its own process, on the embedded zenoh runtime
(with a router unless one answers on the endpoint) or on rclpy (``--runtime rclpy``: no router,
no zenoh import; nodes discover each other on ``ROS_DOMAIN_ID``).

``--twin`` adds ``device_twin`` and ``tension_driver`` in front of the node set, the driver's
``port`` wired to the twin's pty link (``<tmp>/tdcm_twin_<pid of tdcm up>``, unique per run), so
tension -> model runs with no hardware. Ctrl-C stops the nodes in reverse order: the driver
releases the tendon before the twin goes away.

``--connect ENDPOINT`` uses an existing router (a ROS machine's ``rmw_zenohd``, or tdcm's own
router on another host) and never starts one; ``--endpoint`` starts one there unless one answers.
Either is exported to the nodes as ``TDCM_ZENOH_ENDPOINT``.

``--zenoh-config FILE`` (exported as ``TDCM_ZENOH_CONFIG``) is the zenoh config of every node and
``--router-config FILE`` (``TDCM_ZENOH_ROUTER_CONFIG``) the router's, e.g. ``config/zenoh/``'s
peer and router files (TLS, user/password, access control); the role's mode and endpoints are
set on top of each. Both load before anything starts; nodes listening beyond loopback without
authentication log a warning (the router warns for itself).
"""

from __future__ import annotations

import argparse
import os
import tempfile
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.runtime import (
    DEFAULT_NODE_SET,
    FRAMED_NODES,
    NODES,
    normalize_namespace,
    parse_cli_param,
    validate_frame_prefix,
)

TWIN_NODES = ("device_twin", "tension_driver")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``up`` subcommand."""
    parser = subparsers.add_parser(
        "up", help="start the node set (Ctrl-C stops every process)",
        description="Start the node set, each node its own process, on the embedded zenoh "
                    "runtime (with a router unless one answers on the endpoint) or on rclpy. "
                    "--twin adds the device twin and the tension driver wired to it, so the "
                    "graph runs with no hardware. Ctrl-C stops the nodes in reverse order.",
        epilog="examples:\n"
               "  tdcm up --twin --schedule                 # simulated bench, runs the staircase\n"
               "  tdcm up --params config/model_node.yaml --nodes model_node\n"
               "  tdcm up --runtime rclpy --twin --scene friction-hysteresis")
    parser.add_argument("--params", help="ROS 2 parameter YAML (ros__parameters layout)")
    parser.add_argument("--nodes", default=",".join(DEFAULT_NODE_SET),
                        help=f"comma-separated node names from: {', '.join(sorted(NODES))}")
    parser.add_argument("--runtime", default="zenoh", choices=("zenoh", "rclpy"),
                        help="runtime of every node (default zenoh)")
    parser.add_argument("--namespace", default="/",
                        help="namespace of every node (default /): a second robot on the same "
                             "graph runs with another, e.g. --namespace /robot2 --connect "
                             "ENDPOINT")
    parser.add_argument("--frame-prefix", default="", metavar="PREFIX",
                        help="put before every TF frame of this robot (frame_prefix of every "
                             "node that names one), e.g. --frame-prefix robot2/ with "
                             "--namespace /robot2: robot2/tdcm_base; the mocap frame is shared")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--endpoint", default=None,
                       help="zenoh router endpoint, started here unless one answers (default "
                            "TDCM_ZENOH_ENDPOINT or tcp/127.0.0.1:7447; zenoh runtime only)")
    where.add_argument("--connect", default=None, metavar="ENDPOINT",
                       help="use the existing zenoh router at ENDPOINT (e.g. a ROS machine's "
                            "rmw_zenohd, tcp/HOST:7447) and never start one; zenoh runtime only")
    parser.add_argument("--zenoh-config", default=None,
                        help="zenoh JSON5 config of every node (and of the router without "
                             "--router-config), e.g. config/zenoh/peer.json5; zenoh runtime only")
    parser.add_argument("--router-config", default=None,
                        help="zenoh JSON5 config of the router tdcm up starts, e.g. "
                             "config/zenoh/router.json5; zenoh runtime only")
    parser.add_argument("-p", "--param", action="append", default=[], metavar="NODE:NAME:=VALUE",
                        help="a parameter of one node (ros2's -p spelling, value as YAML) over "
                             "--params; repeatable, e.g. -p model_node:input.max_age_s:=2.0")
    parser.add_argument("--use-sim-time", action="store_true",
                        help="every node takes its time from /clock (use_sim_time: true), e.g. "
                             "for tdcm bag play --clock")
    parser.add_argument("--on-router-exit", choices=("restart", "stop"), default="restart",
                        help="when the router tdcm up started exits: start it again (default; "
                             "the nodes reconnect) or stop the graph and exit 1; zenoh only")
    parser.add_argument("--twin", action="store_true",
                        help="also start device_twin and tension_driver wired to it (no hardware)")
    parser.add_argument("--scene", help="scene of the device twin (name or YAML path; needs --twin)")
    parser.add_argument("--schedule", action="store_true",
                        help="tension_driver runs its schedule.* staircase once connected")
    parser.set_defaults(handler=run)


def plan(args: argparse.Namespace, pid: int) -> tuple[list[str], dict[str, dict[str, Any]],
                                                      dict[str, str]]:
    """Node names, per-node parameter overrides and ready paths for ``launch``."""
    nodes = [n.strip() for n in args.nodes.split(",") if n.strip()]
    try:
        args.namespace = normalize_namespace(args.namespace)
    except InputError as error:
        raise InputError(f"--namespace = {args.namespace!r} is invalid", parameter="--namespace",
                         value=args.namespace, allowed=error.allowed) from error
    overrides: dict[str, dict[str, Any]] = {}
    ready: dict[str, str] = {}
    for option in ("endpoint", "connect", "zenoh_config", "router_config"):
        value = getattr(args, option)
        if value and args.runtime != "zenoh":
            flag = "--" + option.replace("_", "-")
            raise InputError(f"{flag} = {value!r} needs --runtime zenoh", parameter=flag,
                             value=value, allowed="with --runtime zenoh")
    if args.scene and not args.twin:
        raise InputError(f"--scene = {args.scene!r} needs --twin", parameter="--scene",
                         value=args.scene, allowed="with --twin")
    if args.twin:
        link = os.path.join(tempfile.gettempdir(), f"tdcm_twin_{pid}")
        nodes = [*TWIN_NODES, *(n for n in nodes if n not in TWIN_NODES)]
        overrides["device_twin"] = {"link": link, **({"scene": args.scene} if args.scene else {})}
        overrides["tension_driver"] = {"port": link}
        ready["device_twin"] = link
    for item in args.param:
        node, name, value = parse_cli_param(item)
        if not node:
            raise InputError(f"-p {item!r} names no node; tdcm up starts several: write "
                             f"NODE:NAME:=VALUE", parameter="-p", value=item,
                             allowed="NODE:NAME:=VALUE")
        if node not in nodes:
            raise InputError(f"-p {item!r} names node {node!r}, which is not started; nodes: "
                             f"{', '.join(nodes)}", parameter="-p", value=item,
                             allowed=", ".join(nodes))
        overrides.setdefault(node, {})[name] = value
    if args.frame_prefix:
        validate_frame_prefix(args.frame_prefix, "--frame-prefix")
        for node in nodes:
            if node in FRAMED_NODES:
                overrides.setdefault(node, {}).setdefault("frame_prefix", args.frame_prefix)
    if args.use_sim_time:
        for node in nodes:
            overrides.setdefault(node, {})["use_sim_time"] = True
    if args.schedule:
        if "tension_driver" not in nodes:
            raise InputError("--schedule needs tension_driver in the node set (or --twin)",
                             parameter="--schedule", value=True, allowed="with tension_driver")
        overrides.setdefault("tension_driver", {})["schedule.autostart"] = True
    return nodes, overrides, ready


def router_endpoint(args: argparse.Namespace) -> str | None:
    """The zenoh router endpoint (``--endpoint``, also exported to the nodes); ``None`` on rclpy."""
    if args.runtime != "zenoh":
        return None
    from tdcm_ros.runtime.zenoh_runtime import ENDPOINT_ENV, endpoint

    chosen = args.endpoint or args.connect
    if chosen:
        os.environ[ENDPOINT_ENV] = chosen
    return endpoint()


def export_zenoh_configs(args: argparse.Namespace, router_endpoint: str) -> None:
    """Export ``--zenoh-config`` and ``--router-config`` to every child, load both configs now
    (a bad file fails before anything starts) and warn if the nodes would listen beyond loopback
    without authentication."""
    from tdcm_ros.runtime.zenoh_config import ROUTER_CONFIG_ENV, warn_if_exposed
    from tdcm_ros.runtime.zenoh_runtime import CONFIG_ENV, session_config

    if args.zenoh_config:
        os.environ[CONFIG_ENV] = args.zenoh_config
    if args.router_config:
        os.environ[ROUTER_CONFIG_ENV] = args.router_config
    session_config(mode="router", router_endpoint=router_endpoint)
    warn_if_exposed(session_config(mode="peer", router_endpoint=router_endpoint), "peer")


def run(args: argparse.Namespace) -> int:
    """Launch and wait; returns the exit status."""
    from tdcm_ros.runtime import launch
    from tdcm_ros.runtime.run_node import configure_logging

    configure_logging()
    nodes, overrides, ready = plan(args, os.getpid())
    endpoint = router_endpoint(args)
    if endpoint is not None:
        export_zenoh_configs(args, endpoint)
    return launch(nodes, params_file=args.params, runtime=args.runtime, endpoint=endpoint,
                  overrides=overrides, ready_paths=ready, start_router=not args.connect,
                  on_router_exit=args.on_router_exit, namespace=args.namespace)
