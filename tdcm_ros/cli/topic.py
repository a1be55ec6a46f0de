"""``tdcm topic list|echo|pub|hz``: poke the embedded (zenoh) graph like ``ros2 topic``."""

from __future__ import annotations

import argparse
import itertools
import math
import statistics
import sys
import time
from typing import Any

import yaml

from tdcm_ros.errors import InputError
from tdcm_ros.yamlio import load_yaml

TOOL_NODE = "_tdcm_topic"


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``topic`` with its verbs."""
    parser = subparsers.add_parser("topic", help="list, echo, publish, measure topics (zenoh)")
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
    echo.set_defaults(handler=run_echo)

    pub = verbs.add_parser("pub", help="publish a message given as YAML")
    pub.add_argument("topic")
    pub.add_argument("type", help="pkg/msg/Name, e.g. geometry_msgs/msg/WrenchStamped")
    pub.add_argument("values", nargs="?", default="{}", help='YAML, e.g. "{data: 1.0}"')
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
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    return ZenohContext()


def graph_topics(timeout: float) -> dict[str, set[str]]:
    """Topic -> message types of the publishers and subscriptions seen within ``timeout`` s.

    A liveliness subscriber with history collects the tokens (present ones and those that show
    up while waiting); a one-shot liveliness query right after the session opens can come back
    empty.
    """
    import zenoh

    from tdcm_ros.runtime import RuntimePortError, wire

    context = _context()
    alive: set[str] = set()

    def seen(sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if sample.kind == zenoh.SampleKind.DELETE:
            alive.discard(key)
        else:
            alive.add(key)

    try:
        subscriber = context.session.liveliness().declare_subscriber(
            f"{wire.ADMIN_SPACE}/{context.domain_id}/**", seen, history=True)
        time.sleep(timeout)
        subscriber.undeclare()
    finally:
        context.close()
    topics: dict[str, set[str]] = {}
    for key in sorted(alive):
        try:
            token = wire.parse_token(key)
        except (RuntimePortError, ValueError):
            continue
        if token.kind in (wire.PUBLISHER, wire.SUBSCRIPTION):
            topics.setdefault(token.topic, set()).add(token.type_name)
    return topics


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

    try:
        port.create_raw_subscription(args.topic, args.type, show)
        context.spin()
    finally:
        context.close()
    return 0


def run_pub(args: argparse.Namespace) -> int:
    """Publish ``values`` as ``type`` at ``--rate`` Hz (or once)."""
    from tdcm_ros.bagio import from_dict

    if not args.rate > 0:
        raise InputError(f"--rate = {args.rate} Hz must be > 0", parameter="rate",
                         value=args.rate, allowed="> 0 Hz")
    values = load_yaml(args.values, "values")
    message = from_dict(args.type, values if values is not None else {})
    times = 1 if args.once else args.times
    context = _context()
    try:
        publisher = context.create_port(TOOL_NODE).create_publisher(args.topic, args.type)
        deadline = time.monotonic() + args.wait_matching
        while not publisher.matched() and time.monotonic() < deadline:
            time.sleep(0.02)
        print(f"publisher: beginning loop\npublishing #1: {message}", flush=True)
        sent = 0
        while True:
            publisher.publish(message)
            sent += 1
            if times and sent >= times:
                break
            context.spin_for(1.0 / args.rate)
        context.spin_for(0.2)
    finally:
        context.close()
    return 0


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
