"""Fixtures for multi-process node tests on both runtimes (a plugin of test/conftest.py).

``runtime`` runs a test twice: on the embedded zenoh runtime (a router on a private loopback
port) and on rclpy (a private ``ROS_DOMAIN_ID``, discovery on this host only). Nodes started with
``spawn`` pick the runtime up from ``TDCM_RUNTIME``; ``context`` is the test's own peer on that
runtime (a zenoh context, or plain rclpy nodes); ``params`` is a client of a node's
rcl_interfaces parameter services (the package's, or rclpy's ``AsyncParameterClient``). The rclpy half is marked ``rclpy``; where rclpy is not
importable it is skipped, unless ``TDCM_REQUIRE_RCLPY=1`` (CI's ROS step), where that fails.
"""

from __future__ import annotations

import dataclasses
import itertools
import os
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from test.support.processes import REPO, Lines, child_env, free_port, stop
from test.support.waiting import eventually, scaled

#: Seconds (scaled) a child still running at teardown has to exit after SIGINT before it is
#: killed.
TEARDOWN_STOP_S = 5.0

RUNTIMES = ["zenoh", pytest.param("rclpy", marks=pytest.mark.rclpy)]
_domains = itertools.count()
#: ROS domain ids the tests use: 1..100 (Linux keeps DDS ports below the ephemeral range up to
#: domain 101; ``.ci/ros.sh``'s own node uses 101). Each xdist worker owns a block of them.
DOMAINS = 100
BLOCK = 25


