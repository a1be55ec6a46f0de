"""How the recorder finds publishers: one small strategy per runtime.

A strategy calls ``on_offer(topic, type, qos)`` on the recorder's spinning thread for every
(topic, type) that some publisher offers, including publishers that appear later; the recorder
ignores repeats. zenoh: rmw_zenoh liveliness tokens (offered depth included). rclpy: the node's
graph, polled every :data:`POLL_PERIOD_S` s (DDS discovery does not carry the history depth, so
the offered depth is the writer's default, :class:`OfferedQos` ``depth``).

``any_type`` tells whether the runtime can subscribe to a topic without naming its type (zenoh:
``<domain>/<topic>/*/*``); the recorder then subscribes to each named topic at the start.

zenoh and rclpy are imported inside the strategies only.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from typing import Any, Protocol

from tdcm_ros.bagio.writer import OfferedQos
from tdcm_ros.errors import InputError
from tdcm_ros.runtime import RuntimePortError, wire

#: Period (s) of the rclpy graph poll.
POLL_PERIOD_S = 0.1
_RELIABILITY = {"": "reliable", "1": "reliable", "2": "best_effort"}
_DURABILITY = {"": "volatile", "2": "volatile", "1": "transient_local"}

#: ``on_offer(topic, type_name, offered_qos)``.
OnOffer = Callable[[str, str, OfferedQos], None]


class Discovery(Protocol):
    """Publisher discovery of one runtime."""

    #: True when a topic can be subscribed before its type is known.
    any_type: bool

    def close(self) -> None:
        """Stop discovering (no ``on_offer`` call after this returns)."""

    def finish(self, drain_s: float) -> None:
        """Close the context after delivering the samples already received (for up to
        ``drain_s`` s)."""


def offered_qos(chunk: str) -> OfferedQos:
    """The publisher's QoS from the QoS chunk of its rmw_zenoh token (unknown parts: defaults)."""
    parts = chunk.split(":")
    reliability = _RELIABILITY.get(parts[0], "reliable") if parts else "reliable"
    durability = _DURABILITY.get(parts[1], "volatile") if len(parts) > 1 else "volatile"
    depth_text = parts[2].partition(",")[2] if len(parts) > 2 else ""
    depth = int(depth_text) if depth_text.isdigit() else wire.RMW_ZENOH_DEFAULT_DEPTH
    return OfferedQos(depth=max(1, depth), reliability=reliability, durability=durability)


class ZenohDiscovery:
    """Publishers from rmw_zenoh liveliness tokens (with history: the ones already there)."""

    any_type = True

    def __init__(self, context: Any, port: Any, wanted: Collection[str],
                 on_offer: OnOffer) -> None:
        self._context = context
        self._wanted = wanted
        self._on_offer = on_offer
        self._tokens = context.session.liveliness().declare_subscriber(
            f"{wire.ADMIN_SPACE}/{context.domain_id}/**", self._on_token, history=True)

    def _on_token(self, sample: Any) -> None:
        """Zenoh thread: a token appeared; publishers are handed to the executor."""
        import zenoh

        if sample.kind != zenoh.SampleKind.PUT:
            return
        try:
            token = wire.parse_token(str(sample.key_expr))
        except (RuntimePortError, ValueError):
            return
        if token.kind == wire.PUBLISHER and (not self._wanted or token.topic in self._wanted):
            self._context.executor.post(lambda: self._on_offer(
                token.topic, token.type_name, offered_qos(token.qos)))

    def close(self) -> None:
        """Undeclare the token subscriber."""
        self._tokens.undeclare()

    def finish(self, drain_s: float) -> None:
        """Close the session first (nothing new is queued), then run the queued callbacks."""
        self._context.close()
        self._context.spin_for(drain_s)


def rclpy_offered_qos(profiles: list[Any]) -> OfferedQos:
    """What a subscription can match of every publisher's rclpy ``QoSProfile``: reliable only
    if all are, transient-local only if all are (DDS refuses a stronger request); default depth."""
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

    reliable = all(p.reliability == ReliabilityPolicy.RELIABLE for p in profiles)
    latched = all(p.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in profiles)
    return OfferedQos(reliability="reliable" if reliable else "best_effort",
                      durability="transient_local" if latched else "volatile")


class RclpyGraphDiscovery:
    """Publishers from the rclpy node's graph, polled every :data:`POLL_PERIOD_S` s."""

    any_type = False

    def __init__(self, context: Any, port: Any, wanted: Collection[str],
                 on_offer: OnOffer) -> None:
        self._context = context
        self._node = port.node
        self._wanted = wanted
        self._on_offer = on_offer
        self._offered: set[tuple[str, str]] = set()
        self._timer = port.create_timer(POLL_PERIOD_S, self.poll)

    def poll(self) -> None:
        """Offer every (topic, type) with a publisher that was not offered before."""
        for topic, types in self._node.get_topic_names_and_types():
            if self._wanted and topic not in self._wanted:
                continue
            for type_name in types:
                if (topic, type_name) not in self._offered:
                    self._offer(topic, type_name)

    def _offer(self, topic: str, type_name: str) -> None:
        profiles = [info.qos_profile for info in self._node.get_publishers_info_by_topic(topic)
                    if info.topic_type == type_name]
        if profiles:  # a topic with subscribers only is offered once a publisher appears
            self._offered.add((topic, type_name))
            self._on_offer(topic, type_name, rclpy_offered_qos(profiles))

    def close(self) -> None:
        """Cancel the poll timer."""
        self._timer.cancel()

    def finish(self, drain_s: float) -> None:
        """Run the callbacks of what the readers hold for ``drain_s`` s, then close the context
        (closing first would drop the readers' caches)."""
        self._context.spin_for(drain_s)
        self._context.close()


#: Discovery strategy per runtime name.
DISCOVERIES: dict[str, Callable[[Any, Any, Collection[str], OnOffer], Discovery]] = {
    "zenoh": ZenohDiscovery, "rclpy": RclpyGraphDiscovery}


def check_runtime(runtime: str) -> str:
    """``runtime`` if a discovery strategy exists for it; ``InputError`` otherwise."""
    if runtime not in DISCOVERIES:
        raise InputError(f"runtime = {runtime!r} is not recordable; allowed: "
                         f"{', '.join(DISCOVERIES)}", parameter="runtime", value=runtime,
                         allowed=", ".join(DISCOVERIES))
    return runtime
