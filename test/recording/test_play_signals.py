"""``tdcm bag play`` leaves after Ctrl-C whatever it is doing: the signal lands at a chosen point
of an in-process run (a stand-in player) and the transport's close may block for good."""

from __future__ import annotations

import argparse
import signal
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from tdcm_ros.cli import bag as bag_cli
from tdcm_ros.recording import player as player_module


class _Exited(Exception):
    def __init__(self, status: int) -> None:
        super().__init__(status)
        self.status = status


class _FakePlayer:
    """A player whose ``run`` raises SIGINT at ``signal_at`` and whose context close blocks
    (``close_blocks``) until the test ends."""

    signal_at = "run"
    close_blocks = False
    ignore_stop = False
    released = threading.Event()

    def __init__(self, bag: str, options: Any, *, runtime: str, on_progress: Any,
                 on_topic: Any) -> None:
        self.reader = argparse.Namespace(path=bag)
        self.base_ns = time.time_ns()  # a bag of now: no stale-stamp warning
        self.topics = ["/a"]
        self._stop = threading.Event()
        self.closed = False
        if self.signal_at == "init":
            signal.raise_signal(signal.SIGINT)

    def request_stop(self) -> None:
        self._stop.set()

    def run(self) -> int:
        if self.signal_at == "run":
            signal.raise_signal(signal.SIGINT)
        for _ in range(1000):  # the player's wait loop: it looks at the stop request
            if self._stop.is_set() and not self.ignore_stop:
                return 3
            if self.ignore_stop and self.signal_at == "run":
                signal.raise_signal(signal.SIGINT)  # the second Ctrl-C of an impatient user
            self._stop.wait(0.01)
        raise AssertionError("the stand-in player was never stopped")

    def close(self, timeout: float | None = None) -> bool:
        context = argparse.Namespace(close=self._close_context)
        real = player_module.Player.__new__(player_module.Player)
        real._context = context  # the real close, on a context whose close may block
        return real.close(timeout)

    def _close_context(self) -> None:
        if self.close_blocks:
            self.released.wait()
        self.closed = True


@pytest.fixture
def play(monkeypatch: pytest.MonkeyPatch) -> Iterator[Callable[..., tuple[int, list[int]]]]:
    import tdcm_ros.recording

    exits: list[int] = []
    deadlines: list[bool] = []

    def exit_now(status: int) -> None:
        exits.append(status)
        raise _Exited(status)

    monkeypatch.setattr(tdcm_ros.recording, "Player", _FakePlayer)
    monkeypatch.setattr(bag_cli, "exit_now", exit_now)
    monkeypatch.setattr(bag_cli, "arm_exit_deadline", lambda: deadlines.append(True))
    monkeypatch.setattr(bag_cli, "CLOSE_TIMEOUT_S", 0.2)
    monkeypatch.setattr(player_module, "LINGER_S", 0.0)
    _FakePlayer.released = threading.Event()
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}

    def run(**fake: Any) -> tuple[int, list[int]]:
        for name, value in fake.items():
            monkeypatch.setattr(_FakePlayer, name, value)
        args = argparse.Namespace(bag="fake", rate=1.0, start_offset=0.0, loop=False, topics=[],
                                  remap=[], clock=0.0, delay=0.0, runtime="zenoh", quiet=True)
        try:
            status = bag_cli.run_play(args)
        except _Exited as exited:
            status = exited.status
        assert deadlines, "no exit deadline was armed by the signal"
        return status, exits

    try:
        yield run
    finally:
        _FakePlayer.released.set()
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def test_ctrl_c_while_playing_exits_130(play: Callable[..., tuple[int, list[int]]]) -> None:
    assert play() == (130, [])


def test_ctrl_c_while_the_player_starts_exits_130(
        play: Callable[..., tuple[int, list[int]]]) -> None:
    assert play(signal_at="init") == (130, [])


