"""A node graph as child processes: nodes, helper processes and, on the zenoh runtime, a router
if none is reachable (rclpy nodes discover each other; nothing here imports zenoh for them).

Each node runs ``python -m tdcm_ros.runtime.run_node <module:Class>``. Per-node parameter
overrides are merged over the parameter file into a per-node file in a temporary directory.
A node given a ``ready_path`` must create it before :meth:`NodeGraph.start_node` returns (e.g. the
twin's pty link before the driver opens it); a symlink left there at exit is removed. Stopping
goes in reverse start order, router last: SIGINT, then SIGTERM after ``grace`` seconds, then
SIGKILL after ``grace`` seconds more (as ROS 2 launch's ``sigterm_timeout`` and
``sigkill_timeout``, 5 s each by default). Children
run in their own sessions and, on Linux, get SIGTERM if the parent dies (``PR_SET_PDEATHSIG``).
"""

from __future__ import annotations

import ctypes
import logging
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.names import fully_qualified_node_name, normalize_namespace
from tdcm_ros.runtime.params import node_parameters, param_file_text
from tdcm_ros.runtime.registry import node_target

log = logging.getLogger("tdcm.graph")
_PR_SET_PDEATHSIG = 1
#: Exit statuses of a child that stopped because it was asked to (SIGINT, or SIGTERM after it).
CLEAN_EXITS = (0, -signal.SIGINT, 130, -signal.SIGTERM, 143)


def _die_with_parent() -> None:
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)


@dataclass
class Child:
    """A started process and the name shown in logs."""

    name: str
    process: subprocess.Popen[bytes]

    @property
    def running(self) -> bool:
        """True until the process exits."""
        return self.process.poll() is None


def merged_params(folder: Path, name: str, params_file: str | None,
                  overrides: Mapping[str, Any], namespace: str = "/") -> str:
    """Write node ``namespace/name``'s parameters from ``params_file`` with ``overrides`` on
    top; the path."""
    fqn = fully_qualified_node_name(namespace, name)
    values = {**node_parameters([params_file] if params_file else [], fqn), **overrides}
    path = folder / f"{name}.yaml"
    path.write_text(param_file_text({fqn: values}), encoding="utf-8")
    return str(path)


