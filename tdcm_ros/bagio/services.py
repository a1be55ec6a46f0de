"""Service types in the one message model: ``pkg/srv/Name`` as rosidl generates it.

rosbags' Jazzy store holds messages only. A service adds four types: ``Name_Request`` and
``Name_Response`` (the two halves of the ``.srv``; an empty half gets rosidl's
``uint8 structure_needs_at_least_one_member``), ``Name_Event`` (``service_msgs/msg/ServiceEventInfo
info``, at most one request and one response) and ``Name`` (the three as ``request_message``,
``response_message``, ``event_message``). The RIHS01 hash of ``Name`` (REP 2011) is the one rmw
implementations put in a service's key; :func:`tdcm_ros.bagio.typestore.service_type_hash`
computes it.
"""

from __future__ import annotations

from typing import Any

from rosbags.typesys import get_types_from_msg
from rosbags.typesys.base import Nodetype

from tdcm_ros.bagio.errors import BagError

#: ``.srv`` text (request ``---`` response) of every service type the package serves or calls.
SERVICE_DEFINITIONS: dict[str, str] = {
    "std_srvs/srv/Trigger": "---\n"
                            "bool success    # the command was carried out\n"
                            "string message  # why not, or what was done\n",
    # The six parameter services every ROS node serves (rcl_interfaces, Jazzy), comments cut.
    "rcl_interfaces/srv/DescribeParameters": "string[] names\n---\n"
                                             "ParameterDescriptor[] descriptors\n",
    "rcl_interfaces/srv/GetParameterTypes": "string[] names\n---\nuint8[] types\n",
    "rcl_interfaces/srv/GetParameters": "string[] names\n---\nParameterValue[] values\n",
    "rcl_interfaces/srv/ListParameters": "uint64 DEPTH_RECURSIVE=0\nstring[] prefixes\n"
                                         "uint64 depth\n---\nListParametersResult result\n",
    "rcl_interfaces/srv/SetParameters": "Parameter[] parameters\n---\n"
                                        "SetParametersResult[] results\n",
    "rcl_interfaces/srv/SetParametersAtomically": "Parameter[] parameters\n---\n"
                                                  "SetParametersResult result\n",
    # The services of a managed (lifecycle) node (lifecycle_msgs, Jazzy), comments cut.
    "lifecycle_msgs/srv/ChangeState": "Transition transition\n---\nbool success\n",
    "lifecycle_msgs/srv/GetState": "---\nState current_state\n",
    "lifecycle_msgs/srv/GetAvailableStates": "---\nState[] available_states\n",
    "lifecycle_msgs/srv/GetAvailableTransitions": "---\n"
                                                  "TransitionDescription[] available_transitions\n",
}
EVENT_INFO = "service_msgs/msg/ServiceEventInfo"
_PLACEHOLDER = ("structure_needs_at_least_one_member", (Nodetype.BASE, ("uint8", 0)))


def normalize_service_type(type_name: str) -> str:
    """Accept ``pkg/srv/Name`` or ``pkg/Name`` of a known service; return ``pkg/srv/Name``."""
    parts = type_name.strip().split("/")
    name = "/".join([parts[0], "srv", parts[1]] if len(parts) == 2 else parts)
    if name not in SERVICE_DEFINITIONS:
        raise BagError(f"unknown service type {type_name!r}; known: "
                       f"{', '.join(SERVICE_DEFINITIONS)}")
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
