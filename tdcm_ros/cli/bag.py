"""``tdcm bag info BAG`` and ``tdcm bag play BAG``: describe a bag; play it into the live graph.

``bag play`` publishes the bag's messages byte for byte on the embedded (zenoh) runtime or, with
``--runtime rclpy``, on ROS 2 (default: ``TDCM_RUNTIME``, else zenoh), as ``ros2 bag play``
does: ``--rate``, ``--start-offset``, ``--loop``, ``--topics``, ``--remap OLD:=NEW``, ``--clock
[HZ]``, ``--delay``. A progress line goes to stderr when it is a terminal (not with
``--quiet``); Ctrl-C (SIGINT) stops it with status 130, SIGTERM with 143. Exit after a signal is
guaranteed: the context gets :data:`CLOSE_TIMEOUT_S` s to close, after which the process leaves
without it (output flushed, ``os._exit``); a second signal leaves at once; and a process still
there :data:`EXIT_DEADLINE_S` s after the first signal writes every thread's stack to stderr and
exits with status 1 (so a hang anywhere, even in the interpreter's exit, shows where it was).
"""

from __future__ import annotations

import argparse
import datetime
import faulthandler
import signal
import sys
import time
from types import FrameType
from typing import Any

from tdcm_ros.cli.main import INTERRUPTED_EXIT
from tdcm_ros.cli.runtime_option import add_runtime_option
from tdcm_ros.runtime import exit_now
from tdcm_ros.runtime.run_node import resolve_runtime

DEFAULT_CLOCK_HZ = 40.0
"""``--clock`` without a value: ``ros2 bag play --clock``'s default rate (Hz)."""

EXIT_MEANINGS = {"bag play": {INTERRUPTED_EXIT: f"playback stopped; SIGTERM gives "
                                                f"{128 + signal.SIGTERM}"}}
