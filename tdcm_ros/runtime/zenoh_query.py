"""Zenoh queries whose replies are all collected, within a deadline, interruptibly.

Zenoh's default reply handler is a 256-deep channel: a reader that stops early (``any(...)`` over
a domain's liveliness tokens) leaves it full, and zenoh then blocks delivering the next reply, so
with more than ~256 endpoints on a domain every later query of the session hung, and a thread
blocked inside the channel's ``recv`` did not see Ctrl-C. Here a callback takes each reply as it
arrives (up to :data:`MAX_REPLIES`; the rest are counted, not kept), zenoh's ``drop`` hook says when
the query is complete, and the caller waits on an event: at most the query's timeout plus
:data:`GRACE_S`, and a ``KeyboardInterrupt`` ends the wait.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import zenoh

from tdcm_ros.runtime import wire
from tdcm_ros.runtime.errors import RuntimePortError

#: Most replies one query keeps (a liveliness token is ~200 B: ~20 MB at most).
MAX_REPLIES = 100_000
#: How long past its own timeout a query may take to report that it is complete (s).
GRACE_S = 1.0
_LOG = logging.getLogger("tdcm.zenoh")


@dataclass
class Replies:
    """What one query gathered: the replies kept, how many were left out, whether it completed."""

    kept: list[zenoh.Reply] = field(default_factory=list)
    dropped: int = 0
    complete: bool = False


def gather(start: Callable[[zenoh.handlers.Callback], Any], timeout: float,
           limit: int = MAX_REPLIES) -> Replies:
    """Run ``start(handler)`` (a ``get`` given the handler and ``timeout`` s) and wait for its
    replies: until zenoh reports the query complete or ``timeout + GRACE_S`` s have passed."""
    replies = Replies()
    done = threading.Event()

    def take(reply: zenoh.Reply) -> None:
        if len(replies.kept) < limit:
            replies.kept.append(reply)
        else:
            replies.dropped += 1

    # indirect=False: ``take`` runs on zenoh's own thread (it only appends), not behind a queue
    # to a Python thread that a busy machine lets fall behind
    start(zenoh.handlers.Callback(take, done.set, indirect=False))
    replies.complete = done.wait(timeout + GRACE_S)
    if replies.dropped:
        _LOG.warning("a query kept %d replies and left out %d", limit, replies.dropped)
    return replies


def graph_tokens(session: zenoh.Session, domain: int, timeout: float = 1.0,
                 selector: str = "**") -> list[wire.TokenInfo]:
    """The rmw_zenoh liveliness tokens of ``domain`` now whose key after the domain matches
    ``selector`` (default: all; malformed ones skipped)."""
    replies = gather(lambda handler: session.liveliness().get(
        f"{wire.ADMIN_SPACE}/{domain}/{selector}", handler, timeout=timeout), timeout)
    tokens = []
    for reply in replies.kept:
        if reply.ok is None:
            continue
        try:
            tokens.append(wire.parse_token(str(reply.ok.key_expr)))
        except (RuntimePortError, ValueError):
            continue
    return tokens


def servers_of(name: str, type_name: str) -> str:
    """The :func:`graph_tokens` selector of the servers of service ``name`` (absolute) of
    ``type_name``: one reply per server however crowded the domain."""
    return (f"*/*/*/{wire.SERVICE}/*/*/*/{wire.mangle(name)}/{wire.dds_type_name(type_name)}"
            f"/**")
