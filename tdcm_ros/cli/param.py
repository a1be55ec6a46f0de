"""``tdcm param get|set|list NODE ...``: parameters of nodes on the embedded runtime."""

from __future__ import annotations

import argparse
import json
from typing import Any

import yaml

from tdcm_ros.errors import InputError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``param`` with its verbs."""
    parser = subparsers.add_parser("param", help="get, set or list node parameters (zenoh)")
    verbs = parser.add_subparsers(dest="verb", required=True, metavar="VERB")
    get = verbs.add_parser("get", help="print a parameter value")
    get.add_argument("node")
    get.add_argument("name")
    get.set_defaults(handler=run_get)
    put = verbs.add_parser("set", help="change a parameter (validated by the node)")
    put.add_argument("node")
    put.add_argument("name")
    put.add_argument("value", help="YAML value, e.g. 0.25, true, [15, 33, 53]")
    put.set_defaults(handler=run_set)
    listing = verbs.add_parser("list", help="list parameters with values")
    listing.add_argument("node")
    listing.set_defaults(handler=run_list)


def _call(node: str, op: str, request: dict[str, Any]) -> dict[str, Any]:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext, call_parameters

    context = ZenohContext()
    try:
        return call_parameters(context.session, context.domain_id, "/" + node.strip("/"), op,
                               request)
    finally:
        context.close()


def run_get(args: argparse.Namespace) -> int:
    """Print the value."""
    print(json.dumps(_call(args.node, "get", {"name": args.name})["value"]))
    return 0


def run_set(args: argparse.Namespace) -> int:
    """Set the value; a rejection is an input error carrying the node's reason."""
    try:
        value = yaml.safe_load(args.value)
    except yaml.YAMLError as error:
        raise InputError(f"value is not valid YAML: {error}", parameter=args.name,
                         value=args.value) from error
    answer = _call(args.node, "set", {"name": args.name, "value": value})
    if not answer["successful"]:
        raise InputError(f"rejected: {answer['reason']}", parameter=args.name, value=value)
    print("Set parameter successful")
    return 0


def run_list(args: argparse.Namespace) -> int:
    """Print ``name: value  # description`` lines."""
    for name, info in sorted(_call(args.node, "list", {})["parameters"].items()):
        note = f"  # {info['description']}" if info["description"] else ""
        print(f"  {name}: {json.dumps(info['value'])}{note}")
    return 0
