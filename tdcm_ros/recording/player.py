"""Play a rosbag2 bag into the live graph (embedded zenoh or rclpy): ``tdcm bag play``.

Every message goes out as the bag holds it: its CDR bytes, unchanged (no decode, no re-encode),
on its topic or the name it is remapped to, in log-time order, spaced by the log times divided
by ``rate``. Each topic is published with the QoS its recorded publishers offered
(:meth:`BagReader.qos`: e.g. ``/tf_static`` transient local with depth 1, so a node that starts
later still receives it, as long as the player runs), a volatile one with a history of at least
:data:`VOLATILE_DEPTH` (:func:`played_depth`). Playback starts ``start_offset_s`` after
the bag's first log time; ``loop`` plays it again from there until stopped. With ``clock_hz`` > 0,
``/clock`` (rosgraph_msgs/msg/Clock) carries the bag time (log time) at that rate (Hz of wall
time): the start offset's time during ``delay_s``, then once at the start of each pass and
periodically, so nodes with ``use_sim_time`` run on the bag's time from before the first message. Topics whose type is unknown (no definition in the bag or the typestore) or
that the runtime cannot publish (rclpy without the message package) are skipped with a warning.

The player owns its context (``open_context(runtime)``, configured from the environment);
:meth:`Player.request_stop` is safe from signal handlers.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tdcm_ros.bagio import BagError, from_dict
from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.runtime import (
    CLOCK_QOS,
    CLOCK_TOPIC,
    CLOCK_TYPE,
    QoS,
    RuntimePortError,
    close_within,
    resolve_topic,
)
from tdcm_ros.runtime.param_client import ParameterClient

NODE_NAME = "_tdcm_play"
#: s: longest wait for the graph's readers of the played topics (:meth:`Player.wall_time_readers`).
READERS_WAIT_S = 2.0
READERS_POLL_S = 0.05  #: s between two looks at the graph's readers
MAX_CLOCK_HZ = 10_000.0
LINGER_S = 0.3  # time given to the last samples to leave before the context closes (s)
PROGRESS_PERIOD_S = 0.1  # wall time between two progress reports (s)
STOP_LATENCY_S = 0.1  # longest wait between two looks at the stop request (s)
RUNTIMES = ("zenoh", "rclpy")
#: Writer history (messages) of a played volatile topic, at least: a reliable keep-last writer
#: drops its oldest unacknowledged sample when the history is full, so with the recorded depth
#: (10 on /markers) a reader starved of CPU for 25 ms at x4 lost marker frames (83 of 6,758 on
#: rclpy/Fast DDS beside other tests). A volatile writer's depth changes nothing else a reader
#: sees; a transient-local one keeps the recorded depth, which is what a late joiner receives.
VOLATILE_DEPTH = 1000
MAX_DEPTH = 10_000

logger = logging.getLogger("tdcm.play")


def played_depth(offered_depth: int, durability: str) -> int:
    """History depth (messages) the player publishes a topic with, from the recorded one."""
    depth = max(offered_depth, 1) if durability == "transient_local" else \
        max(offered_depth, VOLATILE_DEPTH)
    return min(depth, MAX_DEPTH)


def _finite_at_least(name: str, value: float, low: float, unit: str, *, open_low: bool) -> None:
    ok = math.isfinite(value) and (value > low if open_low else value >= low)
    if not ok:
        raise out_of_range(name, value, f"{'(' if open_low else '['}{low:g}, inf) {unit}",
                           unit=unit)


def parse_remap(text: str) -> tuple[str, str]:
    """``OLD:=NEW`` (``ros2 bag play --remap``) as (OLD, NEW); ``InputError`` otherwise."""
    old, sep, new = text.partition(":=")
    if not sep or not old.strip() or not new.strip():
        raise InputError(f"--remap {text!r} is invalid; allowed: OLD:=NEW (topic names)",
                         parameter="remap", value=text, allowed="OLD:=NEW")
    return old.strip(), new.strip()


@dataclass(frozen=True)
class PlayOptions:
    """How to play: ``rate`` (factor of the recorded speed), ``start_offset_s`` (s after the
    bag's first message), ``loop``, ``topics`` (bag names; empty: all), ``remap`` ((bag name,
    published name) pairs), ``clock_hz`` (``/clock`` rate, Hz of wall time; 0: no ``/clock``),
    ``delay_s`` (wall time between creating the publishers and the first message, for discovery)."""

    rate: float = 1.0
    start_offset_s: float = 0.0
    loop: bool = False
    topics: tuple[str, ...] = ()
    remap: tuple[tuple[str, str], ...] = ()
    clock_hz: float = 0.0
    delay_s: float = 0.0

    def __post_init__(self) -> None:
        _finite_at_least("rate", self.rate, 0.0, "", open_low=True)
        _finite_at_least("start_offset_s", self.start_offset_s, 0.0, "s", open_low=False)
        _finite_at_least("delay_s", self.delay_s, 0.0, "s", open_low=False)
        if not (self.clock_hz == 0.0 or 0.0 < self.clock_hz <= MAX_CLOCK_HZ):
            raise out_of_range("clock_hz", self.clock_hz, f"0 (off) or (0, {MAX_CLOCK_HZ:g}] Hz",
                               unit="Hz")


@dataclass(frozen=True)
class Progress:
    """Where playback is: bag time since the start offset (s) of ``span_s``, messages published
    so far, and the pass (1 = first; > 1 with ``loop``)."""

    bag_s: float
    span_s: float
    published: int
    pass_number: int


class Player:
    """Publishes the messages of the bag at ``path`` into the ``runtime`` graph (``zenoh`` or
    ``rclpy``); ``on_progress`` is called about every :data:`PROGRESS_PERIOD_S` s while playing
    and once at the end. ``on_topic(bag topic, published topic, type, qos)`` is called for each
    topic it publishes."""

    def __init__(self, path: str | Path, options: PlayOptions | None = None, *,
                 runtime: str = "zenoh",
                 on_progress: Callable[[Progress], None] | None = None,
                 on_topic: Callable[[str, str, str, QoS], None] | None = None) -> None:
        from tdcm_ros.bagio.reader import open_bag
        from tdcm_ros.runtime.run_node import open_context

        if runtime not in RUNTIMES:
            raise InputError(f"runtime = {runtime!r} is invalid; allowed: {', '.join(RUNTIMES)}",
                             parameter="runtime", value=runtime, allowed=", ".join(RUNTIMES))
        self.options = options or PlayOptions()
        self.runtime = runtime
        self.reader = open_bag(path)
        self._on_progress = on_progress
        first_ns, last_ns = self.reader.time_range_ns
        self.base_ns = first_ns + round(self.options.start_offset_s * 1e9)
        self.span_s = (last_ns - self.base_ns) / 1e9
        if self.base_ns > last_ns:
            raise out_of_range("start_offset_s", self.options.start_offset_s,
                               f"[0, {(last_ns - first_ns) / 1e9:g}] s (the bag's span)",
                               unit="s")
        names = self._published_names(self._selected())
        self._names = names
        self.published = 0
        self._stop = threading.Event()
        self._pass = 0
        self._wall0 = time.monotonic()
        self._next_clock = self._next_report = math.inf
        self._context = open_context(self.runtime)
        try:
            self._port = self._context.create_port(NODE_NAME)
            self._publishers = self._create_publishers(names, on_topic)
            self._clock = (self._port.create_publisher(CLOCK_TOPIC, CLOCK_TYPE, CLOCK_QOS)
                           if self.options.clock_hz else None)
        except BaseException:
            self._context.close()
            raise
        self.topics = sorted(self._publishers)
        self._created = time.monotonic()  # the publishers exist: ``delay_s`` counts from here

    def _selected(self) -> list[str]:
        """Bag names of the topics to play; named undecodable topics are an error."""
        undecodable = self.reader.undecodable
        if not self.options.topics:
            for topic in sorted(undecodable):
                logger.warning("not playing %s: %s", topic, undecodable[topic])
            return sorted(set(self.reader.topics) - set(undecodable))
        selected = sorted({self.reader.resolve(t) for t in self.options.topics})
        for topic in selected:
            if topic in undecodable:
                raise BagError(f"{self.reader.path}: topic {topic} cannot be played: "
                               f"{undecodable[topic]}", parameter="topics", value=topic)
        return selected

    def _published_names(self, selected: Sequence[str]) -> dict[str, str]:
        """Bag name -> published name of each selected topic (remapped ones resolved)."""
        remap = {self.reader.resolve(old): resolve_topic(new) for old, new in self.options.remap}
        return {topic: remap.get(topic, topic) for topic in selected}

    def _create_publishers(self, names: dict[str, str],
                           on_topic: Callable[[str, str, str, QoS], None] | None) -> dict[str, Any]:
        publishers = {}
        for topic, name in names.items():
            offered = self.reader.qos(topic)
            qos = QoS(depth=played_depth(offered.depth, offered.durability),
                      reliability=offered.reliability,  # type: ignore[arg-type]
                      durability=offered.durability)  # type: ignore[arg-type]
            msgtype = self.reader.topics[topic]
            try:
                publishers[topic] = self._port.create_publisher(name, msgtype, qos)
            except (BagError, RuntimePortError) as error:
                logger.warning("not playing %s [%s]: %s", topic, msgtype, error)
                continue
            if on_topic is not None:
                on_topic(topic, name, msgtype, qos)
        if not publishers:
            raise BagError(f"{self.reader.path}: no topic can be played", parameter="topics",
                           value=list(self.options.topics))
        return publishers

    def wall_time_readers(self) -> list[tuple[str, str]]:
        """``(node, topic)`` for each node reading a played topic whose ``use_sim_time`` is
        false: while the bag's time is on ``/clock`` such a node still takes the wall clock, and
        one that checks stamps drops the bag's as stale. Readers are looked for up to
        :data:`READERS_WAIT_S` s or ``delay_s`` (the time given to discovery), less once every
        topic has one; hidden nodes (``_`` names: tools such as a recorder) and nodes that do
        not answer a parameter request are left out."""
        timeout = max(READERS_WAIT_S, self.options.delay_s)
        topics = [self._names[topic] for topic in self._publishers]
        found = []
        deadline = time.monotonic() + timeout
        while not all((readers := self._context.subscribed_nodes(topics)).values()) \
                and time.monotonic() < deadline:
            self._context.spin_for(READERS_POLL_S)
        for topic, nodes in readers.items():
            for node in sorted(nodes):
                if node.rsplit("/", 1)[-1].startswith("_"):
                    continue
                try:
                    on_sim_time = ParameterClient(self._context, node).get(
                        "use_sim_time")
                except (RuntimePortError, InputError) as error:
                    logger.info("use_sim_time of %s not known: %s", node, error)
                    continue
                if on_sim_time is False:
                    found.append((node, topic))
        return found

    def request_stop(self) -> None:
        """Stop playing soon (safe from signal handlers and other threads)."""
        self._stop.set()

    @property
    def stopped(self) -> bool:
        """True once :meth:`request_stop` was called."""
        return self._stop.is_set()

    def run(self) -> int:
        """Play until the end (with ``loop``: until stopped); returns the messages published."""
        now = time.monotonic()
        # /clock holds the start time until then
        self._wall0 = max(now, self._created + self.options.delay_s)
        self._next_clock = now if self._clock is not None else math.inf
        self._next_report = now
        if self._wait_until(self._wall0):
            while self._play_pass() and self.options.loop:
                pass
        self._report(time.monotonic())
        return self.published

    def _play_pass(self) -> bool:
        """One pass from the start offset; False if stopped."""
        self._pass += 1
        self._wall0 = now = time.monotonic()
        self._next_report = now
        if self._clock is not None:
            self._next_clock = now
        scale = 1e-9 / self.options.rate
        for topic, stamp, data in self.reader.raw_messages(list(self._publishers)):
            if stamp < self.base_ns:
                continue
            if not self._wait_until(self._wall0 + (stamp - self.base_ns) * scale):
                return False
            self._publishers[topic].publish_cdr(data)
            self.published += 1
        return not self._stop.is_set()

    def _bag_ns(self, wall: float) -> int:
        """Bag time (log time, ns) at monotonic time ``wall`` of the current pass (the start
        offset's time during ``delay_s``)."""
        return self.base_ns + max(round((wall - self._wall0) * self.options.rate * 1e9), 0)

    def _wait_until(self, due: float) -> bool:
        """Wait for monotonic time ``due``, sending ``/clock`` ticks and progress reports;
        False if stopped."""
        while not self._stop.is_set():
            now = time.monotonic()
            if now >= self._next_clock:
                self._tick(now)
            if now >= self._next_report:
                self._report(now)
            if now >= due:
                return True
            wake = min(due, self._next_clock, self._next_report)
            self._context.spin_for(min(max(wake - now, 0.0), STOP_LATENCY_S))
        return False

    def _tick(self, now: float) -> None:
        assert self._clock is not None
        ns = self._bag_ns(now)
        self._clock.publish(from_dict(CLOCK_TYPE, {"clock": {"sec": ns // 1_000_000_000,
                                                             "nanosec": ns % 1_000_000_000}}))
        period = 1.0 / self.options.clock_hz
        self._next_clock = max(self._next_clock + period, now)

    def _report(self, now: float) -> None:
        self._next_report = now + PROGRESS_PERIOD_S
        if self._on_progress is not None:
            bag_s = min((self._bag_ns(now) - self.base_ns) / 1e9, self.span_s)
            self._on_progress(Progress(max(bag_s, 0.0), self.span_s, self.published,
                                       max(self._pass, 1)))

    def close(self, timeout: float | None = None) -> bool:
        """Give the last samples :data:`LINGER_S` s to leave, then close the context; True once
        closed. With ``timeout``, the context closes on a daemon thread and False means it had
        not closed ``timeout`` s after the linger (a transport blocked in its close): the thread
        is left behind and does not hold the process, which should then exit."""
        time.sleep(LINGER_S)
        if timeout is None:
            self._context.close()
            return True
        return close_within(self._context.close, timeout, name="play-close")
