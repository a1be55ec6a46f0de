"""ROS 2 name rules: validation and resolution of node names, namespaces and topic names.

Follows https://design.ros2.org/articles/topic_and_service_names.html (no remapping); and the
prefix of a robot's TF frame ids.
"""

from __future__ import annotations

import re

from tdcm_ros.errors import InputError

_TOKEN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_TOPIC_TOKEN = re.compile(r"^[A-Za-z0-9_]+$")


def validate_node_name(name: str) -> str:
    """Return ``name`` if it is a valid node name (``[A-Za-z_][A-Za-z0-9_]*``)."""
    if not _TOKEN.match(name):
        raise InputError(f"node name {name!r} is invalid; allowed: [A-Za-z_][A-Za-z0-9_]*",
                         parameter="node_name", value=name, allowed="[A-Za-z_][A-Za-z0-9_]*")
    return name


#: What a ``frame_prefix`` may be (tf2 frame ids have no leading ``/``).
FRAME_PREFIX_ALLOWED = "'' or a tf2 frame-id start: no leading '/', no white space"


def validate_frame_prefix(prefix: str, parameter: str = "frame_prefix") -> str:
    """Return ``prefix`` if it can start tf2 frame ids (robot_state_publisher's
    ``frame_prefix``, e.g. ``robot1/``); else an InputError naming ``parameter``."""
    if prefix.startswith("/") or any(c.isspace() for c in prefix):
        raise InputError(f"{parameter} = {prefix!r} is not a frame prefix; allowed: "
                         f"{FRAME_PREFIX_ALLOWED}", parameter=parameter, value=prefix,
                         allowed=FRAME_PREFIX_ALLOWED)
    return prefix


def normalize_namespace(namespace: str) -> str:
    """Absolute namespace without trailing slash (``""``/``"/"`` -> ``"/"``; ``"a"`` -> ``"/a"``)."""
    ns = "/" + namespace.strip("/")
    if ns != "/" and not all(_TOKEN.match(t) for t in ns[1:].split("/")):
        raise InputError(f"namespace {namespace!r} is invalid", parameter="namespace",
                         value=namespace, allowed="/-separated tokens [A-Za-z_][A-Za-z0-9_]*")
    return ns


def fully_qualified_node_name(namespace: str, name: str) -> str:
    """``/ns/name`` of a node."""
    ns = normalize_namespace(namespace)
    return f"{ns.rstrip('/')}/{validate_node_name(name)}"


def resolve_topic(topic: str, namespace: str = "/", node_name: str | None = None) -> str:
    """Fully qualified topic name: absolute kept, ``~`` = the node's name, else under namespace."""
    ns = normalize_namespace(namespace)
    if topic.startswith("~"):
        if node_name is None:
            raise InputError(f"topic {topic!r} uses '~' but no node name is known",
                             parameter="topic", value=topic, allowed="a name without '~'")
        base = fully_qualified_node_name(ns, node_name)
        resolved = base + topic[1:] if topic != "~" else base
    elif topic.startswith("/"):
        resolved = topic
    else:
        resolved = f"{ns.rstrip('/')}/{topic}"
    tokens = resolved[1:].split("/") if resolved != "/" else [""]
    if resolved.endswith("/") or not all(_TOPIC_TOKEN.match(t) and not t[0].isdigit()
                                         for t in tokens):
        raise InputError(f"topic name {topic!r} resolves to invalid {resolved!r}",
                         parameter="topic", value=topic,
                         allowed="/-separated tokens of [A-Za-z0-9_] not starting with a digit")
    return resolved
