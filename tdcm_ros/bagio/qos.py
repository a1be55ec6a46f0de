"""The QoS a bag records for a topic (rosbag2 ``offered_qos_profiles``), as one keep-last profile.

rosbag2 stores, per topic, the QoS each recorded publisher offered: in MCAP channel metadata and
``metadata.yaml`` as YAML (version 9: names such as ``reliable``; older versions: the rmw enum
numbers, reliability 1 = reliable, 2 = best effort; durability 1 = transient local, 2 = volatile),
and through rosbags (sqlite3 storage) as ``Qos`` tuples. :func:`recorded_qos` folds them into the
profile a player offers, as ``ros2 bag play`` adapts it: reliable only if every publisher was,
transient local only if every publisher was, the largest depth; no profile: the defaults.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import yaml

from tdcm_ros.bagio.writer import OfferedQos
from tdcm_ros.yamlio import load_yaml

_RELIABILITY = {"reliable": "reliable", "1": "reliable", "best_effort": "best_effort",
                "2": "best_effort"}
_DURABILITY = {"transient_local": "transient_local", "1": "transient_local",
               "volatile": "volatile", "2": "volatile"}


def _policy(value: Any) -> str:
    """A policy value as a lower-case name or enum number (``Qos`` enums give their name)."""
    name = getattr(value, "name", value)
    return str(name).strip().lower()


def _field(profile: Any, name: str) -> Any:
    return profile.get(name) if isinstance(profile, dict) else getattr(profile, name, None)


def parse_profiles(value: Any) -> list[Any]:
    """The profiles of one topic from YAML text (MCAP metadata, old ``metadata.yaml``) or a
    list (``metadata.yaml`` version 9, rosbags); unreadable text gives no profile."""
    if isinstance(value, str):
        try:
            value = load_yaml(value, "offered_qos_profiles") if value.strip() else []
        except yaml.YAMLError:
            return []
    return list(value) if isinstance(value, list | tuple) else []


def recorded_qos(profiles: Iterable[Any]) -> OfferedQos:
    """One keep-last profile for the publishers of ``profiles`` (see the module docstring)."""
    found = list(profiles)
    if not found:
        return OfferedQos()
    reliabilities = [_RELIABILITY.get(_policy(_field(p, "reliability")), "reliable") for p in found]
    durabilities = [_DURABILITY.get(_policy(_field(p, "durability")), "volatile") for p in found]
    depths = [int(d) for p in found if isinstance(d := _field(p, "depth"), int | float) and d > 0]
    return OfferedQos(
        depth=max(depths, default=OfferedQos.depth),
        reliability="reliable" if all(r == "reliable" for r in reliabilities) else "best_effort",
        durability=("transient_local" if all(d == "transient_local" for d in durabilities)
                    else "volatile"))
