"""``tdcm topic list|echo|pub|hz``: poke the embedded (zenoh) graph like ``ros2 topic``.

As ``ros2 topic`` does, ``echo`` warns when no publisher of the topic shows up within
``--wait-matching`` s (naming topics with similar names), and ``echo``/``pub`` given a type that
is not the one the graph uses on the topic end with an input error (exit status 2) instead of
waiting or publishing where no one listens.
"""

from __future__ import annotations

import argparse
import difflib
import itertools
import math
import statistics
import sys
import time
from collections.abc import Collection
from typing import TYPE_CHECKING, Any

import yaml

from tdcm_ros.errors import InputError
from tdcm_ros.yamlio import load_yaml

if TYPE_CHECKING:
    from tdcm_ros.runtime.zenoh_runtime import GraphWatch, ZenohContext

TOOL_NODE = "_tdcm_topic"
NOT_RECEIVED_EXIT = 1
"""``topic pub``: no subscriber matched while it published (nothing received the messages)."""
EXIT_MEANINGS = {f"topic {verb}": {InputError.exit_code: "also: the type given is not the one "
                                                         "the graph uses on the topic"}
                 for verb in ("echo", "pub")}
EXIT_MEANINGS["topic pub"][NOT_RECEIVED_EXIT] = ("no subscriber matched while it published: "
                                                 "nothing received the messages")
