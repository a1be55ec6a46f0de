"""The ``--runtime`` option shared by the commands that join a live graph."""

from __future__ import annotations

import argparse
import os

from tdcm_ros.runtime.run_node import RUNTIME_ENV, RUNTIMES


def add_runtime_option(parser: argparse.ArgumentParser, what: str, note: str = "") -> None:
    """Add ``--runtime zenoh|rclpy|auto`` to ``parser``: the runtime of ``what`` (e.g. "the
    graph to record"), default ``TDCM_RUNTIME``, else zenoh; ``note`` is appended to the help."""
    parser.add_argument("--runtime", choices=RUNTIMES,
                        default=os.environ.get(RUNTIME_ENV) or "zenoh",
                        help=f"runtime of {what} (default: {RUNTIME_ENV}, else zenoh; auto: rclpy "
                             f"if importable){note}")
