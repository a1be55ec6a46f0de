"""``tdcm record BAG [TOPIC...]``: record a live graph (zenoh or rclpy) into a rosbag2 MCAP bag.

``--runtime`` defaults to ``TDCM_RUNTIME`` if set, else zenoh.

``tdcm bag info|play`` is in :mod:`tdcm_ros.cli.bag`.
"""

from __future__ import annotations

import argparse
import shutil
import signal
import sys
from types import FrameType

from tdcm_ros.cli.runtime_option import add_runtime_option
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.run_node import resolve_runtime

EMPTY_BAG_EXIT = 1
"""Exit status of a recording that wrote no message (the empty bag is kept)."""
WRITE_FAILED_EXIT = 3
"""Exit status of a recording whose writing failed (the bag keeps what was written)."""
EXIT_MEANINGS = {"record": {EMPTY_BAG_EXIT: "no message was recorded; the empty bag is kept",
                            WRITE_FAILED_EXIT: "writing failed (e.g. a full disk): the bag keeps "
                                               "what was written, readable, with metadata.yaml"}}
"""What ``record`` means by an exit status (its ``--help`` epilog)."""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``record``."""
    parser = subparsers.add_parser(
        "record", help="record topics into a rosbag2 MCAP bag (zenoh or rclpy)",
        description="Record topics (all when none are named, including ones that appear later) "
                    "until Ctrl-C/SIGTERM, --duration or --max-messages; the bag is then closed.",
        epilog="examples:\n"
               "  tdcm record /tmp/run1                     # every topic, until Ctrl-C\n"
               "  tdcm record /tmp/run2 tension markers /tf_static --duration 60")
    parser.add_argument("bag", help="bag folder to create (must not exist)")
    parser.add_argument("topics", nargs="*", help="topics to record (default: all)")
    parser.add_argument("--duration", type=float, default=0.0, help="stop after S seconds")
    parser.add_argument("--max-messages", type=int, default=0, help="stop after N messages")
    parser.add_argument("--flush-period", type=float, default=0.1,
                        help="longest time (s) a received message waits before it is written "
                             "to the file (bounds the loss on SIGKILL)")
    add_runtime_option(parser, "the graph to record")
    parser.set_defaults(handler=run_record)


def _check(args: argparse.Namespace) -> None:
    if not args.duration >= 0:
        raise InputError(f"--duration = {args.duration} s is out of range; allowed: >= 0",
                         parameter="duration", value=args.duration, allowed=">= 0 s")
    if args.max_messages < 0:
        raise InputError(f"--max-messages = {args.max_messages} is out of range; allowed: >= 0",
                         parameter="max_messages", value=args.max_messages, allowed=">= 0")


def run_record(args: argparse.Namespace) -> int:
    """Record until a signal or a limit; print a per-topic summary."""
    _check(args)
    stop_requested: list[int] = []

    def on_signal(signum: int, _: FrameType | None) -> None:
        stop_requested.append(signum)
        if recorder is not None:
            recorder.request_stop()

    recorder = None
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, on_signal)

    from tdcm_ros.bagio.writer import BagWriter
    from tdcm_ros.recording import Recorder

    runtime = resolve_runtime(args.runtime)
    writer = BagWriter(args.bag, flush_period_s=args.flush_period)
    try:
        recorder = Recorder(writer, args.topics, runtime=runtime, max_messages=args.max_messages,
                            on_topic=lambda t, m: print(f"subscribed {t} [{m}]", flush=True))
    except BaseException:
        writer.close()
        shutil.rmtree(writer.path, ignore_errors=True)
        raise
    print(f"recording to {writer.path} from the {runtime} graph ({', '.join(args.topics) or 'all topics'}); "
          f"Ctrl-C to stop", flush=True)
    try:
        if not stop_requested:
            recorder.run(args.duration)
    finally:
        recorder.close()
    counts = writer.counts
    for topic in sorted(counts):
        print(f"{topic} [{writer.topics[topic]}]: {counts[topic]} messages")
    print(f"{sum(counts.values())} messages in {len(counts)} topics written to {writer.path}",
          flush=True)
    if writer.failure:
        print(f"tdcm record: {writer.failure}; the bag keeps the {sum(counts.values())} "
              f"messages written before (readable, metadata.yaml written); {writer.lost} "
              f"received later were lost", file=sys.stderr)
        return WRITE_FAILED_EXIT
    if recorder.missing:
        print(f"tdcm record: never published: {', '.join(recorder.missing)}", file=sys.stderr)
    if not sum(counts.values()):
        print("tdcm record: no message was recorded; the bag is empty", file=sys.stderr)
        return EMPTY_BAG_EXIT
    return 0
