"""Service types in the one message model: ``pkg/srv/Name`` as rosidl generates it.

rosbags' Jazzy store holds messages only. A service adds four types: ``Name_Request`` and
``Name_Response`` (the two halves of the ``.srv``; an empty half gets rosidl's
``uint8 structure_needs_at_least_one_member``), ``Name_Event`` (``service_msgs/msg/ServiceEventInfo
info``, at most one request and one response) and ``Name`` (the three as ``request_message``,
``response_message``, ``event_message``). The RIHS01 hash of ``Name`` (REP 2011) is the one rmw
implementations put in a service's key; :func:`service_type_hash` computes it.
"""

from __future__ import annotations

from functools import cache
from typing import Any

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import Nodetype

#: ``.srv`` text (request ``---`` response) of every service type the package serves or calls.
SERVICE_DEFINITIONS: dict[str, str] = {
    "std_srvs/srv/Trigger": "---\n"
                            "bool success    # the command was carried out\n"
                            "string message  # why not, or what was done\n",
}
EVENT_INFO = "service_msgs/msg/ServiceEventInfo"
_PLACEHOLDER = ("structure_needs_at_least_one_member", (Nodetype.BASE, ("uint8", 0)))


def normalize_service_type(type_name: str) -> str:
    """Accept ``pkg/srv/Name`` or ``pkg/Name`` of a known service; return ``pkg/srv/Name``."""
    from tdcm_ros.bagio.errors import BagError

    parts = type_name.strip().split("/")
    name = "/".join([parts[0], "srv", parts[1]] if len(parts) == 2 else parts)
    if name not in SERVICE_DEFINITIONS:
        raise BagError(f"unknown service type {type_name!r}; known: "
                       f"{', '.join(sorted(SERVICE_DEFINITIONS))}")
    return name


def _fields(text: str, name: str) -> tuple[list[Any], list[Any]]:
    """(constants, fields) of one ``.srv`` half, parsed as a message."""
    package, _, short = name.partition("/srv/")
    consts, fields = get_types_from_msg(text, f"{package}/msg/{short}")[f"{package}/msg/{short}"]
    return consts, fields or [_PLACEHOLDER]


def service_typesdict(name: str, text: str) -> dict[str, tuple[list[Any], list[Any]]]:
    """The four types of service ``name`` (``pkg/srv/Name``) from its ``.srv`` ``text``."""
    request_text, _, response_text = text.partition("\n---")
    if text.startswith("---"):
        request_text, response_text = "", text[3:]
    request, response, event = f"{name}_Request", f"{name}_Response", f"{name}_Event"
    return {
        request: _fields(request_text, request),
        response: _fields(response_text, response),
        event: ([], [("info", (Nodetype.NAME, EVENT_INFO)),
                     ("request", (Nodetype.SEQUENCE, ((Nodetype.NAME, request), 1))),
                     ("response", (Nodetype.SEQUENCE, ((Nodetype.NAME, response), 1)))]),
        name: ([], [("request_message", (Nodetype.NAME, request)),
                    ("response_message", (Nodetype.NAME, response)),
                    ("event_message", (Nodetype.NAME, event))]),
    }


def all_service_types() -> dict[str, tuple[list[Any], list[Any]]]:
    """The types of every service in :data:`SERVICE_DEFINITIONS`."""
    types: dict[str, tuple[list[Any], list[Any]]] = {}
    for name, text in SERVICE_DEFINITIONS.items():
        types.update(service_typesdict(name, text))
    return types


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
    from tdcm_ros.bagio.typestore import typestore

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
