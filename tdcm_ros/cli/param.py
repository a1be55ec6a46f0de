"""``tdcm param get|set|list NODE ...``: parameters of running nodes, on either runtime;
``tdcm param specs NODE``: a node's parameters from their specs, without running it.

On zenoh it uses the embedded runtime's parameter queryables; on rclpy the node's
rcl_interfaces parameter services (what ``ros2 param`` uses). ``--runtime`` defaults to
``TDCM_RUNTIME`` if set, else zenoh.
"""

from __future__ import annotations

import argparse
import json
import os
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.run_node import RUNTIME_ENV, RUNTIMES
from tdcm_ros.yamlio import load_yaml


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``param`` with its verbs."""
    parser = subparsers.add_parser(
        "param", help="get, set or list node parameters",
        description="Parameters of running nodes, on either runtime, the way ros2 param works; "
                    "'specs' reads a node's parameters from their specs without running it.",
        epilog="examples:\n"
               "  tdcm param list /model_node\n"
               "  tdcm param get /model_node design.preset\n"
               "  tdcm param set /model_node design.E 1.2e+9\n"
               "  tdcm param specs model_node               # offline: units, defaults, ranges")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--runtime", choices=RUNTIMES,
                        default=os.environ.get(RUNTIME_ENV) or "zenoh",
                        help=f"runtime of the node (default: {RUNTIME_ENV}, else zenoh; auto: rclpy "
                             f"if importable)")
    verbs = parser.add_subparsers(dest="verb", required=True, metavar="VERB")
    get = verbs.add_parser("get", parents=[common], help="print a parameter value")
    get.add_argument("node")
    get.add_argument("name")
    get.set_defaults(handler=run_get)
    put = verbs.add_parser("set", parents=[common], help="change a parameter (validated by the node)")
    put.add_argument("node")
    put.add_argument("name")
    put.add_argument("value", help="YAML value, e.g. 0.25, true, [15, 33, 53]")
    put.set_defaults(handler=run_set)
    listing = verbs.add_parser("list", parents=[common], help="list parameters with values")
    listing.add_argument("node")
    listing.set_defaults(handler=run_list)
    specs = verbs.add_parser("specs", help="print a node's parameters from their specs (offline): "
                                           "name, unit, default, allowed values, meaning")
    specs.add_argument("node")
    specs.set_defaults(handler=run_specs)


def _call(args: argparse.Namespace, op: str, request: dict[str, Any]) -> dict[str, Any]:
    from tdcm_ros.runtime.run_node import open_context, resolve_runtime

    runtime = resolve_runtime(args.runtime)
    context = open_context(runtime)
    node = "/" + args.node.strip("/")
    try:
        if runtime == "rclpy":
            from tdcm_ros.runtime.rclpy_runtime import call_parameters as call_rclpy

            return call_rclpy(context, node, op, request)
        from tdcm_ros.runtime.zenoh_runtime import call_parameters

        return call_parameters(context.session, context.domain_id, node, op, request)
    finally:
        context.close()


def run_get(args: argparse.Namespace) -> int:
    """Print the value."""
    print(json.dumps(_call(args, "get", {"name": args.name})["value"]))
    return 0


def run_set(args: argparse.Namespace) -> int:
    """Set the value; a rejection is an input error carrying the node's reason."""
    value = load_yaml(args.value, args.name)
    answer = _call(args, "set", {"name": args.name, "value": value})
    if not answer["successful"]:
        raise InputError(f"rejected: {answer['reason']}", parameter=args.name, value=value)
    print("Set parameter successful")
    return 0


def run_list(args: argparse.Namespace) -> int:
    """Print ``name: value  # description`` lines."""
    for name, info in sorted(_call(args, "list", {})["parameters"].items()):
        note = f"  # {info['description']}" if info["description"] else ""
        print(f"  {name}: {json.dumps(info['value'])}{note}")
    return 0


def run_specs(args: argparse.Namespace) -> int:
    """Print the node's parameters as a Markdown table, from the specs it declares them with."""
    import importlib

    from tdcm_ros.runtime import node_target
    from tdcm_ros.spec import spec_table

    module = importlib.import_module(node_target(args.node).partition(":")[0])
    print("| parameter | unit | default | allowed | meaning |\n|---|---|---|---|---|")
    for name, row in zip(module.PARAMETERS, spec_table(module.PARAMETERS.values()), strict=True):
        default = "(derived)" if row["default"] == "None" else row["default"]
        cells = (f"`{name}`", row["unit"], default, row["allowed"], row["description"])
        print("| " + " | ".join(cell.replace("|", "\\|") for cell in cells) + " |")
    return 0
