"""Record topics of a live graph (embedded zenoh or rclpy) into a rosbag2 MCAP bag.

Publishers are discovered by the runtime's strategy (:mod:`tdcm_ros.recording.discovery`),
including those that appear after the start; each (topic, type) is subscribed once for raw CDR,
with the reliability and durability its publishers offer. Where the runtime can subscribe without
a type (zenoh), each named topic is instead subscribed for every type at the start, before any
publisher is known, so a publisher that starts later loses nothing: a (topic, type) enters the bag
when its publisher's token arrives (with the offered QoS); samples that come before the token are
held for it, at most :data:`HOLD_S` s, after which (or at the stop) the (topic, type) enters with
the default QoS (:class:`OfferedQos`) and they are written. Every message is written with its
receive time (``log_time``, ns since the epoch, taken when the callback runs) and, when the
runtime gives them, the sender's time and sequence number (``publish_time``, ``sequence``).
The recorder owns its context (``open_context(runtime)``, configured from the environment); all
callbacks, the chunk-flush timer and the writer run on the thread that calls :meth:`run`.
A (topic, type) that cannot be subscribed (e.g. no rclpy message class) is logged and skipped.

:meth:`Recorder.request_stop` is safe from signal handlers; :meth:`Recorder.close` stops the
intake, writes every message already received, and closes the bag.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence

from tdcm_ros.bagio import BagError, normalize_type_name
from tdcm_ros.bagio.writer import BagWriter, OfferedQos
from tdcm_ros.recording.discovery import DISCOVERIES, check_runtime
from tdcm_ros.runtime import QoS, RuntimePortError, resolve_topic
from tdcm_ros.runtime.wire import RawSample

NODE_NAME = "_tdcm_record"
QUEUE_DEPTH = 10_000  # messages a subscription buffers while the writer is busy
# a named topic's any-type subscription: transient-local fetches the caches of transient-local
# publishers and also takes every live sample (zenoh)
ANY_TYPE_QOS = QoS(depth=QUEUE_DEPTH, durability="transient_local")
DRAIN_S = 0.3  # time given to samples already received when the recorder stops (s)
HOLD_S = 0.5  # longest a named topic's sample waits for its publisher's token (s)

logger = logging.getLogger("tdcm.record")


class Recorder:
    """Subscribes to ``topics`` (all when empty) of the ``runtime`` graph and writes to ``writer``.

    ``runtime`` is ``zenoh`` or ``rclpy``. ``max_messages`` > 0 stops the recording after that
    many messages; ``on_topic`` is called (on the spinning thread) with (topic, type) for each
    topic added to the bag.
    """

    def __init__(self, writer: BagWriter, topics: Sequence[str] = (), *, runtime: str = "zenoh",
                 max_messages: int = 0,
                 on_topic: Callable[[str, str], None] | None = None) -> None:
        from tdcm_ros.runtime.run_node import open_context

        if max_messages < 0:
            raise BagError(f"max_messages = {max_messages} is out of range; allowed: >= 0 "
                           f"(0: no limit)", parameter="max_messages", value=max_messages,
                           allowed=">= 0")
        discovery = DISCOVERIES[check_runtime(runtime)]
        self.runtime = runtime
        self._writer = writer
        self._wanted = {resolve_topic(t) for t in topics}
        self._max = max_messages
        self._on_topic = on_topic
        self._stop = threading.Event()
        self._skipped: set[tuple[str, str]] = set()
        self._held: dict[tuple[str, str], list[tuple[int, RawSample]]] = {}
        self.total = 0
        self._context = open_context(runtime)
        self._port = self._context.create_port(NODE_NAME)
        self._port.create_timer(writer.flush_period_s, writer.poll)
        self._discovery = discovery(self._context, self._port, self._wanted, self._on_offer)
        self._any_type = frozenset(self._wanted if self._discovery.any_type else ())
        for topic in sorted(self._any_type):
            self._port.create_raw_subscription(topic, None, self._on_sample, ANY_TYPE_QOS)
        if self._any_type:
            self._port.create_timer(HOLD_S / 5, lambda: self._add_held(int(HOLD_S * 1e9)))

    @property
    def topics(self) -> dict[str, str]:
        """Recorded topic -> type."""
        return self._writer.topics

    @property
    def missing(self) -> list[str]:
        """Requested topics no publisher has offered yet."""
        return sorted(self._wanted - set(self._writer.topics))

    def _on_offer(self, topic: str, msgtype: str, qos: OfferedQos) -> None:
        """Discovery's ``on_offer``: add (topic, type) to the bag once, subscribing to it unless
        the topic's any-type subscription already delivers it (no new subscription once
        stopping)."""
        subscribe = topic not in self._any_type
        if not self._is_new(topic, msgtype) or (subscribe and self._stop.is_set()):
            return
        held = self._held.pop((topic, msgtype), [])
        try:
            msgtype = normalize_type_name(msgtype)
            if subscribe:
                self._port.create_raw_subscription(
                    topic, msgtype, self._on_sample,
                    QoS(depth=QUEUE_DEPTH, reliability=qos.reliability,  # type: ignore[arg-type]
                        durability=qos.durability))  # type: ignore[arg-type]
            self._writer.add_topic(topic, msgtype, qos)
        except (BagError, RuntimePortError) as error:
            self._skip(topic, msgtype, str(error))
            return
        if self._on_topic is not None:
            self._on_topic(topic, msgtype)
        for received, sample in held:
            self._write(received, sample)

    def _is_new(self, topic: str, msgtype: str) -> bool:
        """True if (topic, type) is neither in the bag nor skipped; a second type on a topic is
        skipped (logged once)."""
        known = self._writer.topics.get(topic)
        if known is None:
            return (topic, msgtype) not in self._skipped
        if known != msgtype and (topic, msgtype) not in self._skipped:
            self._skip(topic, msgtype, f"the bag already records it as {known}")
        return False

    def _skip(self, topic: str, msgtype: str, why: str) -> None:
        self._skipped.add((topic, msgtype))
        logger.warning("not recording %s [%s]: %s", topic, msgtype, why)

    def _add_held(self, min_wait_ns: int) -> None:
        """Add each held (topic, type) whose first sample waited ``min_wait_ns`` for its token,
        with the default QoS (its held samples are written)."""
        deadline = time.time_ns() - min_wait_ns
        for (topic, msgtype), held in list(self._held.items()):
            if held[0][0] <= deadline:
                self._on_offer(topic, msgtype, OfferedQos())

    def _on_sample(self, sample: RawSample) -> None:
        """Subscription callback: stamp the receive time; write, or hold a named topic's sample
        whose (topic, type) is not in the bag yet (a second type on it is dropped, logged)."""
        received = time.time_ns()
        if sample.topic not in self._any_type or \
                self._writer.topics.get(sample.topic) == sample.type_name:
            self._write(received, sample)
        elif self._is_new(sample.topic, sample.type_name):
            self._held.setdefault((sample.topic, sample.type_name), []).append((received, sample))

    def _write(self, received: int, sample: RawSample) -> None:
        """Write one sample received at ``received`` ns (the only write path)."""
        if self._max and self.total >= self._max:
            return
        attachment = sample.attachment
        self._writer.write(sample.topic, received, sample.data,
                           publish_time_ns=attachment.source_timestamp_ns if attachment else None,
                           sequence=attachment.sequence_number if attachment else 0)
        self.total += 1
        if self._max and self.total >= self._max:
            self.request_stop()
        self._stop_if_failed()

    def _stop_if_failed(self) -> None:
        """The writer failed (e.g. the disk is full): say so once and stop recording."""
        if self._writer.failure and not self._stop.is_set():
            logger.error("%s; stopping the recording", self._writer.failure)
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
            self._stop_if_failed()  # a chunk flushed by the timer may have failed

    def close(self) -> None:
        """Stop the intake, write the messages already received, close the bag."""
        self._stop.set()
        self._discovery.close()
        self._discovery.finish(DRAIN_S)
        self._add_held(0)
        self._writer.close()
