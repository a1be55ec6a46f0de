"""Record topics of a live graph (embedded zenoh or rclpy) into a rosbag2 MCAP bag.

Publishers are discovered by the runtime's strategy (:mod:`tdcm_ros.recording.discovery`),
including those that appear after the start; each (topic, type) is subscribed once for raw CDR,
with the reliability and durability its publishers offer. Every message is written with its
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

from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.typestore import normalize_type_name
from tdcm_ros.bagio.writer import BagWriter, OfferedQos
from tdcm_ros.recording.discovery import DISCOVERIES, check_runtime
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.names import resolve_topic
from tdcm_ros.runtime.port import QoS
from tdcm_ros.runtime.wire import RawSample

NODE_NAME = "_tdcm_record"
QUEUE_DEPTH = 10_000  # messages a subscription buffers while the writer is busy
DRAIN_S = 0.3  # time given to samples already received when the recorder stops (s)

logger = logging.getLogger("tdcm.record")


class Recorder:
    """Subscribes to ``topics`` (all when empty) of the ``runtime`` graph and writes to ``writer``.

    ``runtime`` is ``zenoh`` or ``rclpy``. ``max_messages`` > 0 stops the recording after that
    many messages; ``on_topic`` is called (on the spinning thread) with (topic, type) for each
    new subscription.
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
        self.total = 0
        self._context = open_context(runtime)
        self._port = self._context.create_port(NODE_NAME)
        self._port.create_timer(writer.flush_period_s, writer.poll)
        self._discovery = discovery(self._context, self._port, self._wanted, self._subscribe)

    @property
    def topics(self) -> dict[str, str]:
        """Subscribed topic -> type."""
        return self._writer.topics

    @property
    def missing(self) -> list[str]:
        """Requested topics no publisher has offered yet."""
        return sorted(self._wanted - set(self._writer.topics))

    def _subscribe(self, topic: str, msgtype: str, qos: OfferedQos) -> None:
        """Discovery's ``on_offer``: subscribe and add (topic, type) to the bag once."""
        known = self._writer.topics.get(topic)
        if known == msgtype or (topic, msgtype) in self._skipped or self._stop.is_set():
            return
        if known is not None:
            self._skip(topic, msgtype, f"the bag already records it as {known}")
            return
        try:
            msgtype = normalize_type_name(msgtype)
            self._port.create_raw_subscription(
                topic, msgtype, self._on_sample,
                QoS(depth=QUEUE_DEPTH, reliability=qos.reliability,  # type: ignore[arg-type]
                    durability=qos.durability))  # type: ignore[arg-type]
        except (BagError, RuntimePortError) as error:
            self._skip(topic, msgtype, str(error))
            return
        self._writer.add_topic(topic, msgtype, qos)
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
        self._discovery.close()
        self._discovery.finish(DRAIN_S)
        self._writer.close()
