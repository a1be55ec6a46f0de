"""Fixtures for multi-process tests over the embedded runtime: free ports, router, nodes."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def listening(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.2):
            return True
    except OSError:
        return False


def wait_for(predicate: Callable[[], bool], timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)


def stop(process: subprocess.Popen[bytes], timeout: float = 10.0) -> int:
    """SIGINT, then wait; returns the exit status."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    return process.wait(timeout)


@pytest.fixture
def zenoh_env(monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    """Environment (also applied to this process) pointing at a private router port."""
    pytest.importorskip("zenoh", reason="eclipse-zenoh not installed")
    port = free_port()
    monkeypatch.setenv("TDCM_ZENOH_ENDPOINT", f"tcp/127.0.0.1:{port}")
    monkeypatch.setenv("TDCM_RUNTIME", "zenoh")
    monkeypatch.setenv("ROS_DOMAIN_ID", "0")
    monkeypatch.delenv("TDCM_ZENOH_CONFIG", raising=False)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])]))
    return {**os.environ, "ZENOH_TEST_PORT": str(port)}


@pytest.fixture
def spawn(zenoh_env: dict[str, str]) -> Iterator[Callable[..., subprocess.Popen[bytes]]]:
    """Start ``python -m <args>`` children; every one is stopped at teardown."""
    children: list[subprocess.Popen[bytes]] = []

    def start(*args: str) -> subprocess.Popen[bytes]:
        child = subprocess.Popen([sys.executable, "-m", *args], env=zenoh_env, cwd=REPO,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        children.append(child)
        return child

    yield start
    for child in children:
        if child.poll() is None:
            child.kill()
            child.wait()


@pytest.fixture
def router(zenoh_env: dict[str, str], spawn: Callable[..., subprocess.Popen[bytes]]
           ) -> Iterator[subprocess.Popen[bytes]]:
    """A zenoh router (tdcm_ros.runtime.router) on the private port."""
    port = int(zenoh_env["ZENOH_TEST_PORT"])
    process = spawn("tdcm_ros.runtime.router", "--listen", f"tcp/127.0.0.1:{port}")
    wait_for(lambda: listening(port), 10.0, "the router")
    yield process
    stop(process)
