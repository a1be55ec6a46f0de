"""``tdcm up``: start the node set on the embedded runtime, each node its own process."""

from __future__ import annotations

import argparse
import os

from tdcm_ros.runtime.registry import DEFAULT_NODE_SET, NODES


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``up`` subcommand."""
    parser = subparsers.add_parser("up", help="start the node set (Ctrl-C stops every process)")
    parser.add_argument("--params", help="ROS 2 parameter YAML (ros__parameters layout)")
    parser.add_argument("--nodes", default=",".join(DEFAULT_NODE_SET),
                        help=f"comma-separated node names from: {', '.join(sorted(NODES))}")
    parser.add_argument("--runtime", default="zenoh", choices=("zenoh", "rclpy"),
                        help="runtime of every node (default zenoh)")
    parser.add_argument("--endpoint", default=None,
                        help="router endpoint (default TDCM_ZENOH_ENDPOINT or tcp/127.0.0.1:7447)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Launch and wait; returns the exit status."""
    from tdcm_ros.runtime.launcher import launch
    from tdcm_ros.runtime.run_node import configure_logging
    from tdcm_ros.runtime.zenoh_runtime import ENDPOINT_ENV, endpoint

    configure_logging()
    if args.endpoint:
        os.environ[ENDPOINT_ENV] = args.endpoint
    nodes = [n.strip() for n in args.nodes.split(",") if n.strip()]
    return launch(nodes, params_file=args.params, runtime=args.runtime,
                  endpoint=endpoint())
