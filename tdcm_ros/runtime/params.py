"""ROS 2 parameter files (``ros__parameters`` layout) and ``-p`` values, read as rcl reads them.

Both runtimes use this reader, so one file gives the same values on each (the rclpy half of CI
checks it against rclpy itself):

- **scalars** take rcl's types, not YAML's (:mod:`tdcm_ros.runtime.rcl_scalars`: ``y`` is a
  bool, ``0x1F`` an integer, ``1e9`` a double, ``~`` and ``1_000`` strings);
- **sequences** hold one type (``[1, 2.5]`` is refused, as rcl refuses it) and at least one item;
- **node keys** are fully qualified (``/ns/node``), relative (``node`` = ``/node``), nested
  mappings (``ns: {node: ...}``), or wildcards of whole tokens (``/**`` any depth, ``*`` one
  token); a partial wildcard (``/ns/pro*``) or a malformed token is refused;
- **precedence** is rcl's: all sources (files, then ``-p`` items, in order) fill one table of
  node keys in order of first appearance (a key written again, in any source, merges into its
  first place), and every key that matches the node applies in that order, later over earlier.
  Within one key, a later value replaces an earlier one of the same type; of values of different
  types, rclpy keeps the first of bool, integer, double, string, then the arrays in that order.

Nested mappings under ``ros__parameters`` flatten to dotted names (``solver.tol``).
"""

from __future__ import annotations

import math
import re
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.rcl_scalars import rcl_scalar
from tdcm_ros.yamlio import compose_yaml

ROS_PARAMETERS = "ros__parameters"
_STR_TAG = "tag:yaml.org,2002:str"
_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_WILDCARDS = ("*", "**")
_NAME_TOKENS = "tokens [A-Za-z_][A-Za-z0-9_]*, or whole-token wildcards * and **"
#: rclpy's order among the values one node key holds for a parameter (the first present wins)
_KIND_ORDER = ("bool", "integer", "double", "string",
               "bool array", "integer array", "double array", "string array")


@dataclass(frozen=True)
class CliParam:
    """A ``-p [NODE:]NAME:=VALUE`` item, one source of parameters among files."""

    item: str


Source = str | Path | CliParam
#: parameter name -> {kind: value}; see the module docstring for how kinds compete
_Values = dict[str, dict[str, Any]]


def _kind(value: Any) -> str:
    """rcl's type name of a scalar or list value."""
    if isinstance(value, list):
        return f"{_kind(value[0])} array"
    if isinstance(value, bool):
        return "bool"
    return {int: "integer", float: "double"}.get(type(value), "string")


def _scalar(node: ScalarNode) -> bool | int | float | str:
    return rcl_scalar(node.value, quoted=node.style in ("'", '"'), str_tag=node.tag == _STR_TAG)


def _problem(where: str, node: Node, what: str, allowed: str) -> InputError:
    return InputError(f"{where}: line {node.start_mark.line + 1}: {what}", parameter="params_file",
                      value=where, allowed=allowed)


def _value(node: Node, name: str, where: str) -> Any:
    """The value rcl reads for parameter ``name`` from ``node``: a scalar or a one-type list."""
    if isinstance(node, ScalarNode):
        if node.value == "" and node.style not in ("'", '"'):
            raise _problem(where, node, f"parameter {name} has no value",
                           "a value (write '' for an empty string)")
        return _scalar(node)
    if not isinstance(node, SequenceNode):
        raise _problem(where, node, f"parameter {name} is neither a value nor a sequence",
                       "a scalar or a sequence of scalars")
    if not node.value:
        raise _problem(where, node, f"parameter {name} is an empty sequence, which rcl reads as "
                       "no value", "a sequence of at least one item")
    items = []
    for item in node.value:
        if not isinstance(item, ScalarNode):
            raise _problem(where, item, f"parameter {name} nests a collection in a sequence",
                           "a sequence of scalars")
        items.append(_scalar(item))
    kinds = {_kind(item) for item in items}
    if len(kinds) > 1:
        raise _problem(where, node, f"parameter {name} mixes {' and '.join(sorted(kinds))} "
                       "items in one sequence (rcl refuses it)",
                       "items of one type (write 2.0, not 2, among doubles)")
    return items


def _check_node_key(key: str, where: str, node: Node) -> None:
    """Refuse a node key rcl refuses: a token that is not a name, or a partial wildcard."""
    if key in ("/**", "/*"):
        return
    namespace, _, name = key.rpartition("/")
    tokens = [*(namespace.removeprefix("/").split("/") if namespace else []), name]
    for token in tokens:
        if token not in _WILDCARDS and not _TOKEN.fullmatch(token):
            raise _problem(where, node, f"node key {key!r}: {token!r} is not a node or namespace "
                           "token (rcl refuses the file)", _NAME_TOKENS)