class NodeGraph:
    """Start nodes and processes in order; :meth:`close` stops them all.

    ``log_dir``, when set, receives each child's stdout and stderr as ``<name>.log``; otherwise
    children share the terminal. ``stop_event`` aborts waits for ready paths. ``endpoint`` is the
    zenoh router's (``None`` on rclpy). Every node starts in ``namespace`` (its relative topics
    and private services resolve there; its parameter file entries are looked up by
    ``namespace/name``).
    """

    def __init__(self, *, endpoint: str | None = None, runtime: str = "zenoh",
                 params_file: str | None = None, grace: float = 5.0, log_dir: Path | None = None,
                 stop_event: threading.Event | None = None, namespace: str = "/") -> None:
        self.endpoint = endpoint
        self.runtime = runtime
        self.namespace = normalize_namespace(namespace)
        self.params_file = params_file
        self.grace = grace
        self.log_dir = log_dir
        self.stop_event = stop_event or threading.Event()
        self.children: list[Child] = []
        self.router: Child | None = None
        self.router_restarts = 0
        self._ready_paths: list[str] = []
        self._logs: list[IO[bytes]] = []
        self._folder = tempfile.TemporaryDirectory(prefix="tdcm_graph_")

    def start(self, name: str, argv: Sequence[str]) -> Child:
        """Start ``argv`` as child ``name``."""
        log.info("starting %s: %s", name, " ".join(argv))
        output: IO[bytes] | None = None
        if self.log_dir is not None:
            output = open(self.log_dir / f"{name}.log", "wb")  # noqa: SIM115 - closed in close()
            self._logs.append(output)
        # A process group of its own: a terminal's Ctrl-C reaches the launcher only, which stops
        # the children in order. This session, not one of its own: where the kernel shares CPU
        # time between sessions first (autogroup), a node alone in its session is a light group
        # that waited up to 0.6 s for a CPU beside a busy one (the driver's heartbeat, measured
        # as run-queue wait in /proc/<pid>/task/<tid>/schedstat; the device's watchdog is 0.5 s),
        # and a niced build beside the graph competed as an equal. A node never reads stdin.
        process = subprocess.Popen(
            list(argv), process_group=0, stdin=subprocess.DEVNULL,
            preexec_fn=_die_with_parent,  # noqa: PLW1509 - it only calls prctl
            stdout=output, stderr=output)
        child = Child(name, process)
        self.children.append(child)
        return child

    def ensure_router(self, timeout: float = 10.0, *, start: bool = True) -> None:
        """Start a router on ``endpoint`` unless one already answers there (zenoh runtime only;
        ``timeout`` in s). With ``start=False`` (an existing router, e.g. a ROS machine's
        ``rmw_zenohd``) wait up to ``timeout`` for it to answer and never start one."""
        if self.runtime != "zenoh":
            return
        from tdcm_ros.runtime.zenoh_diagnosis import is_listening

        endpoint = self.endpoint
        if endpoint is None:
            raise RuntimePortError("the zenoh runtime needs a router endpoint")
        if not start:
            deadline = time.monotonic() + timeout
            while not is_listening(endpoint):
                if time.monotonic() > deadline or self.stop_event.is_set():
                    raise RuntimePortError(
                        f"no zenoh router answers at {endpoint} after {timeout:g} s (--connect "
                        "starts none: start rmw_zenohd or tdcm's router there, or use --endpoint "
                        "to let tdcm up start one)")
                time.sleep(0.1)
            log.info("connecting to the existing zenoh router at %s", endpoint)
            return
        if is_listening(endpoint):
            return
        self._start_router(endpoint, timeout)

    def check_peers_connect(self) -> None:
        """On zenoh with a config file (``TDCM_ZENOH_CONFIG``), open a peer session as the nodes
        will: ``RuntimePortError`` naming the cause if it reaches no router (a missing file, the
        router's certificate, the password), before any node starts."""
        if self.runtime != "zenoh":
            return
        from tdcm_ros.runtime.zenoh_runtime import CONFIG_ENV, open_session

        if os.environ.get(CONFIG_ENV):
            open_session(router_endpoint=self.endpoint).close()

    def restart_router(self, timeout: float = 10.0) -> None:
        """Start the router again on the endpoint after it exited (``RuntimePortError`` if it
        does not answer within ``timeout`` s)."""
        if self.endpoint is None or self.router is None:
            raise RuntimePortError("no router of this graph to restart")
        self.router_restarts += 1
        self._start_router(self.endpoint, timeout)

    def _start_router(self, endpoint: str, timeout: float) -> None:
        from tdcm_ros.runtime.zenoh_diagnosis import is_listening

        self.router = self.start("router", [sys.executable, "-m", "tdcm_ros.runtime.router",
                                            "--listen", endpoint])
        self.children.remove(self.router)
        deadline = time.monotonic() + timeout
        while not is_listening(endpoint):
            if not self.router.running or time.monotonic() > deadline:
                raise RuntimePortError(f"zenoh router did not come up on {endpoint}")
            time.sleep(0.05)

    def start_node(self, name: str, *, overrides: Mapping[str, Any] | None = None,
                   ready_path: str | None = None, ready_timeout: float = 30.0) -> Child:
        """Start registered node ``name``; with ``ready_path``, wait until the node creates it."""
        argv = [sys.executable, "-m", "tdcm_ros.runtime.run_node", node_target(name), "--name",
                name, "--namespace", self.namespace, "--runtime", self.runtime]
        params = (merged_params(Path(self._folder.name), name, self.params_file, overrides,
                                self.namespace) if overrides else self.params_file)
        if params:
            argv += ["--params", params]
        child = self.start(name, argv)
        if ready_path is not None:
            self._ready_paths.append(ready_path)
            self._wait_ready(child, ready_path, ready_timeout)
        return child

    def _wait_ready(self, child: Child, path: str, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        while not os.path.lexists(path):
            if not child.running:
                raise RuntimePortError(f"{child.name} exited ({child.process.returncode}) before "
                                       f"creating {path}")
            if time.monotonic() > deadline:
                raise RuntimePortError(f"{child.name} did not create {path} within {timeout:g} s")
            if self.stop_event.wait(0.05):
                return

    def stop(self, child: Child) -> int:
        """Stop one child as ROS 2 launch does: SIGINT, SIGTERM after ``grace`` s, SIGKILL
        after ``grace`` s more; its exit status."""
        for signum, then in ((signal.SIGINT, "sending SIGTERM"), (signal.SIGTERM, "killing it")):
            if not child.running:
                break
            child.process.send_signal(signum)
            try:
                child.process.wait(self.grace)
            except subprocess.TimeoutExpired:
                log.warning("%s still running %.1f s after %s; %s", child.name, self.grace,
                            signal.Signals(signum).name, then)
        if child.running:
            child.process.kill()
            child.process.wait()
        log.info("%s exited with %s", child.name, child.process.returncode)
        return int(child.process.returncode)

    def failed(self) -> list[Child]:
        """Children that exited with a status other than a clean stop."""
        return [c for c in self.children
                if not c.running and c.process.returncode not in CLEAN_EXITS]

    def close(self) -> None:
        """Stop every child newest first, then the router; remove leftovers."""
        for child in reversed(self.children):
            self.stop(child)
        if self.router is not None:
            self.stop(self.router)
        for path in self._ready_paths:
            if os.path.islink(path):
                os.unlink(path)
        for handle in self._logs:
            handle.close()
        self._logs.clear()
        self._folder.cleanup()