def test_a_context_close_that_blocks_does_not_keep_the_player_alive(
        play: Callable[..., tuple[int, list[int]]], capsys: pytest.CaptureFixture[str]) -> None:
    assert play(close_blocks=True) == (130, [130])
    captured = capsys.readouterr()
    assert "3 messages published on 1 topics" in captured.out  # said before leaving
    assert "did not close within 0.2 s; exiting without it" in captured.err


def test_a_second_ctrl_c_leaves_at_once(play: Callable[..., tuple[int, list[int]]]) -> None:
    assert play(ignore_stop=True) == (130, [130])


def test_player_close_with_a_timeout_reports_a_blocked_context() -> None:
    released = threading.Event()
    player = player_module.Player.__new__(player_module.Player)
    player._context = argparse.Namespace(close=released.wait)
    try:
        assert player.close(timeout=0.05) is False
    finally:
        released.set()
    player._context = argparse.Namespace(close=lambda: None)
    assert player.close(timeout=5.0) is True


def test_ctrl_c_during_the_players_wait_stops_it_even_if_the_handler_is_slow() -> None:
    """The root cause of ``tdcm bag play`` still running after Ctrl-C (caught with the exit
    deadline's stack: the main thread in ``_Executor.spin_once``'s queue wait, 15 s after the
    signal): SIGINT lands while the player waits for its next message, and its handler returns
    after the wait's remaining timeout (a loaded machine; here a handler that takes 0.15 s).
    CPython's SimpleQueue.get then waited for the next task forever; the player queues none."""
    zenoh_runtime = pytest.importorskip("tdcm_ros.runtime.zenoh_runtime")
    import time

    player = player_module.Player.__new__(player_module.Player)
    context = zenoh_runtime.ZenohContext.__new__(zenoh_runtime.ZenohContext)
    context.executor = zenoh_runtime._Executor()
    player._context = context
    player._stop = threading.Event()
    player._next_clock = player._next_report = float("inf")
    woken = threading.Event()

    def slow_handler(signum: int, frame: Any) -> None:
        player.request_stop()
        time.sleep(0.15)  # longer than any wait of the player's loop (STOP_LATENCY_S)

    def rescue() -> None:  # never needed with the fix: without it the test would hang
        woken.set()
        context.executor.post(lambda: None)

    previous = signal.signal(signal.SIGINT, slow_handler)
    main = threading.main_thread().ident
    assert main is not None
    interrupt = threading.Timer(0.2, signal.pthread_kill, (main, signal.SIGINT))
    safety = threading.Timer(10.0, rescue)
    interrupt.start()
    safety.start()
    try:
        assert player._wait_until(time.monotonic() + 60.0) is False
    finally:
        safety.cancel()
        interrupt.cancel()
        signal.signal(signal.SIGINT, previous)
    assert not woken.is_set(), "the player's wait outlived the stop: woken only by a new task"


def test_a_zenoh_context_stop_takes_no_lock_the_spinning_thread_may_hold() -> None:
    """``ZenohContext.request_stop`` runs in signal handlers (``tdcm_node``): on the thread that
    spins, between two bytecodes, possibly inside ``Queue.get`` with the queue's lock held. It
    used to post a wake-up task, which takes that (non-reentrant) lock: called there, it would
    wait forever. The call is made on a thread that holds the lock, as the handler would be."""
    zenoh_runtime = pytest.importorskip("tdcm_ros.runtime.zenoh_runtime")

    context = zenoh_runtime.ZenohContext.__new__(zenoh_runtime.ZenohContext)
    context.executor = zenoh_runtime._Executor()
    returned = threading.Event()

    def spinning_thread_interrupted_inside_get() -> None:
        with context.executor._tasks.mutex:
            context.request_stop()
            returned.set()

    worker = threading.Thread(target=spinning_thread_interrupted_inside_get, daemon=True)
    worker.start()
    worker.join(5.0)
    assert returned.is_set(), "request_stop waited for a lock its own thread holds"
    assert context.executor.stop.is_set()
