"""``launch``: run a node set (see :class:`~tdcm_ros.runtime.graph.NodeGraph`) until a signal.

Nodes start in the order given, on the zenoh runtime after a router if none is reachable.
Per-node parameter ``overrides`` are merged over the parameter file; a node listed in
``ready_paths`` must create that path before the next node starts (e.g. the twin's pty link
before the driver opens it).
SIGINT/SIGTERM to the launcher stops nodes in reverse order, router last. The router it started
is watched: its exit is logged as an error and, with ``on_router_exit="restart"`` (the default),
it is started again on the same endpoint (the nodes' sessions reconnect to it); with ``"stop"``
the graph stops and the launcher exits 1. While no router runs, every zenoh node is cut off:
``tension_driver`` releases the tendon after ``safety.graph_timeout_s`` and stays disarmed.
"""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Mapping, Sequence
from types import FrameType
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.errors import RuntimePortError
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


ROUTER_EXIT_ACTIONS = ("restart", "stop")


def watch_router(graph: NodeGraph, on_exit: str) -> bool:
    """If the router the graph started has exited: log it, then restart it (True) or, with
    ``on_exit="stop"`` or when it does not come up again, say the graph must stop (False)."""
    router = graph.router
    if router is None or router.running:
        return True
    log.error("the zenoh router at %s exited with status %s; every zenoh node is cut off (the "
              "tension driver releases the tendon after safety.graph_timeout_s)", graph.endpoint,
              router.process.returncode)
    if on_exit == "stop":
        log.error("stopping the graph (--on-router-exit stop)")
        return False
    try:
        graph.restart_router()
    except RuntimePortError as error:
        log.error("%s; stopping the graph", error)
        return False
    log.warning("zenoh router restarted at %s (restart %d); the nodes reconnect, a disarmed "
                "driver needs clear_faults", graph.endpoint, graph.router_restarts)
    return True


def launch(nodes: Sequence[str], *, params_file: str | None = None, runtime: str = "zenoh",
           endpoint: str | None = None, grace: float = 5.0,
           overrides: Mapping[str, Mapping[str, Any]] | None = None,
           ready_paths: Mapping[str, str] | None = None, ready_timeout: float = 30.0,
           start_router: bool = True, on_router_exit: str = "restart", namespace: str = "/") -> int:
    """Run ``nodes`` (registry names) until SIGINT/SIGTERM or until every node has exited.

    ``endpoint``: the zenoh router's (``None`` on rclpy); ``grace``: s from SIGINT to SIGTERM
    and from SIGTERM to SIGKILL of a node (as launch's ``sigterm_timeout``,
    ``sigkill_timeout``); ``overrides``: node name -> parameter values over ``params_file``;
    ``ready_paths``: node name -> path it creates when ready (waited for, ``ready_timeout`` s,
    before the next node); ``start_router``: False to use only an existing router at
    ``endpoint`` (fails if none answers within 10 s); ``on_router_exit``: ``restart`` or
    ``stop`` (see the module); ``namespace``: every node's (two robots share one graph, each
    in its own).
    """
    if on_router_exit not in ROUTER_EXIT_ACTIONS:
        raise InputError(f"on_router_exit = {on_router_exit!r} is not one of "
                         f"{', '.join(ROUTER_EXIT_ACTIONS)}", parameter="on_router_exit",
                         value=on_router_exit, allowed=", ".join(ROUTER_EXIT_ACTIONS))
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
                      stop_event=stop, namespace=namespace)
    try:
        graph.ensure_router(start=start_router)
        graph.check_peers_connect()
        for name in nodes:
            if stop.is_set():
                break
            graph.start_node(name, overrides=overrides.get(name),
                             ready_path=ready_paths.get(name), ready_timeout=ready_timeout)
        reported: set[str] = set()
        router_lost = False
        while not stop.wait(0.2):
            if not watch_router(graph, on_router_exit):
                router_lost = True
                break
            report_exits(graph, reported)
            if all(not c.running for c in graph.children):
                log.warning("every node has exited")
                break
    finally:
        graph.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return 1 if graph.failed() or router_lost else 0