def _add(table: dict[str, _Values], key: str, name: str, value: Any) -> None:
    """Merge one value into ``table[key]`` (the key's first place if it is already there)."""
    table.setdefault(key, {}).setdefault(name, {})[_kind(value)] = value


def _parameters(node: Node, prefix: str, key: str, table: dict[str, _Values], where: str) -> None:
    if not isinstance(node, MappingNode):
        raise _problem(where, node, f"{key}: {ROS_PARAMETERS}{prefix and ' ' + prefix} must be "
                       "a mapping", "a mapping of parameter names to values")
    table.setdefault(key, {})
    for name_node, value_node in node.value:
        name = f"{prefix}{_key_text(name_node, where)}"
        if isinstance(value_node, MappingNode):
            _parameters(value_node, f"{name}.", key, table, where)
        else:
            _add(table, key, name, _value(value_node, name, where))


def _key_text(node: Node, where: str) -> str:
    if not isinstance(node, ScalarNode) or node.value == "":
        raise _problem(where, node, "a key is empty or not a scalar", "a non-empty scalar key")
    return str(node.value)


def _nodes(mapping: Node, path: str, table: dict[str, _Values], where: str) -> None:
    if not isinstance(mapping, MappingNode):
        raise _problem(where, mapping, f"{path or 'the top level'} must map node names to "
                       f"{ROS_PARAMETERS}", f"node name: {{{ROS_PARAMETERS}: {{...}}}}")
    for key_node, value_node in mapping.value:
        key = _key_text(key_node, where)
        if key.startswith(ROS_PARAMETERS):  # rcl compares the prefix only
            if not path:
                raise _problem(where, key_node, f"{ROS_PARAMETERS} with no node name before it",
                               f"node name: {{{ROS_PARAMETERS}: {{...}}}}")
            _check_node_key(path, where, key_node)
            _parameters(value_node, "", path, table, where)
        elif isinstance(value_node, MappingNode):
            _nodes(value_node, f"{path}/{key}" if path else key, table, where)
        else:
            raise _problem(where, value_node, f"{path}/{key} is not under {ROS_PARAMETERS}",
                           f"node name: {{{ROS_PARAMETERS}: {{...}}}}")


def _read_file(path: str | Path, table: dict[str, _Values]) -> None:
    where = Path(path)
    try:
        text = where.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"cannot read parameter file {where}: {error}",
                         parameter="params_file", value=str(where)) from error
    tree = compose_yaml(text, str(where), parameter="params_file")
    if tree is not None:
        _nodes(tree, "", table, str(where))


def parse_cli_param(item: str) -> tuple[str, str, Any]:
    """``[NODE:]NAME:=VALUE`` (ros2's ``-p`` spelling) as ``(node or "", name, value)``, the
    value read by rcl's rules. ``InputError`` naming the item if it is not of that form."""
    target, sep, text = item.partition(":=")
    node, _, name = target.rpartition(":")
    if not sep or not name:
        raise InputError(f"-p {item!r} is not [NODE:]NAME:=VALUE", parameter="-p", value=item,
                         allowed="[NODE:]NAME:=VALUE, e.g. model_node:input.max_age_s:=2.0")
    tree = compose_yaml(text, f"-p {target}", parameter="-p")
    if tree is None:
        raise InputError(f"-p {item!r} has no value", parameter="-p", value=item,
                         allowed="[NODE:]NAME:=VALUE with a value")
    return node, name, _value(tree, name, f"-p {target}")


def _resolved(values: _Values) -> dict[str, Any]:
    return {name: next(kinds[kind] for kind in _KIND_ORDER if kind in kinds)
            for name, kinds in values.items()}


def parameter_table(sources: Iterable[Source]) -> list[tuple[str, dict[str, Any]]]:
    """``(node key, {parameter: value})`` for every node key of ``sources`` (files, and
    :class:`CliParam` items, whose key is their node or ``/**``), in rcl's order of first
    appearance; any problem an :class:`InputError` naming the file, line and parameter."""
    if isinstance(sources, str | Path):
        raise TypeError("sources is a sequence of files and -p items, not one path")
    table: dict[str, _Values] = {}
    for source in sources:
        if isinstance(source, CliParam):
            node, name, value = parse_cli_param(source.item)
            _add(table, node or "/**", name, value)
        else:
            _read_file(source, table)
    return [(key, _resolved(values)) for key, values in table.items()]


def read_param_file(path: str | Path) -> list[tuple[str, dict[str, Any]]]:
    """:func:`parameter_table` of one file."""
    return parameter_table([path])


def _matches(key: str, fully_qualified_name: str) -> bool:
    """rclpy's test of a node key against ``/ns/name``: ``/*`` is one token, ``/**`` any."""
    absolute = key if key.startswith("/") else f"/{key}"
    return re.fullmatch(absolute.replace("/*", "(?:/[A-Za-z0-9_]+)"), fully_qualified_name) is not None


