"""``tdcm up --connect``: the nodes join an existing zenoh router (a ROS machine's ``rmw_zenohd``)
and never start one. The router here is tdcm's own, started with rmw_zenoh's default router
settings (``conformance/rmw_zenoh_router.json5``); a plain zenoh session, using only rmw_zenoh's
key expressions, sees the nodes' liveliness tokens and their data through it."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from test.support.processes import free_port, listening, stop
from test.support.waiting import eventually

zenoh = pytest.importorskip("zenoh", reason="eclipse-zenoh not installed")

REPO = Path(__file__).resolve().parents[2]
RMW_ZENOH_ROUTER = Path(__file__).parent / "conformance" / "rmw_zenoh_router.json5"


def _children(pid: int) -> list[int]:
    """Direct child pids of ``pid`` (Linux /proc)."""
    found = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        children = (task / "children").read_text().split()
        found += [int(c) for c in children]
    return found


def _start(env: dict[str, str], *args: str) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, "-m", *args], env=env, cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


@pytest.fixture
def env(monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    """Children's environment: TDCM_ZENOH_ENDPOINT names a port nobody listens on, so only
    ``--connect`` can lead the nodes to the router."""
    import os

    dead = free_port()
    monkeypatch.setenv("TDCM_ZENOH_ENDPOINT", f"tcp/127.0.0.1:{dead}")
    monkeypatch.delenv("TDCM_ZENOH_CONFIG", raising=False)
    monkeypatch.setenv("PYTHONPATH", str(REPO))
    monkeypatch.setenv("ROS_DOMAIN_ID", "0")
    return dict(os.environ)


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_up_connects_to_a_router_with_rmw_zenohs_defaults_and_starts_none(
        env: dict[str, str]) -> None:
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    router = _start(env, "tdcm_ros.runtime.router", "--listen", endpoint, "--config",
                    str(RMW_ZENOH_ROUTER))
    launcher = None
    session = None
    try:
        eventually(lambda: listening(port), 10.0, "the router")
        launcher = _start(env, "tdcm_ros.cli.main", "up", "--connect", endpoint,
                          "--nodes", "talker")
        eventually(lambda: len(_children(launcher.pid)) == 1, 15.0, "the talker process")
        config = zenoh.Config()
        config.insert_json5("mode", json.dumps("client"))
        config.insert_json5("connect/endpoints", json.dumps([endpoint]))
        session = zenoh.open(config)
        received: list[str] = []
        subscriber = session.declare_subscriber("0/chatter/**",
                                                lambda sample: received.append(str(sample.key_expr)))
        eventually(lambda: bool(received), 20.0, "the talker's data through the router")
        assert received[0].startswith("0/chatter/std_msgs::msg::dds_::String_/RIHS01_")
        tokens = [str(reply.ok.key_expr) for reply in
                  session.liveliness().get("@ros2_lv/0/**", timeout=5.0) if reply.ok]
        assert any("/NN/%/%/talker" in token for token in tokens), tokens
        assert any("/MP/%/%/talker/%chatter/" in token for token in tokens), tokens
        assert len(_children(launcher.pid)) == 1  # the talker only: no router of its own
        subscriber.undeclare()
        launcher.send_signal(signal.SIGINT)
        assert launcher.wait(15) == 0
        assert router.poll() is None  # the existing router outlives the node set
    finally:
        if session is not None:
            session.close()
        if launcher is not None and launcher.poll() is None:
            stop(launcher)
        stop(router)


def test_connect_with_no_router_there_fails_and_starts_nothing(env: dict[str, str]) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    started = time.monotonic()
    result = subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "up", "--connect",
                             endpoint, "--nodes", "talker"], env=env, cwd=REPO,
                            capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 1
    assert f"no zenoh router answers at {endpoint}" in result.stderr
    assert "--connect starts none" in result.stderr
    assert "starting talker" not in result.stderr
    assert time.monotonic() - started < 45.0  # it gives up; it does not hang


def test_connect_and_endpoint_are_exclusive(env: dict[str, str]) -> None:
    result = subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "up", "--connect",
                             "tcp/127.0.0.1:7447", "--endpoint", "tcp/127.0.0.1:7448"],
                            env=env, cwd=REPO, capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 2
    assert "not allowed with argument" in result.stderr


class _FakeSession:
    """A router session whose ``close`` blocks until released (zenoh waiting on its clients)."""

    def __init__(self, close_blocks: bool = False) -> None:
        import threading

        self.released = threading.Event()
        self.closed = False
        self.close_blocks = close_blocks

    def zid(self) -> str:
        return "fake"

    def close(self) -> None:
        if self.close_blocks:
            self.released.wait()
        self.closed = True


class _Exited(Exception):
    pass


def _run_router(monkeypatch: pytest.MonkeyPatch, session: _FakeSession, *,
                signal_in_open: bool = False) -> tuple[int | None, list[int], list[float]]:
    """Run the router's ``main`` in-process on ``session``; SIGINT lands during
    ``open_session`` (``signal_in_open``) or during the first wait of its loop. Returns main's
    status (None if it left through ``exit_now``), exit_now's statuses and the loop's sleeps."""
    from tdcm_ros.runtime import router

    exits: list[int] = []
    sleeps: list[float] = []

    def open_session(**_: object) -> _FakeSession:
        if signal_in_open:
            signal.raise_signal(signal.SIGINT)
        return session

    def sleep(seconds: float) -> None:
        sleeps.append(seconds)
        assert len(sleeps) < 100, "the router's loop never saw the signal"
        if len(sleeps) == 1:
            signal.raise_signal(signal.SIGINT)  # lands while the main loop waits

    def exit_now(status: int) -> None:
        exits.append(status)
        raise _Exited

    monkeypatch.setattr(router, "open_session", open_session)
    monkeypatch.setattr(router, "warn_if_exposed", lambda *_: None)
    monkeypatch.setattr(router.time, "sleep", sleep)
    monkeypatch.setattr(router, "exit_now", exit_now)
    monkeypatch.setattr(router, "CLOSE_TIMEOUT_S", 0.2)
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        return router.main(["--listen", "tcp/127.0.0.1:7447"]), exits, sleeps
    except _Exited:
        return None, exits, sleeps
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        session.released.set()


def test_the_router_closes_its_session_and_exits_on_sigint(
        monkeypatch: pytest.MonkeyPatch) -> None:
    session = _FakeSession()
    status, exits, sleeps = _run_router(monkeypatch, session)
    assert status == 0 and exits == [] and len(sleeps) == 1
    assert session.closed


def test_a_sigint_while_the_session_opens_stops_the_router_at_once(
        monkeypatch: pytest.MonkeyPatch) -> None:
    session = _FakeSession()
    status, exits, sleeps = _run_router(monkeypatch, session, signal_in_open=True)
    assert status == 0 and exits == [] and sleeps == []
    assert session.closed


def test_a_session_close_that_blocks_does_not_keep_the_router_alive(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    session = _FakeSession(close_blocks=True)
    status, exits, _ = _run_router(monkeypatch, session)
    assert status is None and exits == [0]
    assert "did not close within 0.2 s" in capsys.readouterr().err

