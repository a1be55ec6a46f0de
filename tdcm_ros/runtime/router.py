"""A zenoh router for the embedded runtime (stands in for ``ros2 run rmw_zenoh_cpp rmw_zenohd``).

``python -m tdcm_ros.runtime.router [--listen tcp/127.0.0.1:7447] [--config router.json5]``; runs
until SIGINT/SIGTERM. ``--config`` (or ``TDCM_ZENOH_ROUTER_CONFIG``, else ``TDCM_ZENOH_CONFIG``)
names a zenoh JSON5 file, e.g. ``config/zenoh/router.json5`` (TLS, user/password, access control);
the router listens on ``--listen`` whatever the file says. Listening beyond loopback without
authentication logs a warning.

Exit on a signal is guaranteed: the handler only sets a flag (no lock: a ``threading.Event.set``
in a handler deadlocks when the signal lands while the main thread holds the event's lock inside
``Event.wait``), and a session that does not close within :data:`CLOSE_TIMEOUT_S` s (zenoh
waiting on its connected clients) is abandoned: the process flushes its output and leaves with
``os._exit``.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from collections.abc import Sequence
from types import FrameType

from tdcm_ros.errors import TdcmError
from tdcm_ros.runtime.run_node import configure_logging
from tdcm_ros.runtime.shutdown import close_within, exit_now
from tdcm_ros.runtime.zenoh_config import ROUTER_CONFIG_ENV, warn_if_exposed
from tdcm_ros.runtime.zenoh_runtime import endpoint, open_session, session_config

#: Longest wait (s) for the zenoh session to close after a signal before the process leaves.
CLOSE_TIMEOUT_S = 3.0
#: Longest time (s) between a signal and the main loop seeing it.
POLL_S = 0.1


def main(argv: Sequence[str] | None = None) -> int:
    """Run a router on ``--listen`` (default ``TDCM_ZENOH_ENDPOINT`` or tcp/127.0.0.1:7447)."""
    parser = argparse.ArgumentParser(prog="tdcm_router", description=__doc__.splitlines()[0])
    parser.add_argument("--listen", default=None, help="endpoint, e.g. tcp/127.0.0.1:7447")
    parser.add_argument("--config", default=None,
                        help=f"zenoh JSON5 config of the router (sets {ROUTER_CONFIG_ENV})")
    args = parser.parse_args(argv)
    configure_logging()
    if args.config:
        os.environ[ROUTER_CONFIG_ENV] = args.config
    listen = args.listen or endpoint()
    # A list, not a threading.Event: the handler runs on the main thread between two bytecodes,
    # possibly while the main thread holds an Event's lock in Event.wait, and Event.set would
    # then wait for that lock forever (the router's hang after SIGINT).
    signals: list[int] = []

    def on_signal(signum: int, frame: FrameType | None) -> None:
        signals.append(signum)

    # Before the session opens: the router accepts connections while open_session is still
    # running, so a client may signal it then; a KeyboardInterrupt there would leave an open
    # session whose threads keep the process from exiting (seen on eclipse-zenoh 1.5.0 under load).
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_signal)
    try:
        warn_if_exposed(session_config(mode="router", router_endpoint=listen), "router")
        session = open_session(mode="router", router_endpoint=listen)
    except TdcmError as error:
        print(f"tdcm_router: {error}", file=sys.stderr)
        return error.exit_code
    print(f"tdcm_router: listening on {listen} (zid {session.zid()})", file=sys.stderr,
          flush=True)
    while not signals:
        time.sleep(POLL_S)
    if not close_within(session.close, CLOSE_TIMEOUT_S):
        print(f"tdcm_router: the session did not close within {CLOSE_TIMEOUT_S:g} s; exiting "
              f"without it", file=sys.stderr)
        exit_now(0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
