"""``launch``: run a node set (see :class:`~tdcm_ros.runtime.graph.NodeGraph`) until a signal.

Nodes start in the order given, on the zenoh runtime after a router if none is reachable.
Per-node parameter ``overrides`` are merged over the parameter file; a node listed in
``ready_paths`` must create that path before the next node starts (e.g. the twin's pty link
before the driver opens it).
SIGINT/SIGTERM to the launcher stops nodes in reverse order, router last.
"""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Mapping, Sequence
from types import FrameType
from typing import Any

from tdcm_ros.runtime.graph import CLEAN_EXITS, NodeGraph, merged_params
from tdcm_ros.runtime.registry import node_target

__all__ = ["launch", "merged_params"]

log = logging.getLogger("tdcm.up")


def report_exits(graph: NodeGraph, reported: set[str]) -> None:
    """Log each node that exited on its own since the last call (once per node)."""
    for child in graph.children:
        if not child.running and child.name not in reported:
            reported.add(child.name)
            status = child.process.returncode
            level = logging.WARNING if status in CLEAN_EXITS else logging.ERROR
            log.log(level, "node %s exited with status %s while the graph runs; the other "
                    "nodes go on", child.name, status)


def launch(nodes: Sequence[str], *, params_file: str | None = None, runtime: str = "zenoh",
           endpoint: str | None = None, grace: float = 5.0,
           overrides: Mapping[str, Mapping[str, Any]] | None = None,
           ready_paths: Mapping[str, str] | None = None, ready_timeout: float = 30.0,
           start_router: bool = True) -> int:
    """Run ``nodes`` (registry names) until SIGINT/SIGTERM or until every node has exited.

    ``endpoint``: the zenoh router's (``None`` on rclpy); ``grace``: s from SIGINT to SIGKILL of
    a node; ``overrides``: node name -> parameter values over ``params_file``; ``ready_paths``:
    node name -> path it creates when ready (waited for, ``ready_timeout`` s, before the next
    node); ``start_router``: False to use only an existing router at ``endpoint`` (fails if
    none answers within 10 s).
    """
    for name in nodes:
        node_target(name)  # unknown names fail before anything starts
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        # set from another thread: Event.set here could wait forever for the event's lock,
        # held by this (main) thread when the signal lands inside stop.wait
        threading.Thread(target=stop.set, daemon=True).start()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    overrides, ready_paths = overrides or {}, ready_paths or {}
    graph = NodeGraph(endpoint=endpoint, runtime=runtime, params_file=params_file, grace=grace,
                      stop_event=stop)
    try:
        graph.ensure_router(start=start_router)
        for name in nodes:
            if stop.is_set():
                break
            graph.start_node(name, overrides=overrides.get(name),
                             ready_path=ready_paths.get(name), ready_timeout=ready_timeout)
        reported: set[str] = set()
        while not stop.wait(0.2):
            report_exits(graph, reported)
            if all(not c.running for c in graph.children):
                log.warning("every node has exited")
                break
    finally:
        graph.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return 1 if graph.failed() else 0