"""What ``topic echo|pub`` mean by an exit status (their ``--help`` epilogs)."""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``topic`` with its verbs."""
    parser = subparsers.add_parser(
        "topic", help="list, echo, publish, measure topics (zenoh)",
        description="Look at and poke the embedded (zenoh) graph the way ros2 topic does.",
        epilog="examples:\n"
               "  tdcm topic list -t\n"
               "  tdcm topic echo tip_pose --once\n"
               "  tdcm topic pub tension geometry_msgs/msg/WrenchStamped "
               "'{header: auto, wrench: {force: {z: 8.0}}}' --once\n"
               "  tdcm topic hz markers --duration 5")
    verbs = parser.add_subparsers(dest="verb", required=True, metavar="VERB")

    listing = verbs.add_parser("list", help="topics with a publisher or subscription")
    listing.add_argument("-t", "--show-types", action="store_true", help="show message types")
    listing.add_argument("--timeout", type=float, default=1.0, help="discovery wait (s)")
    listing.set_defaults(handler=run_list)

    echo = verbs.add_parser("echo", help="print messages as YAML")
    echo.add_argument("topic")
    echo.add_argument("type", nargs="?", help="pkg/msg/Name (default: any type on the topic)")
    echo.add_argument("--once", action="store_true", help="print one message and exit")
    echo.add_argument("--count", type=int, default=0, help="exit after N messages")
    echo.add_argument("--wait-matching", type=float, default=1.0,
                      help="warn if no publisher of the topic is seen within this long (s; "
                           "default: 1)")
    echo.set_defaults(handler=run_echo)

    pub = verbs.add_parser("pub", help="publish a message given as YAML")
    pub.add_argument("topic")
    pub.add_argument("type", help="pkg/msg/Name, e.g. geometry_msgs/msg/WrenchStamped")
    pub.add_argument("values", nargs="?", default="{}",
                     help='YAML, e.g. "{data: 1.0}"; a Header may be "auto" and a Time "now" '
                          "(stamped as each message is sent)")
    pub.add_argument("-1", "--once", action="store_true", help="publish once and exit")
    pub.add_argument("-r", "--rate", type=float, default=1.0, help="publishing rate (Hz)")
    pub.add_argument("-t", "--times", type=int, default=0, help="publish N times and exit")
    pub.add_argument("--wait-matching", type=float, default=2.0,
                     help="wait up to this long (s) for a subscriber before publishing")
    pub.set_defaults(handler=run_pub)

    hz = verbs.add_parser("hz", help="print the receive rate")
    hz.add_argument("topic")
    hz.add_argument("-w", "--window", type=int, default=100, help="messages in the statistics")
    hz.add_argument("--duration", type=float, default=0.0, help="exit after this long (s)")
    hz.set_defaults(handler=run_hz)


def _context() -> Any:
    from tdcm_ros.runtime.run_node import open_context

    return open_context("zenoh", require_graph=True)


def graph_topics(timeout: float) -> dict[str, set[str]]:
    """Topic -> message types of the publishers and subscriptions seen within ``timeout`` s."""
    from tdcm_ros.runtime.zenoh_runtime import GraphWatch

    context = _context()

    try:
        watch = GraphWatch(context)
        time.sleep(timeout)
        watch.close()
    finally:
        context.close()
    return watch.topics()


def similar_topics(topic: str, topics: Collection[str]) -> str:
    """``"; similar topics: /a, /b"`` for names close to ``topic``, else ``""``."""
    near = difflib.get_close_matches(topic, sorted(topics), n=3, cutoff=0.6)
    return f"; similar topics: {', '.join(near)}" if near else ""


def check_type(topic: str, type_name: str | None, types: Collection[str], graph: str) -> None:
    """``InputError`` if ``type_name`` is given, the graph uses ``topic`` with ``types`` (its
    ``graph`` endpoints, e.g. "published") and ``type_name`` is not among them."""
    from tdcm_ros.bagio import normalize_type_name

    if type_name is None or not types or normalize_type_name(type_name) in types:
        return
    allowed = ", ".join(sorted(types))
    raise InputError(f"topic {topic} is {graph} as {allowed}, not {type_name}; allowed: {allowed}",
                     parameter="type", value=type_name, allowed=allowed)


def run_list(args: argparse.Namespace) -> int:
    """Print topic names (``-t``: with types) known from liveliness tokens."""
    if not args.timeout > 0:
        raise InputError(f"--timeout = {args.timeout} s must be > 0", parameter="timeout",
                         value=args.timeout, allowed="> 0 s")
    topics = graph_topics(args.timeout)
    for topic in sorted(topics):
        print(f"{topic} [{', '.join(sorted(topics[topic]))}]" if args.show_types else topic)
    return 0


def run_echo(args: argparse.Namespace) -> int:
    """Print each message as a YAML document until Ctrl-C, ``--once`` or ``--count``."""
    from tdcm_ros.bagio import BagError, deserialize, to_dict
    from tdcm_ros.runtime import QoS, resolve_topic

    if not args.wait_matching >= 0:
        raise InputError(f"--wait-matching = {args.wait_matching} s must be >= 0",
                         parameter="wait_matching", value=args.wait_matching, allowed=">= 0 s")
    limit = 1 if args.once else args.count
    context = _context()
    port = context.create_port(TOOL_NODE)
    received = 0

    def show(sample: Any) -> None:
        # The executor runs every callback already queued after the one that requests the stop,
        # so samples of a burst can still arrive here once the limit is reached.
        nonlocal received
        if limit and received >= limit:
            return
        try:
            message = deserialize(sample.data, sample.type_name)
        except BagError as error:
            print(f"# dropped: {error}", file=sys.stderr)
            return
        print(yaml.safe_dump(to_dict(message), sort_keys=False, default_flow_style=False), end="")
        print("---", flush=True)
        received += 1
        if limit and received >= limit:
            context.request_stop()

    from tdcm_ros.runtime.zenoh_runtime import GraphWatch

    try:
        watch = GraphWatch(context)
        topic = resolve_topic(args.topic)
        seen = _wait_for_publishers(context, watch, topic, args.wait_matching)
        # as ros2 topic echo: transient local when every publisher is (their latest message
        # then reaches this late joiner), else the default, volatile
        qos = QoS(durability="transient_local") if seen == {"transient_local"} else QoS()
        _check_published(watch, topic, args.type, args.wait_matching)
        port.create_raw_subscription(args.topic, args.type, show, qos)
        context.spin()
    finally:
        context.close()
    return 0


def _wait_for_publishers(context: ZenohContext, watch: GraphWatch, topic: str,
                         wait_s: float) -> set[str]:
    """Spin until a publisher of ``topic`` is seen or ``wait_s`` s passed; the durabilities
    its publishers declare (empty: none seen)."""
    deadline = time.monotonic() + wait_s
    while not (seen := watch.publisher_durabilities(topic)) and time.monotonic() < deadline:
        context.spin_for(min(0.05, max(deadline - time.monotonic(), 0.0)))
    return seen


def _check_published(watch: GraphWatch, topic: str, type_name: str | None, waited: float) -> None:
    """After ``waited`` s: an error if the topic is published with other types only, a warning
    (with similar names) if it is not published at all."""
    publishers = watch.topics(kinds=("MP",))
    types = publishers.get(topic, set())
    check_type(topic, type_name, types, "published")
    if not types:
        print(f"WARNING: topic [{topic}] does not appear to be published yet (no publisher seen "
              f"in {waited:g} s){similar_topics(topic, watch.topics())}; still waiting",
              file=sys.stderr, flush=True)


def run_pub(args: argparse.Namespace) -> int:
    """Publish ``values`` as ``type`` at ``--rate`` Hz (or once)."""
    from tdcm_ros.bagio import from_dict, to_dict

    if not args.rate > 0:
        raise InputError(f"--rate = {args.rate} Hz must be > 0", parameter="rate",
                         value=args.rate, allowed="> 0 Hz")
    values = load_yaml(args.values, "values")
    values = values if values is not None else {}
    from_dict(args.type, with_stamps(args.type, values, 0))  # a bad value fails before connecting
    times = 1 if args.once else args.times
    context = _context()
    from tdcm_ros.runtime.zenoh_runtime import GraphWatch

    try:
        watch = GraphWatch(context)
        publisher = context.create_port(TOOL_NODE).create_publisher(args.topic, args.type)
        deadline = time.monotonic() + args.wait_matching
        while not publisher.matched() and time.monotonic() < deadline:
            time.sleep(0.02)
        graph = watch.topics(ignore_zid=context.zid)
        check_type(publisher.topic, args.type, graph.get(publisher.topic, set()), "used")
        if not publisher.matched():
            print(f"WARNING: no subscriber of {publisher.topic} matched within "
                  f"{args.wait_matching:g} s{similar_topics(publisher.topic, graph)}; "
                  f"publishing anyway", file=sys.stderr, flush=True)
        print("publisher: beginning loop", flush=True)
        sent = 0
        heard = publisher.matched()
        while True:
            message = from_dict(args.type, with_stamps(args.type, values, time.time_ns()))
            publisher.publish(message)
            sent += 1
            print(f"publishing #{sent}: {flow_yaml(to_dict(message))}", flush=True)
            heard = heard or publisher.matched()
            if times and sent >= times:
                break
            context.spin_for(1.0 / args.rate)
        context.spin_for(0.2)
    finally:
        context.close()
    if not heard:  # a command (estop) that reached nobody must not look delivered
        print(f"tdcm topic pub: no subscriber of {publisher.topic} matched while it published; "
              f"nothing received the {sent} message(s)", file=sys.stderr)
        return NOT_RECEIVED_EXIT
    return 0


HEADER, TIME = "std_msgs/msg/Header", "builtin_interfaces/msg/Time"


def with_stamps(type_name: str, values: Any, now_ns: int) -> Any:
    """``values`` (YAML data of ``type_name``) with ``ros2 topic pub``'s keywords filled in: a
    ``std_msgs/msg/Header`` given ``auto`` is stamped ``now_ns`` (frame_id ""), a
    ``builtin_interfaces/msg/Time`` given ``now`` is ``now_ns`` (ns since the epoch)."""
    from rosbags.typesys.base import Nodetype

    from tdcm_ros.bagio import normalize_type_name, typestore

    name = normalize_type_name(type_name)
    now = {"sec": now_ns // 1_000_000_000, "nanosec": now_ns % 1_000_000_000}
    if name == HEADER and values == "auto":
        return {"stamp": now, "frame_id": ""}
    if name == TIME and values == "now":
        return now
    if not isinstance(values, dict):
        return values
    filled = dict(values)
    for field, (kind, rest) in typestore().fielddefs[name][1]:
        if field in filled and kind == Nodetype.NAME and isinstance(rest, str):
            filled[field] = with_stamps(rest, filled[field], now_ns)
    return filled


def flow_yaml(data: Any) -> str:
    """``data`` as one line of YAML flow style (how ``publishing #N:`` shows a message)."""
    return str(yaml.safe_dump(data, default_flow_style=True, sort_keys=False, width=2**31)).strip()


def rate_stats(arrivals: list[float]) -> tuple[float, float, float, float]:
    """Average rate (Hz), min and max period (s), period standard deviation (s)."""
    periods = [b - a for a, b in itertools.pairwise(arrivals)]
    mean = statistics.fmean(periods)
    return (1.0 / mean if mean > 0 else math.inf, min(periods), max(periods),
            statistics.pstdev(periods))


def run_hz(args: argparse.Namespace) -> int:
    """Print rate statistics about once per second."""
    context = _context()
    arrivals: list[float] = []

    def arrived(_: Any) -> None:
        arrivals.append(time.monotonic())
        del arrivals[:-args.window - 1]

    end = time.monotonic() + args.duration if args.duration > 0 else math.inf
    try:
        context.create_port(TOOL_NODE).create_raw_subscription(args.topic, None, arrived)
        while time.monotonic() < end:
            context.spin_for(min(1.0, end - time.monotonic()))
            if len(arrivals) < 2:
                print("no new messages", flush=True)
                continue
            rate, low, high, std = rate_stats(arrivals)
            print(f"average rate: {rate:.3f}\n\tmin: {low:.3f}s max: {high:.3f}s "
                  f"std dev: {std:.5f}s window: {len(arrivals)}", flush=True)
    finally:
        context.close()
    return 0
