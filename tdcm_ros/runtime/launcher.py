"""Start a node set as separate processes (plus a zenoh router if none is reachable).

Each child runs ``python -m tdcm_ros.runtime.run_node <module:Class>``, in the order given.
Per-node parameter ``overrides`` are merged over the parameter file into a per-node file in a
temporary directory (removed at exit). A node listed in ``ready_paths`` must create that path
before the next node starts (e.g. the twin's pty link before the driver opens it); a symlink left
there at exit (the node was killed) is removed. SIGINT/SIGTERM to the launcher stops nodes in
reverse order, router last: SIGINT, then SIGKILL after ``grace`` seconds. Children run in their
own sessions and, on Linux, get SIGTERM if the launcher dies (``PR_SET_PDEATHSIG``).
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
from types import FrameType
from typing import Any

import yaml

from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.names import fully_qualified_node_name
from tdcm_ros.runtime.params import ROS_PARAMETERS, node_parameters
from tdcm_ros.runtime.registry import node_target

log = logging.getLogger("tdcm.up")
_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)


@dataclass
class Child:
    """A started process and the name shown in logs."""

    name: str
    process: subprocess.Popen[bytes]


def _spawn(name: str, argv: list[str]) -> Child:
    log.info("starting %s: %s", name, " ".join(argv))
    process = subprocess.Popen(argv, start_new_session=True, preexec_fn=_die_with_parent)  # noqa: PLW1509
    return Child(name, process)


def _stop(child: Child, grace: float) -> None:
    if child.process.poll() is None:
        child.process.send_signal(signal.SIGINT)
        try:
            child.process.wait(grace)
        except subprocess.TimeoutExpired:
            log.warning("%s ignored SIGINT for %.1f s; killing it", child.name, grace)
            child.process.kill()
            child.process.wait()
    log.info("%s exited with %s", child.name, child.process.returncode)


def _wait_listening(endpoint: str, router: Child, timeout: float) -> None:
    from tdcm_ros.runtime.router import is_listening

    deadline = time.monotonic() + timeout
    while not is_listening(endpoint):
        if router.process.poll() is not None or time.monotonic() > deadline:
            raise RuntimePortError(f"zenoh router did not come up on {endpoint}")
        time.sleep(0.05)


def merged_params(folder: Path, name: str, params_file: str | None,
                  overrides: Mapping[str, Any]) -> str:
    """Write node ``name``'s parameters from ``params_file`` with ``overrides`` on top; the path."""
    fqn = fully_qualified_node_name("/", name)
    values = {**node_parameters(params_file, fqn), **overrides}
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump({fqn: {ROS_PARAMETERS: values}}), encoding="utf-8")
    return str(path)


def _wait_ready(child: Child, path: str, timeout: float, stop: threading.Event) -> None:
    deadline = time.monotonic() + timeout
    while not os.path.lexists(path):
        if child.process.poll() is not None:
            raise RuntimePortError(f"{child.name} exited ({child.process.returncode}) before "
                                   f"creating {path}")
        if time.monotonic() > deadline:
            raise RuntimePortError(f"{child.name} did not create {path} within {timeout:g} s")
        if stop.wait(0.05):
            return


def launch(nodes: Sequence[str], *, params_file: str | None = None, runtime: str = "zenoh",
           endpoint: str, grace: float = 5.0,
           overrides: Mapping[str, Mapping[str, Any]] | None = None,
           ready_paths: Mapping[str, str] | None = None, ready_timeout: float = 30.0) -> int:
    """Run ``nodes`` (registry names) until SIGINT/SIGTERM or until every node has exited.

    ``overrides``: node name -> parameter values over ``params_file``; ``ready_paths``: node
    name -> path it creates when ready (waited for, ``ready_timeout`` s, before the next node).
    """
    from tdcm_ros.runtime.router import is_listening

    targets = [(name, node_target(name)) for name in nodes]
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    router: Child | None = None
    children: list[Child] = []
    overrides, ready_paths = overrides or {}, ready_paths or {}
    folder = tempfile.TemporaryDirectory(prefix="tdcm_up_")
    try:
        if runtime == "zenoh" and not is_listening(endpoint):
            router = _spawn("router", [sys.executable, "-m", "tdcm_ros.runtime.router",
                                       "--listen", endpoint])
            _wait_listening(endpoint, router, timeout=10.0)
        for name, target in targets:
            if stop.is_set():
                break
            argv = [sys.executable, "-m", "tdcm_ros.runtime.run_node", target, "--name", name,
                    "--runtime", runtime]
            params = (merged_params(Path(folder.name), name, params_file, overrides[name])
                      if name in overrides else params_file)
            if params:
                argv += ["--params", params]
            children.append(_spawn(name, argv))
            if name in ready_paths:
                _wait_ready(children[-1], ready_paths[name], ready_timeout, stop)
        while not stop.wait(0.2):
            if all(c.process.poll() is not None for c in children):
                log.warning("every node has exited")
                break
    finally:
        for child in reversed(children):
            _stop(child, grace)
        if router is not None:
            _stop(router, grace)
        for path in ready_paths.values():
            if os.path.islink(path):
                os.unlink(path)
        folder.cleanup()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    failed = [c.name for c in children if c.process.returncode not in (0, -signal.SIGINT, 130)]
    return 1 if failed and not stop.is_set() else 0
