"""``RclpyContext.close`` never destroys a node while another thread is inside the executor's
``spin_once`` (the classic cause of a segfault in rclpy's ``destroy_node``). Runs without rclpy:
the context's executor, nodes and rclpy context are stand-ins that record what happens when."""

from __future__ import annotations

import threading
from types import SimpleNamespace
from typing import Any

from tdcm_ros.runtime import rclpy_runtime
from tdcm_ros.runtime.rclpy_runtime import RclpyContext
from test.support.waiting import eventually


class _Recorder:
    def __init__(self) -> None:
        self.events: list[str] = []
        self.in_spin = 0
        self.entered = threading.Event()
        self.release = threading.Event()
        self.lock = threading.Lock()

    def note(self, event: str) -> None:
        with self.lock:
            self.events.append(f"{event}{' DURING SPIN' if self.in_spin else ''}")


class _Executor:
    def __init__(self, log: _Recorder) -> None:
        self.log = log

    def spin_once(self, timeout_sec: float) -> None:
        self.log.in_spin += 1
        self.log.entered.set()
        self.log.release.wait()  # a wake-up that lasts until the test lets it end
        self.log.in_spin -= 1
        self.log.note("spun")

    def shutdown(self) -> None:
        self.log.note("executor shutdown")


class _Node:
    def __init__(self, log: _Recorder) -> None:
        self.log = log

    def destroy_node(self) -> None:
        self.log.note("destroy_node")


def _context(log: _Recorder) -> Any:
    ctx = RclpyContext.__new__(RclpyContext)
    ctx.context = type("Ctx", (), {"ok": lambda self: True,
                                   "try_shutdown": lambda self: log.note("context shutdown")})()
    ctx.executor = _Executor(log)
    ctx._stop = threading.Event()
    ctx._nodes = [_Node(log), _Node(log)]
    ctx._spinners = {}
    ctx._spinning = threading.Condition()
    ctx._closed = False
    ctx._timeout = SimpleNamespace(timeout=0.0)
    return ctx


def test_close_waits_for_the_spinning_thread_before_destroying_nodes() -> None:
    log = _Recorder()
    ctx = _context(log)
    spinner = threading.Thread(target=ctx.spin, daemon=True)
    spinner.start()
    eventually(log.entered.is_set, 10.0, "the spinner inside spin_once")
    closer = threading.Thread(target=ctx.close, daemon=True)
    closer.start()
    eventually(ctx._stop.is_set, 10.0, "close to ask the spinner to stop")
    log.release.set()  # the wake-up under way ends only now
    closer.join(10.0)
    spinner.join(10.0)
    assert not closer.is_alive() and not spinner.is_alive()
    assert log.events == ["spun", "executor shutdown", "destroy_node", "destroy_node",
                          "context shutdown"]


def test_close_leaves_the_nodes_alone_if_the_other_thread_never_leaves_spin_once(
        monkeypatch: Any) -> None:
    monkeypatch.setattr(rclpy_runtime, "CLOSE_SPIN_WAIT_S", 0.05)
    log = _Recorder()
    ctx = _context(log)
    spinner = threading.Thread(target=ctx.spin, daemon=True)
    spinner.start()
    eventually(log.entered.is_set, 10.0, "the spinner inside spin_once")
    try:
        ctx.close()
        assert log.events == []  # nothing destroyed under the spinning thread
    finally:
        log.release.set()
        spinner.join(10.0)
    ctx.spin_for(1.0)  # a closed context does not spin again
    assert log.events == ["spun"]


def test_close_from_inside_a_callback_does_not_wait_for_itself() -> None:
    log = _Recorder()
    ctx = _context(log)
    log.release.set()
    ctx.executor.spin_once = lambda timeout_sec: ctx.close()  # type: ignore[method-assign]
    ctx.spin_for(1.0)
    assert log.events == ["executor shutdown", "destroy_node", "destroy_node", "context shutdown"]