def private_domain_id() -> int:
    """A ROS domain id in 1..100 that differs between the tests of a run: worker ``gwN`` takes
    from block ``N`` (of :data:`BLOCK` ids), shifted by the run's id so that two runs on one
    machine rarely meet."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker[2:].isdigit() else 0
    run = int(os.environ.get("PYTEST_XDIST_TESTRUNUID", "0")[:8] or "0", 16)
    return 1 + (run + index * BLOCK + next(_domains) % BLOCK) % DOMAINS


def require_rclpy() -> None:
    """Skip without rclpy, or fail when ``TDCM_REQUIRE_RCLPY=1``."""
    try:
        import rclpy  # noqa: F401
    except ImportError as error:
        if os.environ.get("TDCM_REQUIRE_RCLPY") == "1":
            pytest.fail(f"TDCM_REQUIRE_RCLPY=1 but rclpy is not importable: {error}")
        pytest.skip("rclpy is not importable (no ROS 2 Jazzy); run .ci/ros.sh for the rclpy half")


def _base_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("TDCM_ZENOH_CONFIG", raising=False)
    monkeypatch.setenv("PYTHONPATH", child_env()["PYTHONPATH"])


@pytest.fixture
def zenoh_env(monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    """Environment (also applied to this process) pointing at a private router port."""
    port = free_port()
    monkeypatch.setenv("TDCM_ZENOH_ENDPOINT", f"tcp/127.0.0.1:{port}")
    monkeypatch.setenv("TDCM_RUNTIME", "zenoh")
    monkeypatch.setenv("ROS_DOMAIN_ID", "0")
    _base_env(monkeypatch)
    return {**os.environ, "ZENOH_TEST_PORT": str(port)}


@pytest.fixture(params=RUNTIMES)
def runtime(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """``zenoh`` or ``rclpy``; sets the environment the test and its children share."""
    if request.param == "rclpy":
        require_rclpy()
        monkeypatch.setenv("TDCM_RUNTIME", "rclpy")
        monkeypatch.setenv("ROS_DOMAIN_ID", str(private_domain_id()))
        monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        _base_env(monkeypatch)
    else:
        request.getfixturevalue("router")
    return str(request.param)


@pytest.fixture
def graph_env(runtime: str) -> dict[str, str]:
    """The environment of the chosen runtime, for children."""
    return dict(os.environ)


def _spawner(env: dict[str, str], item: pytest.Item
             ) -> Iterator[Callable[..., subprocess.Popen[bytes]]]:
    children: list[subprocess.Popen[bytes]] = []

    def start(*args: str) -> subprocess.Popen[bytes]:
        child = subprocess.Popen([sys.executable, "-m", *args], env=env, cwd=REPO,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        children.append(child)
        return child

    yield start
    failed = getattr(item, "report_call", None) is not None and item.report_call.failed
    for child in children:
        running = child.poll() is None
        state = f"exited {child.returncode}"
        if running:
            # SIGINT first, so that a node leaves the graph as it does when stopped, before
            # the test's own peer is torn down (a killed DDS participant is noticed by the
            # others later, on their threads); killed only if it does not exit
            child.send_signal(signal.SIGINT)
            state = "stopped at teardown (SIGINT)"
        try:
            _, err = child.communicate(timeout=scaled(TEARDOWN_STOP_S) if running else None)
        except subprocess.TimeoutExpired:
            child.kill()
            state = f"killed at teardown ({scaled(TEARDOWN_STOP_S):g} s after SIGINT)"
            _, err = child.communicate()
        except ValueError:  # the test closed a pipe it had read
            err = b""
            try:
                child.wait(scaled(TEARDOWN_STOP_S) if running else None)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait()
        if failed:  # what each child said, in the failure's report (teardown output)
            tail = (err or b"")[-2000:].decode(errors="replace")
            print(f"--- {' '.join(map(str, child.args[2:]))} ({state}); stderr ends:\n{tail}")


@pytest.fixture
def spawn(request: pytest.FixtureRequest) -> Iterator[Callable[..., subprocess.Popen[bytes]]]:
    """Start ``python -m <args>`` children (runtime of the test, else zenoh); stopped at teardown."""
    name = "graph_env" if "runtime" in request.fixturenames else "zenoh_env"
    yield from _spawner(request.getfixturevalue(name), request.node)


ROUTER_ATTEMPTS = 3


def start_router(port: int, env: dict[str, str]) -> tuple[subprocess.Popen[bytes], Lines]:
    """A zenoh router (tdcm_ros.runtime.router) on 127.0.0.1:``port``, waited for until it says
    it listens or exits: known by its own line, not merely by something accepting on the port.
    A port :func:`free_port` found free can be taken before the router binds it (by another
    test's zenoh peer, on a random loopback port); the router then exits ("Address already in
    use") while the port accepts, and a peer would join a foreign graph."""
    process = subprocess.Popen([sys.executable, "-m", "tdcm_ros.runtime.router", "--listen",
                                f"tcp/127.0.0.1:{port}"], env=env, cwd=REPO,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    err = Lines(process, "stderr")
    # a loaded machine starts slowly
    eventually(lambda: err.has("tdcm_router: listening on") or process.poll() is not None,
               30.0, "the router", detail=err.tail)
    return process, err


@pytest.fixture
def router(zenoh_env: dict[str, str], monkeypatch: pytest.MonkeyPatch
           ) -> Iterator[subprocess.Popen[bytes]]:
    """A router from :func:`start_router` on the private port; one that exited (its port was
    taken, a query of the foreign graph then ended early with part of its replies) is replaced
    on another port (at most :data:`ROUTER_ATTEMPTS`), in ``zenoh_env`` and the environment."""
    pytest.importorskip("zenoh", reason="eclipse-zenoh not installed")
    for _ in range(ROUTER_ATTEMPTS):
        process, err = start_router(int(zenoh_env["ZENOH_TEST_PORT"]), zenoh_env)
        if process.poll() is None:
            break
        port = free_port()
        monkeypatch.setenv("TDCM_ZENOH_ENDPOINT", f"tcp/127.0.0.1:{port}")
        zenoh_env.update(TDCM_ZENOH_ENDPOINT=f"tcp/127.0.0.1:{port}", ZENOH_TEST_PORT=str(port))
    else:
        pytest.fail(f"no router could listen in {ROUTER_ATTEMPTS} attempts:\n{err.tail()}")
    try:
        yield process
    finally:
        if process.poll() is None:
            stop(process)


@pytest.fixture
def context(request: pytest.FixtureRequest) -> Iterator[Any]:
    """The test's own peer on the test's runtime (zenoh when the test has no ``runtime``)."""
    if "runtime" in request.fixturenames and request.getfixturevalue("runtime") == "rclpy":
        from test.support.plain_rclpy import PlainRclpyContext

        ctx: Any = PlainRclpyContext()
    else:
        request.getfixturevalue("router")
        from tdcm_ros.runtime.zenoh_runtime import ZenohContext

        ctx = ZenohContext()
    yield ctx
    ctx.close()


class ServiceParameterClient:
    """The package's client of the rcl_interfaces parameter services (what ``tdcm param``
    uses), in the same shape as the rclpy one."""

    def __init__(self, ctx: Any, node_fqn: str, timeout: float = 15.0) -> None:
        from tdcm_ros.runtime.param_client import ParameterClient

        self.client = ParameterClient(ctx, node_fqn, timeout)

    def get(self, name: str) -> Any:
        return self.client.get(name)

    def set(self, name: str, value: Any) -> dict[str, Any]:
        return dataclasses.asdict(self.client.set(name, value))

    def names(self) -> list[str]:
        return self.client.names()

    def describe(self, name: str) -> Any:
        return self.client.describe([name])[0]


@pytest.fixture
def params(context: Any) -> Callable[[str], Any]:
    """``params("/node")``: a parameter client of that node on the test's runtime."""
    from test.support.plain_rclpy import PlainParameterClient, PlainRclpyContext

    def client(node_fqn: str) -> Any:
        if isinstance(context, PlainRclpyContext):
            return PlainParameterClient(context, node_fqn)
        return ServiceParameterClient(context, node_fqn)

    return client
