"""Record topics of the embedded (zenoh) graph into a rosbag2 MCAP bag.

Publishers are discovered from rmw_zenoh liveliness tokens, including those that appear after
the start; each (topic, type) is subscribed once for raw CDR. Every message is written with its
receive time (``log_time``, ns since the epoch, taken when the callback runs) and the sender's
time and sequence number from the rmw_zenoh attachment (``publish_time``, ``sequence``).
The recorder owns its zenoh session (:class:`ZenohContext`, configured from the environment);
all callbacks, the chunk-flush timer and the writer run on the thread that calls :meth:`run`.

:meth:`Recorder.request_stop` is safe from signal handlers; :meth:`Recorder.close` stops the
intake, writes every message already received, and closes the bag.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import zenoh

from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.typestore import normalize_type_name
from tdcm_ros.bagio.writer import BagWriter, OfferedQos
from tdcm_ros.runtime import wire
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.names import resolve_topic
from tdcm_ros.runtime.port import QoS
from tdcm_ros.runtime.zenoh_runtime import RawSample, ZenohContext

NODE_NAME = "_tdcm_record"
QUEUE_DEPTH = 10_000  # messages a subscription buffers while the writer is busy
DRAIN_S = 0.3  # time given to samples already received when the recorder stops (s)
_RELIABILITY = {"": "reliable", "1": "reliable", "2": "best_effort"}
_DURABILITY = {"": "volatile", "2": "volatile", "1": "transient_local"}

logger = logging.getLogger("tdcm.record")


def offered_qos(chunk: str) -> OfferedQos:
    """The publisher's QoS from the QoS chunk of its rmw_zenoh token (unknown parts: defaults)."""
    parts = chunk.split(":")
    reliability = _RELIABILITY.get(parts[0], "reliable") if parts else "reliable"
    durability = _DURABILITY.get(parts[1], "volatile") if len(parts) > 1 else "volatile"
    depth_text = parts[2].partition(",")[2] if len(parts) > 2 else ""
    depth = int(depth_text) if depth_text.isdigit() else wire.RMW_ZENOH_DEFAULT_DEPTH
    return OfferedQos(depth=max(1, depth), reliability=reliability, durability=durability)


class Recorder:
    """Subscribes to ``topics`` (all when empty) of the zenoh graph and writes to ``writer``.

    ``max_messages`` > 0 stops the recording after that many messages; ``on_topic`` is called
    (on the spinning thread) with (topic, type) for each new subscription.
    """

    def __init__(self, writer: BagWriter, topics: Sequence[str] = (), *, max_messages: int = 0,
                 on_topic: Callable[[str, str], None] | None = None) -> None:
        if max_messages < 0:
            raise BagError(f"max_messages = {max_messages} is out of range; allowed: >= 0 "
                           f"(0: no limit)", parameter="max_messages", value=max_messages,
                           allowed=">= 0")
        self._writer = writer
        self._wanted = {resolve_topic(t) for t in topics}
        self._max = max_messages
        self._on_topic = on_topic
        self._stop = threading.Event()
        self._skipped: set[tuple[str, str]] = set()
        self.total = 0
        self._context = context = ZenohContext()
        self._port = context.create_port(NODE_NAME)
        self._port.create_timer(writer.flush_period_s, writer.poll)
        self._tokens = context.session.liveliness().declare_subscriber(
            f"{wire.ADMIN_SPACE}/{context.domain_id}/**", self._on_token, history=True)

    @property
    def topics(self) -> dict[str, str]:
        """Subscribed topic -> type."""
        return self._writer.topics

    @property
    def missing(self) -> list[str]:
        """Requested topics no publisher has offered yet."""
        return sorted(self._wanted - set(self._writer.topics))

    def _on_token(self, sample: Any) -> None:
        """Zenoh thread: a liveliness token appeared; publishers are handed to the executor."""
        if sample.kind != zenoh.SampleKind.PUT:
            return
        try:
            token = wire.parse_token(str(sample.key_expr))
        except (RuntimePortError, ValueError):
            return
        if token.kind == wire.PUBLISHER and (not self._wanted or token.topic in self._wanted):
            self._context.executor.post(lambda: self._subscribe(token))

    def _subscribe(self, token: wire.TokenInfo) -> None:
        topic, msgtype = token.topic, token.type_name
        known = self._writer.topics.get(topic)
        if known == msgtype or (topic, msgtype) in self._skipped or self._stop.is_set():
            return
        if known is not None:
            self._skip(topic, msgtype, f"the bag already records it as {known}")
            return
        try:
            msgtype = normalize_type_name(msgtype)
        except BagError as error:
            self._skip(topic, msgtype, str(error))
            return
        qos = offered_qos(token.qos)
        self._writer.add_topic(topic, msgtype, qos)
        self._port.create_raw_subscription(
            topic, msgtype, self._on_sample,
            QoS(depth=QUEUE_DEPTH, reliability="reliable", durability=qos.durability))  # type: ignore[arg-type]
        if self._on_topic is not None:
            self._on_topic(topic, msgtype)

    def _skip(self, topic: str, msgtype: str, why: str) -> None:
        self._skipped.add((topic, msgtype))
        logger.warning("not recording %s [%s]: %s", topic, msgtype, why)

    def _on_sample(self, sample: RawSample) -> None:
        if self._max and self.total >= self._max:
            return
        received = time.time_ns()
        attachment = sample.attachment
        self._writer.write(sample.topic, received, sample.data,
                           publish_time_ns=attachment.source_timestamp_ns if attachment else None,
                           sequence=attachment.sequence_number if attachment else 0)
        self.total += 1
        if self._max and self.total >= self._max:
            self.request_stop()

    def request_stop(self) -> None:
        """Make :meth:`run` return (safe from signal handlers and other threads)."""
        self._stop.set()

    @property
    def stopping(self) -> bool:
        """True once a stop was requested."""
        return self._stop.is_set()

    def run(self, duration_s: float = 0.0) -> None:
        """Record until :meth:`request_stop`, or for ``duration_s`` s when > 0."""
        end = time.monotonic() + duration_s if duration_s > 0 else float("inf")
        while not self._stop.is_set() and (left := end - time.monotonic()) > 0:
            self._context.spin_for(min(0.1, left))

    def close(self) -> None:
        """Stop the intake, write the messages already received, close the bag."""
        self._stop.set()
        self._tokens.undeclare()
        self._context.close()  # undeclares the subscriptions: nothing new is queued
        self._context.spin_for(DRAIN_S)  # deliver what was received before
        self._writer.close()
