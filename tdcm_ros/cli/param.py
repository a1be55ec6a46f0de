"""``tdcm param get|set|list|describe|dump NODE ...``: parameters of running nodes, on either
runtime; ``tdcm param specs NODE``: a node's parameters from their specs, without running it.

Both runtimes go through the node's six ``rcl_interfaces`` parameter services, what ``ros2 param``
uses (:class:`tdcm_ros.runtime.param_client.ParameterClient` over the context's
``call_service``). ``--runtime`` defaults to ``TDCM_RUNTIME`` if set, else zenoh.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

from tdcm_ros.cli.runtime_option import add_runtime_option
from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.yamlio import load_yaml

if TYPE_CHECKING:  # the client imports the message model; help must not
    from tdcm_ros.runtime.param_client import ParameterClient


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
               "  tdcm param describe /model_node design.E\n"
               "  tdcm param dump /model_node > model_node.yaml\n"
               "  tdcm param specs model_node               # offline: units, defaults, ranges")
    common = argparse.ArgumentParser(add_help=False)
    add_runtime_option(common, "the node")
    common.add_argument("--timeout", type=float, metavar="S",
                        help="longest wait for each answer of the node, s (default: the "
                             "parameter client's PARAM_TIMEOUT_S, 5 s); Ctrl-C stops the wait")
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
    describe = verbs.add_parser("describe", parents=[common],
                                help="print type, description and constraints of parameters")
    describe.add_argument("node")
    describe.add_argument("names", nargs="+", metavar="name")
    describe.set_defaults(handler=run_describe)
    dump = verbs.add_parser("dump", parents=[common],
                            help="print every parameter as ROS 2 parameter YAML (ros__parameters)")
    dump.add_argument("node")
    dump.set_defaults(handler=run_dump)
    specs = verbs.add_parser("specs", help="print a node's parameters from their specs (offline): "
                                           "name, unit, default, allowed values, meaning")
    specs.add_argument("node")
    specs.set_defaults(handler=run_specs)


R = TypeVar("R")


def _with_client(args: argparse.Namespace, use: Callable[[ParameterClient], R]) -> R:
    """``use`` a parameter client of ``args.node`` on a context of ``args.runtime``."""
    from tdcm_ros.runtime.param_client import ParameterClient
    from tdcm_ros.runtime.run_node import open_context, resolve_runtime

    if args.timeout is not None and not args.timeout > 0:
        raise out_of_range("--timeout", args.timeout, "> 0 s", unit="s")
    context = open_context(resolve_runtime(args.runtime), require_graph=True)
    try:
        if args.timeout is None:
            return use(ParameterClient(context, args.node))
        return use(ParameterClient(context, args.node, args.timeout))
    finally:
        context.close()


def run_get(args: argparse.Namespace) -> int:
    """Print the value."""
    print(json.dumps(_with_client(args, lambda client: client.get(args.name))))
    return 0


def run_set(args: argparse.Namespace) -> int:
    """Set the value; a rejection is an input error carrying the node's reason."""
    value = load_yaml(args.value, args.name)
    result = _with_client(args, lambda client: client.set(args.name, value))
    if not result.successful:
        raise InputError(f"rejected: {result.reason}", parameter=args.name, value=value)
    print("Set parameter successful")
    return 0


def _listing(client: ParameterClient) -> tuple[dict[str, Any], list[Any]]:
    names = client.names()
    return client.get_values(names), client.describe(names)


def run_list(args: argparse.Namespace) -> int:
    """Print ``name: value  # description`` lines."""
    values, descriptors = _with_client(args, _listing)
    for desc in descriptors:
        note = f"  # {desc.description}" if desc.description else ""
        print(f"  {desc.name}: {json.dumps(values[desc.name])}{note}")
    return 0


def run_describe(args: argparse.Namespace) -> int:
    """Print each parameter's type, description and constraints, as ``ros2 param describe``."""
    from tdcm_ros.runtime.param_services import type_name as parameter_type_name

    for desc in _with_client(args, lambda client: client.describe(args.names)):
        print(f"Parameter name: {desc.name}\n  Type: {parameter_type_name(desc.type)}")
        if desc.description:
            print(f"  Description: {desc.description}")
        print("  Constraints:")
        if desc.read_only:
            print("    Read only: true")
        for bounds in [*desc.floating_point_range, *desc.integer_range]:
            print(f"    Min value: {bounds.from_value}\n    Max value: {bounds.to_value}")
    return 0


def run_dump(args: argparse.Namespace) -> int:
    """Print the node's values as a parameter file (``tdcm up --params`` and ROS read it)."""
    from tdcm_ros.runtime import param_file_text

    values, _ = _with_client(args, _listing)
    print(param_file_text({"/" + args.node.strip("/"): values}), end="")
    return 0


def run_specs(args: argparse.Namespace) -> int:
    """Print the node's parameters as a Markdown table, from the specs it declares them with."""
    import importlib

    from tdcm_ros.runtime import NODE_COMMON, node_target
    from tdcm_ros.spec import spec_table

    module = importlib.import_module(node_target(args.node).partition(":")[0])
    specs = {**module.PARAMETERS, **NODE_COMMON}
    print("| parameter | unit | default | allowed | meaning |\n|---|---|---|---|---|")
    for name, row in zip(specs, spec_table(specs.values()), strict=True):
        default = "(derived)" if row["default"] == "None" else row["default"]
        cells = (f"`{name}`", row["unit"], default, row["allowed"], row["description"])
        print("| " + " | ".join(cell.replace("|", "\\|") for cell in cells) + " |")
    return 0