def node_entries(sources: Iterable[Source], fully_qualified_name: str
                 ) -> list[tuple[str, dict[str, Any]]]:
    """The entries of ``sources`` whose key matches the node ``/ns/name``, in rcl's order."""
    return [(key, values) for key, values in parameter_table(sources)
            if _matches(key, fully_qualified_name)]


def node_parameters(sources: Iterable[Source], fully_qualified_name: str) -> dict[str, Any]:
    """Parameters ``sources`` give the node ``/ns/name``: its matching entries, later over
    earlier, as rclpy applies them."""
    merged: dict[str, Any] = {}
    for _, values in node_entries(sources, fully_qualified_name):
        merged.update(values)
    return merged


class _RclDumper(yaml.SafeDumper):
    """YAML that rcl reads back to the same values: strings always quoted, subnormal doubles in
    hexadecimal (their decimal spelling is a range error to ``strtod``, hence a string)."""


def _quoted(dumper: yaml.SafeDumper, value: str) -> yaml.ScalarNode:
    return dumper.represent_scalar(_STR_TAG, value, style='"')


def _double(dumper: yaml.SafeDumper, value: float) -> yaml.ScalarNode:
    if value != 0.0 and math.isfinite(value) and abs(value) < sys.float_info.min:
        return yaml.ScalarNode(_STR_TAG, value.hex())  # plain: no tag, no quotes
    return dumper.represent_float(value)


def _mapping(dumper: yaml.SafeDumper, value: dict[str, Any]) -> yaml.MappingNode:
    """Keys plain where YAML allows (rcl takes a key's text whatever its style)."""
    pairs = [(yaml.ScalarNode(_STR_TAG, str(key)), dumper.represent_data(item))
             for key, item in value.items()]
    return yaml.MappingNode("tag:yaml.org,2002:map", pairs)


_RclDumper.add_representer(str, _quoted)
_RclDumper.add_representer(float, _double)
_RclDumper.add_representer(dict, _mapping)


def param_file_text(values_by_node: Mapping[str, Mapping[str, Any]]) -> str:
    """A parameter file giving each node (``/ns/name`` key) its values, read back by rcl and by
    :func:`node_parameters` to the same values. ``InputError`` for a value rcl cannot hold
    (``None``, an empty or mixed list, a nested collection)."""
    for node, values in values_by_node.items():
        for name, value in values.items():
            items = value if isinstance(value, list) else [value]
            if (not items or any(item is None or isinstance(item, list | dict) for item in items)
                    or len({_kind(item) for item in items}) > 1):
                raise InputError(f"{node}: parameter {name} = {value!r} cannot be written as an "
                                 "rcl parameter", parameter=name, value=repr(value),
                                 allowed="a bool, integer, double or string, or a non-empty "
                                         "list of one of them")
    document = {node: {ROS_PARAMETERS: dict(values)} for node, values in values_by_node.items()}
    return str(yaml.dump(document, Dumper=_RclDumper, sort_keys=False, default_flow_style=None,
                         allow_unicode=True, width=1 << 16))


#: ROS arguments that take the next argument as their value (rcl's ``arguments.c``)
_VALUED_FLAGS = frozenset({"-p", "--param", "--params-file", "-r", "--remap", "-e", "--enclave",
                           "--log-level", "--log-config-file"})


def ros_arguments(args: Sequence[str]) -> list[tuple[str, str | None]]:
    """``(flag, value or None)`` of each ROS argument in ``args``: those between ``--ros-args``
    and ``--`` (or the end), as rcl reads them."""
    found: list[tuple[str, str | None]] = []
    inside, i = False, 0
    while i < len(args):
        arg = args[i]
        if arg == "--ros-args":
            inside = True
        elif arg == "--":
            inside = False
        elif inside:
            if arg in _VALUED_FLAGS:
                if i + 1 >= len(args):
                    raise InputError(f"ROS argument {arg} has no value", parameter="--ros-args",
                                     value=" ".join(args), allowed=f"{arg} VALUE")
                found.append((arg, args[i + 1]))
                i += 1
            else:
                found.append((arg, None))
        i += 1
    return found


def sources_in_order(files: Sequence[str | Path], args: Sequence[str]) -> list[Source]:
    """``files``, then each ``--params-file FILE`` and ``-p``/``--param ITEM`` among the ROS
    arguments of ``args``, in the order written (the order rcl merges them in)."""
    found: list[Source] = [*files]
    for flag, value in ros_arguments(args):
        if flag == "--params-file" and value is not None:
            found.append(value)
        elif flag in ("-p", "--param") and value is not None:
            found.append(CliParam(value))
    return found
