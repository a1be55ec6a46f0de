"""A zenoh router for the embedded runtime (stands in for ``ros2 run rmw_zenoh_cpp rmw_zenohd``).

``python -m tdcm_ros.runtime.router [--listen tcp/127.0.0.1:7447]``; runs until SIGINT/SIGTERM.
"""

from __future__ import annotations

import argparse
import signal
import socket
import sys
import threading
from collections.abc import Sequence
from types import FrameType

from tdcm_ros.errors import InputError, TdcmError
from tdcm_ros.runtime.zenoh_runtime import endpoint, open_session


def tcp_address(locator: str) -> tuple[str, int]:
    """``(host, port)`` of a ``tcp/host:port`` locator."""
    proto, _, address = locator.partition("/")
    host, _, port = address.rpartition(":")
    if proto != "tcp" or not host or not port.isdigit():
        raise InputError(f"endpoint {locator!r} is not tcp/<host>:<port>", parameter="endpoint",
                         value=locator, allowed="tcp/<host>:<port>")
    return host.strip("[]"), int(port)


def is_listening(locator: str, timeout: float = 0.5) -> bool:
    """True if something accepts TCP connections at the locator."""
    try:
        with socket.create_connection(tcp_address(locator), timeout=timeout):
            return True
    except OSError:
        return False


def main(argv: Sequence[str] | None = None) -> int:
    """Run a router on ``--listen`` (default ``TDCM_ZENOH_ENDPOINT`` or tcp/127.0.0.1:7447)."""
    parser = argparse.ArgumentParser(prog="tdcm_router", description=__doc__.splitlines()[0])
    parser.add_argument("--listen", default=None, help="endpoint, e.g. tcp/127.0.0.1:7447")
    args = parser.parse_args(argv)
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_signal)
    try:
        session = open_session(mode="router", router_endpoint=args.listen or endpoint())
    except TdcmError as error:
        print(f"tdcm_router: {error}", file=sys.stderr)
        return error.exit_code
    print(f"tdcm_router: listening on {args.listen or endpoint()} (zid {session.zid()})",
          file=sys.stderr, flush=True)
    while not stop.wait(0.2):
        pass
    session.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