"""What ``bag play`` means by an exit status (its ``--help`` epilog)."""
CLOSE_TIMEOUT_S = 5.0
"""Longest wait (s) for the player's context to close before the process leaves without it."""
EXIT_DEADLINE_S = 15.0
"""Time (s) after a stop signal by which the process has left, whatever it is doing."""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``bag`` with its verbs ``info`` and ``play``."""
    bag = subparsers.add_parser("bag", help="describe a bag; play it into the live graph",
                                description="Describe a rosbag2 bag (MCAP storage: a folder or "
                                            "an .mcap file) or play it into the live graph "
                                            "(zenoh or rclpy).",
                                epilog="examples:\n"
                                       "  tdcm bag info bags/paper_experiment\n"
                                       "  tdcm bag play bags/paper_experiment --rate 2 --clock")
    verbs = bag.add_subparsers(dest="verb", required=True, metavar="VERB")
    info = verbs.add_parser("info", help="topics, types, message counts, warnings")
    info.add_argument("bag", help="rosbag2 folder or .mcap file")
    info.set_defaults(handler=run_info)

    play = verbs.add_parser(
        "play", help="publish a bag's messages into the live graph (zenoh or rclpy)",
        description="Publish the bag's messages (their CDR bytes, unchanged) at the recorded "
                    "spacing, each topic with the QoS its publishers offered when recorded. "
                    "Ctrl-C stops (exit status 130).")
    play.add_argument("bag", help="rosbag2 folder or .mcap file")
    play.add_argument("--rate", type=float, default=1.0,
                      help="factor of the recorded speed (> 0; default 1)")
    play.add_argument("--start-offset", type=float, default=0.0, metavar="S",
                      help="start S seconds after the bag's first message")
    play.add_argument("--loop", action="store_true", help="play again from the start offset "
                                                          "until Ctrl-C")
    play.add_argument("--topics", nargs="+", default=[], metavar="TOPIC",
                      help="play only these topics (bag names; default: all)")
    play.add_argument("--remap", action="append", default=[], metavar="OLD:=NEW",
                      help="publish bag topic OLD as NEW (repeatable)")
    play.add_argument("--clock", type=float, nargs="?", const=DEFAULT_CLOCK_HZ, default=0.0,
                      metavar="HZ", help=f"publish the bag time on /clock at HZ (default "
                                         f"{DEFAULT_CLOCK_HZ:g}), for nodes with use_sim_time")
    play.add_argument("--delay", type=float, default=0.0, metavar="S",
                      help="wait S seconds between creating the publishers and the first "
                           "message (lets subscribers discover them; useful on rclpy)")
    play.add_argument("--quiet", action="store_true", help="no progress line")
    add_runtime_option(play, "the graph to play into")
    play.set_defaults(handler=run_play)


def utc_time(ns: int) -> str:
    """ns since the epoch as an ISO 8601 UTC time to the microsecond."""
    return datetime.datetime.fromtimestamp(ns / 1e9, datetime.UTC).isoformat(
        timespec="microseconds").replace("+00:00", "Z")


def run_info(args: argparse.Namespace) -> int:
    """Print what ``open_bag`` finds in a bag."""
    from tdcm_ros.bagio.reader import open_bag

    reader = open_bag(args.bag)
    print(f"bag: {reader.path}")
    if reader.message_count:
        first_ns, last_ns = reader.time_range_ns
        print(f"duration: {(last_ns - first_ns) / 1e9:.3f} s\n"
              f"start: {utc_time(first_ns)} ({first_ns / 1e9:.9f})\n"
              f"end: {utc_time(last_ns)} ({last_ns / 1e9:.9f})")
    print(f"messages: {reader.message_count}\ntopics:")
    for topic in sorted(reader.topics):
        print(f"  {topic} [{reader.topics[topic]}]: {reader.counts[topic]}")
    for warning in reader.warnings:
        print(f"warning: {warning}")
    return 0


class ProgressLine:
    """One line on stderr, rewritten in place: bag time played, span, rate, messages, pass."""

    def __init__(self, rate: float, enabled: bool) -> None:
        self.rate = rate
        self.enabled = enabled
        self.shown = False

    def __call__(self, progress: Any) -> None:
        if not self.enabled:
            return
        loop = f"  pass {progress.pass_number}" if progress.pass_number > 1 else ""
        sys.stderr.write(f"\r[playing] {progress.bag_s:8.2f} / {progress.span_s:.2f} s  "
                         f"x{self.rate:g}  {progress.published} messages{loop}\x1b[K")
        sys.stderr.flush()
        self.shown = True

    def end(self) -> None:
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()


def arm_exit_deadline() -> None:
    """Past :data:`EXIT_DEADLINE_S` s from now, dump every thread's stack to stderr and exit 1
    (faulthandler's watchdog: a C thread that needs neither the GIL nor the main thread)."""
    faulthandler.dump_traceback_later(EXIT_DEADLINE_S, exit=True)


#: s: a bag older than this, played without ``--clock``, reaches nodes on wall time stale
#: (model_node's ``input.max_age_s`` default).
STALE_AFTER_S = 0.5


def stale_stamps_warning(bag_start_ns: int, now_ns: int, clock: bool) -> str:
    """What ``bag play`` says when nodes on wall time will drop the bag's stamps ("" if not):
    without ``--clock`` a bag recorded more than :data:`STALE_AFTER_S` s ago."""
    age_s = (now_ns - bag_start_ns) / 1e9
    if clock or age_s <= STALE_AFTER_S:
        return ""
    return (f"WARNING: the bag's messages are stamped {age_s:.0f} s ago and no /clock is played: "
            f"nodes on wall time drop them as stale (model_node: input.max_age_s). Play with "
            f"--clock and run the nodes on it (tdcm up --use-sim-time).")


def run_play(args: argparse.Namespace) -> int:
    """Play until the end, ``--loop`` until a signal; print what was published."""
    stopped_by: list[int] = []
    player: Any = None

    def on_signal(signum: int, _: FrameType | None) -> None:
        if stopped_by:  # a second Ctrl-C: the first one's stop is taking too long
            exit_now(128 + stopped_by[0])
        stopped_by.append(signum)
        arm_exit_deadline()
        if player is not None:
            player.request_stop()

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, on_signal)

    from tdcm_ros.recording import Player, PlayOptions, parse_remap

    options = PlayOptions(rate=args.rate, start_offset_s=args.start_offset, loop=args.loop,
                          topics=tuple(args.topics),
                          remap=tuple(parse_remap(r) for r in args.remap),
                          clock_hz=args.clock, delay_s=args.delay)
    runtime = resolve_runtime(args.runtime)
    line = ProgressLine(args.rate, sys.stderr.isatty() and not args.quiet)
    player = Player(args.bag, options, runtime=runtime, on_progress=line,
                    on_topic=lambda topic, name, msgtype, qos: print(
                        f"publishing {name} [{msgtype}] ({qos.reliability}, {qos.durability}, "
                        f"depth {qos.depth})" + (f" from {topic}" if name != topic else ""),
                        flush=True))
    if stopped_by:
        player.request_stop()
    print(f"playing {player.reader.path} into the {runtime} graph at x{args.rate:g}"
          f"{', looping' if args.loop else ''}; Ctrl-C to stop", flush=True)
    if warning := stale_stamps_warning(player.base_ns, time.time_ns(), bool(args.clock)):
        print(warning, file=sys.stderr, flush=True)
    if args.clock:
        for node, topic in player.wall_time_readers():
            print(f"WARNING: {node} reads {topic} on wall time (use_sim_time false): the bag's "
                  f"time is on /clock, so a node that checks stamps drops them as stale; run it "
                  f"with use_sim_time (tdcm up --use-sim-time)", file=sys.stderr, flush=True)
    try:
        published = player.run()
    finally:
        line.end()
        closed = player.close(timeout=CLOSE_TIMEOUT_S)
    print(f"{published} messages published on {len(player.topics)} topics", flush=True)
    status = 128 + stopped_by[0] if stopped_by else 0
    if not closed:
        print(f"tdcm bag play: the {runtime} context did not close within {CLOSE_TIMEOUT_S:g} s; "
              f"exiting without it", file=sys.stderr)
        exit_now(status)
    return status
