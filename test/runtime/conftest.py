"""Fixtures for multi-process tests over the embedded runtime: free ports, router, nodes."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from runtime_helpers import free_port, listening, stop, wait_for

REPO = Path(__file__).resolve().parents[2]


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
