"""``tdcm service list|call``: the graph's services, like ``ros2 service``, on either runtime.

On zenoh a service is rmw_zenoh's (a queryable and an ``SS`` liveliness token); on rclpy a real
ROS 2 service. ``--runtime`` defaults to ``TDCM_RUNTIME`` if set, else zenoh. ``call`` exits 0
when the service answered ``success: true``, 1 when it answered ``success: false`` (the reason is
printed) or nothing answered within ``--timeout`` (the error on stderr).
"""

from __future__ import annotations

import argparse
from typing import Any

import yaml

from tdcm_ros.cli.runtime_option import add_runtime_option
from tdcm_ros.errors import InputError
from tdcm_ros.yamlio import load_yaml

DEFAULT_TYPE = "std_srvs/srv/Trigger"
REFUSED_EXIT = 1
"""Exit status of a call answered ``success: false`` (or not answered)."""
EXIT_MEANINGS = {"service call": {
    REFUSED_EXIT: "the service answered success: false, or no server answered in --timeout"}}
"""What ``service call`` means by an exit status (its ``--help`` epilog)."""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``service`` with its verbs."""
    parser = subparsers.add_parser(
        "service", help="list or call services (e.g. the driver's commands)",
        description="List the services of the live graph or call one, as `ros2 service` does "
                    "(zenoh or rclpy). The driver's commands are std_srvs/srv/Trigger services: "
                    "the response says whether the command was carried out and, if not, why.",
        epilog="examples:\n"
               "  tdcm service list -t\n"
               "  tdcm service call /tension_driver/clear_faults")
    common = argparse.ArgumentParser(add_help=False)
    add_runtime_option(common, "the graph")
    verbs = parser.add_subparsers(dest="verb", required=True, metavar="VERB")
    listing = verbs.add_parser("list", parents=[common], help="services with a server")
    listing.add_argument("-t", "--show-types", action="store_true", help="show service types")
    listing.add_argument("--timeout", type=float, default=1.0, help="discovery wait (s)")
    listing.set_defaults(handler=run_list)
    call = verbs.add_parser("call", parents=[common],
                            help="call a service and print its response")
    call.add_argument("service", help="service name, e.g. /tension_driver/start_schedule")
    call.add_argument("type", nargs="?", default=DEFAULT_TYPE,
                      help=f"pkg/srv/Name (default: {DEFAULT_TYPE})")
    call.add_argument("values", nargs="?", default="{}", help="request as YAML (default: {})")
    call.add_argument("--timeout", type=float, default=5.0,
                      help="wait this long (s) for the server and its answer")
    call.set_defaults(handler=run_call)


def _context(args: argparse.Namespace) -> Any:
    from tdcm_ros.runtime.run_node import open_context, resolve_runtime

    return open_context(resolve_runtime(args.runtime), require_graph=True)


def run_list(args: argparse.Namespace) -> int:
    """Print one service per line (with ``[type]`` if ``-t``)."""
    context = _context(args)
    try:
        services = context.service_names(args.timeout)
    finally:
        context.close()
    for name, type_name in services:
        print(f"{name} [{type_name}]" if args.show_types else name)
    return 0


def run_call(args: argparse.Namespace) -> int:
    """Call the service; print the request and the response as YAML."""
    from tdcm_ros.bagio import from_dict, normalize_service_type, to_dict

    if not args.timeout > 0:
        raise InputError(f"--timeout = {args.timeout} s must be > 0", parameter="--timeout",
                         value=args.timeout, allowed="> 0 s")
    service = normalize_service_type(args.type)
    values = load_yaml(args.values, "values")
    if not isinstance(values, dict):
        raise InputError(f"request {args.values!r} is not a YAML mapping", parameter="values",
                         value=args.values, allowed="a YAML mapping, e.g. {}")
    request = from_dict(f"{service}_Request", values)
    name = "/" + args.service.strip("/")
    context = _context(args)
    try:
        print(f"requester: making request: {service}_Request {values}")
        response = context.call_service(name, service, request, timeout=args.timeout)
    finally:
        context.close()
    answer = to_dict(response)
    print("\nresponse:")
    print(yaml.safe_dump(answer, sort_keys=False, width=1 << 16).rstrip())
    return REFUSED_EXIT if answer.get("success") is False else 0
