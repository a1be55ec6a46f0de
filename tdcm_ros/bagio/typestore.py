"""The one message model: the ``rosbags`` Jazzy typestore plus the ``.msg`` files of ``msg_defs/``
and the service types of :mod:`tdcm_ros.bagio.services`.

Every carrier (bags, the zenoh runtime, the rclpy adapter) moves the CDR bytes produced here.
``msg_defs`` is searched, in order, in the directories of ``TDCM_MSG_DEFS`` (``os.pathsep``
separated), the source checkout (``<repo>/msg_defs``) and ``<prefix>/share/tdcm_ros/msg_defs``;
each holds ``<pkg>/msg/<Name>.msg``.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import Nodetype
from rosbags.typesys.store import Typestore

from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.services import all_service_types, normalize_service_type
from tdcm_ros.resources import resource_dirs

STORE = Stores.ROS2_JAZZY
MSG_DEFS_ENV = "TDCM_MSG_DEFS"


def msg_defs_dirs() -> list[Path]:
    """Existing ``msg_defs`` directories, in search order."""
    return resource_dirs("msg_defs", MSG_DEFS_ENV)


def _msg_files() -> dict[str, Path]:
    """Type name -> ``.msg`` file; the first directory that defines a type wins."""
    found: dict[str, Path] = {}
    for root in msg_defs_dirs():
        for path in sorted(root.glob("*/msg/*.msg")):
            found.setdefault(f"{path.parent.parent.name}/msg/{path.stem}", path)
    return found


@cache
def typestore() -> Typestore:
    """The process-wide typestore: Jazzy plus every ``msg_defs`` type, built once."""
    store = get_typestore(STORE)
    types: dict[str, Any] = {}
    for name, path in _msg_files().items():
        try:
            types.update(get_types_from_msg(path.read_text(encoding="utf-8"), name))
        except Exception as error:  # rosbags raises several parser error types
            raise BagError(f"cannot parse message definition {path}: {error}") from error
    types.update(all_service_types())
    store.register(types)
    return store


def _check(type_name: str) -> str:
    if type_name not in typestore().types:
        raise BagError(f"unknown message type {type_name!r}; expected 'pkg/msg/Name' from the "
                       f"Jazzy typestore or msg_defs/")
    return type_name


def normalize_type_name(type_name: str) -> str:
    """Accept ``pkg/msg/Name`` or ``pkg/Name``; return the canonical ``pkg/msg/Name``."""
    parts = type_name.strip().split("/")
    if len(parts) == 2:
        parts = [parts[0], "msg", parts[1]]
    return _check("/".join(parts))


def msg_class(type_name: str) -> type:
    """The rosbags message class of ``type_name``."""
    return typestore().types[normalize_type_name(type_name)]


def type_name_of(message: Any) -> str:
    """The ``pkg/msg/Name`` of a rosbags message object."""
    return _check(str(message.__msgtype__))


def serialize(message: Any, type_name: str | None = None) -> bytes:
    """CDR bytes (little endian, with the 4-byte encapsulation header) of ``message``."""
    name = normalize_type_name(type_name) if type_name else type_name_of(message)
    try:
        return bytes(typestore().serialize_cdr(message, name))
    except Exception as error:  # rosbags raises struct/attribute/serde errors
        raise BagError(f"cannot serialise {type(message).__name__} as {name}: {error}") from error


def deserialize(data: bytes | memoryview, type_name: str, *, exact: bool = True) -> Any:
    """The rosbags message decoded from CDR ``data`` of type ``type_name``.

    ``exact=False`` ignores bytes after the message: rclpy's ``serialize_message`` on
    rmw_fastrtps returns a buffer padded past the message with uninitialised bytes.
    """
    name = normalize_type_name(type_name)
    try:
        if exact or len(data) < 4:
            return typestore().deserialize_cdr(data, name)
        msgdef = typestore().get_msgdef(name)
        decode = msgdef.deserialize_cdr_le if data[1] else msgdef.deserialize_cdr_be
        return decode(data[4:], 0, msgdef.cls, typestore())[0]
    except Exception as error:  # truncated or mistyped payloads raise several error types
        raise BagError(f"cannot deserialise {len(data)} bytes as {name}: {error}") from error


def type_hash(type_name: str) -> str:
    """The REP-2016 type hash, ``RIHS01_<64 hex digits>``."""
    return typestore().hash_rihs01(normalize_type_name(type_name))


def message_definition(type_name: str) -> str:
    """The concatenated ``.msg`` definition text (as stored in bags) of ``type_name``."""
    return typestore().generate_msgdef(normalize_type_name(type_name))[0]


def _as_rosidl(desc: Any) -> Any:
    """A field description with ``char`` as rosidl maps it (``uint8``) for hashing."""
    kind, rest = desc
    if kind == Nodetype.BASE:
        return (kind, ("uint8", rest[1]) if rest[0] == "char" else rest)
    if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return (kind, (_as_rosidl(rest[0]), rest[1]))
    return desc


@cache
def service_type_hash(name: str) -> str:
    """RIHS01 hash of service type ``pkg/srv/Name``.

    Hashed in a store of its own: rosbags keeps ``char`` (in ``ServiceEventInfo.client_gid``)
    as its own type where rosidl's type description has ``uint8``, so the Jazzy store's hash of
    the event differs from ROS's.
    """
    name = normalize_service_type(name)
    source = typestore()
    store = get_typestore(Stores.EMPTY)
    pending, seen = [name], set()
    types = {}
    while pending:
        current = pending.pop()
        if current in seen:
            continue
        seen.add(current)
        consts, fields = source.fielddefs[current]
        types[current] = (consts, [(n, _as_rosidl(d)) for n, d in fields])
        for _, desc in fields:
            inner = desc[1][0] if desc[0] in (Nodetype.ARRAY, Nodetype.SEQUENCE) else desc
            if inner[0] == Nodetype.NAME:
                pending.append(inner[1])
    store.register(types)
    return str(store.hash_rihs01(name))
