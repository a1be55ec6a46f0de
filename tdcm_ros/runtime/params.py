"""Reader of ROS 2 parameter YAML (``ros__parameters`` layout), shared by both runtimes.

Node keys may be fully qualified (``/ns/node``), relative (``node`` = ``/node``), nested
namespace mappings, or wildcards (``/**`` any namespace depth, ``*`` one token). Wildcard entries
apply first, exact ones override them. Nested mappings under ``ros__parameters`` flatten to
dotted names (``solver.tol``).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.yamlio import load_yaml

ROS_PARAMETERS = "ros__parameters"


def _flatten(values: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in values.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(_flatten(value, f"{name}."))
        else:
            flat[name] = value
    return flat


def _entries(tree: dict[str, Any], path: str, where: Path) -> list[tuple[str, dict[str, Any]]]:
    found: list[tuple[str, dict[str, Any]]] = []
    for key, value in tree.items():
        if key == ROS_PARAMETERS:
            if not isinstance(value, dict):
                raise InputError(f"{where}: {path}/{ROS_PARAMETERS} must be a mapping",
                                 parameter="params_file", value=str(where))
            found.append((path or "/", _flatten(value)))
        elif isinstance(value, dict):
            found.extend(_entries(value, f"{path}/{str(key).strip('/')}", where))
        else:
            raise InputError(f"{where}: {path}/{key} is not under {ROS_PARAMETERS}",
                             parameter="params_file", value=str(where))
    return found


def _pattern(key: str) -> re.Pattern[str]:
    parts = []
    for token in key.strip("/").split("/"):
        parts.append("(/[^/]+)*" if token == "**" else "/" + re.escape(token).replace(r"\*", "[^/]*"))
    return re.compile("^" + "".join(parts) + "$")


def read_param_file(path: str | Path) -> list[tuple[str, dict[str, Any]]]:
    """``(node key, {parameter: value})`` entries of a parameter file, in file order; the
    YAML is bounded (:mod:`tdcm_ros.yamlio`), any problem an :class:`InputError`."""
    where = Path(path)
    try:
        text = where.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"cannot read parameter file {where}: {error}",
                         parameter="params_file", value=str(where)) from error
    tree = load_yaml(text, str(where), parameter="params_file") or {}
    if not isinstance(tree, dict):
        raise InputError(f"{where}: top level must map node names to {ROS_PARAMETERS}",
                         parameter="params_file", value=str(where))
    return _entries(tree, "", where)


def node_entries(path: str | Path | None, fully_qualified_name: str
                 ) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(wildcard, exact)``: the parameters a file gives the node ``/ns/name`` by entries
    whose key matches it with a wildcard (``/**``), and by entries that name it."""
    wildcard: dict[str, Any] = {}
    exact: dict[str, Any] = {}
    if path is None:
        return wildcard, exact
    for key, values in read_param_file(path):
        if "*" in key and _pattern(key).match(fully_qualified_name):
            wildcard.update(values)
        elif "/" + key.strip("/") == fully_qualified_name:
            exact.update(values)
    return wildcard, exact


def node_parameters(path: str | Path | None, fully_qualified_name: str) -> dict[str, Any]:
    """Parameters a file gives the node ``/ns/name``: wildcard entries, then exact ones."""
    wildcard, exact = node_entries(path, fully_qualified_name)
    return {**wildcard, **exact}


def parse_cli_param(item: str) -> tuple[str, str, Any]:
    """``[NODE:]NAME:=VALUE`` (ros2's ``-p`` spelling) as ``(node or "", name, value)``; the
    value is read as YAML. ``InputError`` naming the item if it is not of that form."""
    target, sep, text = item.partition(":=")
    node, _, name = target.rpartition(":")
    if not sep or not name:
        raise InputError(f"-p {item!r} is not [NODE:]NAME:=VALUE", parameter="-p", value=item,
                         allowed="[NODE:]NAME:=VALUE, e.g. model_node:input.max_age_s:=2.0")
    return node, name, load_yaml(text, f"-p {target}")
