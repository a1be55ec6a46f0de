"""Plain-data views of rosbags messages: build from a (YAML) dict, dump to a dict.

Missing fields take ROS defaults (0, ``""``, ``False``, empty sequences, zero arrays).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from rosbags.typesys.base import Nodetype

from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.typestore import (
    deserialize,
    normalize_type_name,
    serialize,
    typestore,
)

_NUMPY_TYPES: dict[str, type] = {
    "bool": np.bool_, "byte": np.uint8, "char": np.uint8, "int8": np.int8, "uint8": np.uint8,
    "int16": np.int16, "uint16": np.uint16, "int32": np.int32, "uint32": np.uint32,
    "int64": np.int64, "uint64": np.uint64, "float32": np.float32, "float64": np.float64,
}


def _base_value(base: str, value: Any, where: str) -> Any:
    try:
        if base in ("string", "wstring"):
            return "" if value is None else str(value)
        if base == "bool":
            return bool(value) if value is not None else False
        if base in ("float32", "float64"):
            return float(value) if value is not None else 0.0
        return int(value) if value is not None else 0
    except (TypeError, ValueError) as error:
        raise BagError(f"{where}: {value!r} is not a valid {base}") from error


def _field(desc: tuple[Any, Any], value: Any, where: str) -> Any:
    kind, rest = desc
    if kind == Nodetype.BASE:
        return _base_value(rest[0], value, where)
    if kind == Nodetype.NAME:
        return from_dict(rest, value if value is not None else {}, where=where)
    sub, length = rest
    items = [] if value is None else list(value)
    if kind == Nodetype.ARRAY and value is None:
        items = [None] * length
    if kind == Nodetype.ARRAY and len(items) != length:
        raise BagError(f"{where}: expected {length} items, got {len(items)}")
    if sub[0] == Nodetype.BASE and sub[1][0] in _NUMPY_TYPES:
        dtype = _NUMPY_TYPES[sub[1][0]]
        return np.array([_base_value(sub[1][0], v, where) for v in items], dtype=dtype)
    return [_field(sub, v, f"{where}[{i}]") for i, v in enumerate(items)]


def from_dict(type_name: str, data: Mapping[str, Any] | None = None, *, where: str = "") -> Any:
    """A rosbags message of ``type_name`` with the fields given in ``data``, defaults elsewhere."""
    name = normalize_type_name(type_name)
    if data is not None and not isinstance(data, Mapping):
        raise BagError(f"{where or name}: expected a mapping of fields, got {data!r}")
    data = dict(data or {})
    fields = typestore().fielddefs[name][1]
    known = {f for f, _ in fields}
    unknown = sorted(set(data) - known)
    if unknown:
        raise BagError(f"{where or name}: unknown field(s) {unknown}; {name} has {sorted(known)}")
    values = {f: _field(desc, data.get(f), f"{where}.{f}" if where else f) for f, desc in fields}
    return typestore().types[name](**values)


def to_dict(message: Any) -> Any:
    """Nested dicts/lists/scalars of a rosbags message (numpy arrays become lists)."""
    if hasattr(message, "__msgtype__"):
        names = [f for f, _ in typestore().fielddefs[message.__msgtype__][1]]
        return {f: to_dict(getattr(message, f)) for f in names}
    if isinstance(message, np.ndarray):
        return message.tolist()
    if isinstance(message, list | tuple):
        return [to_dict(v) for v in message]
    if isinstance(message, np.generic):
        return message.item()
    return message


def prepare_codec(type_name: str) -> None:
    """Build ``type_name``'s CDR serialiser and deserialiser now: rosbags generates them on first
    use (about 20 ms a type here, many times more on a loaded machine), which a node's callback
    thread must not pay while it has a device to keep alive."""
    deserialize(serialize(from_dict(type_name, {}), type_name), type_name)
