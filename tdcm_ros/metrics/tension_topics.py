"""Where a body's tendon tensions are in a bag: the ``--tension-topic`` values, checked against
the tendon names of the body file.

Two layouts:

- one topic (``TOPIC``, default ``tension``): a ``sensor_msgs/msg/JointState`` with one effort
  (N) per tendon, by tendon name, as model_node takes it; or, for a body with one tendon, a
  ``geometry_msgs/msg/WrenchStamped`` (``force.z``) or ``std_msgs/msg/Float64``;
- one topic per tendon (``NAME=TOPIC`` for every tendon ``NAME`` of the body file), each a
  WrenchStamped or Float64: the samples are put on the stamps of the first tendon's topic
  (:func:`~tdcm_ros.metrics.align.on_first_stamps`, within ``align.tolerance_s``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from tdcm_ros.metrics.errors import TensionTopicError

OPTION = "--tension-topic"
#: What ``--tension-topic`` takes, for the errors.
ALLOWED = "one TOPIC, or NAME=TOPIC once for each tendon NAME of the body file"


@dataclass(frozen=True)
class TensionTopics:
    """The tendons' names (the body file's order) and either the one ``shared`` topic or
    ``per_tendon``, each tendon's own topic in that order (then ``shared`` is None)."""

    tendons: tuple[str, ...]
    shared: str | None = "tension"
    per_tendon: tuple[str, ...] = ()


def tension_topics(given: str | Sequence[str], tendons: Sequence[str]) -> TensionTopics:
    """The layout of ``given`` (one ``TOPIC`` or ``NAME=TOPIC`` values) for the body whose tendons
    are ``tendons``; raises :class:`TensionTopicError` naming the value and what is allowed."""
    values = [given] if isinstance(given, str) else list(given)
    names = tuple(tendons)
    listed = ", ".join(names)
    pairs = [value.partition("=") for value in values]
    if not any(sep for _, sep, _ in pairs):
        if len(values) != 1 or not values[0]:
            raise TensionTopicError(f"{OPTION} {' '.join(values) or '(empty)'}: several topics "
                                    f"or none without NAME=; allowed: {ALLOWED} ({listed})",
                                    parameter=OPTION, value=values, allowed=ALLOWED)
        return TensionTopics(names, values[0])
    topics: dict[str, str] = {}
    for value, (name, sep, topic) in zip(values, pairs, strict=True):
        if not (sep and name and topic):
            what = "has an empty NAME or TOPIC" if sep else "is a plain TOPIC among NAME=TOPIC"
            raise TensionTopicError(f"{OPTION} {value!r} {what}; allowed: {ALLOWED} ({listed})",
                                    parameter=OPTION, value=value, allowed=ALLOWED)
        if name not in names:
            raise TensionTopicError(f"{OPTION} {value!r}: {name!r} is not a tendon of the body; "
                                    f"allowed: its tendon names {listed}", parameter=OPTION,
                                    value=name, allowed=listed)
        if name in topics:
            raise TensionTopicError(f"{OPTION} {value!r}: tendon {name} is given a topic twice "
                                    f"({topics[name]} and {topic}); allowed: one topic per tendon",
                                    parameter=OPTION, value=value, allowed="one topic per tendon")
        topics[name] = topic
    if missing := [name for name in names if name not in topics]:
        raise TensionTopicError(f"{OPTION}: no topic for tendon(s) {', '.join(missing)} of the "
                                f"body; allowed: NAME=TOPIC for every tendon ({listed})",
                                parameter=OPTION, value=missing, allowed=listed)
    if len(set(topics.values())) < len(topics):
        raise TensionTopicError(f"{OPTION}: one topic for several tendons ({', '.join(values)});"
                                " allowed: a topic per tendon (one topic for all: a JointState, "
                                "given once as TOPIC)", parameter=OPTION, value=values,
                                allowed="distinct topics")
    return TensionTopics(names, None, tuple(topics[name] for name in names))
