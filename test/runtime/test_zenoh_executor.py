"""The embedded runtime's callback loop (``zenoh_runtime._Executor``) on a simulated clock: a
timer whose callback outlasts its period. It used to reschedule itself from the time read
before the callback, so it was due again at once and ran again in the same ``spin_once``, for
as long as each call outlasted the period: the loop never reached its queued tasks (the
subscriptions' messages) nor the stop request between ``spin_once`` calls, and a node asked
to stop on a loaded machine was still stopping when ``tdcm up`` gave up on it."""

from __future__ import annotations

import pytest

zenoh_runtime = pytest.importorskip("tdcm_ros.runtime.zenoh_runtime")

MS = 1_000_000  # ns


class Clock:
    """Simulated monotonic time (ns)."""

    def __init__(self) -> None:
        self.now = 10 * MS

    def __call__(self) -> int:
        return self.now


def slow_timer(clock: Clock, executor: object, period_ms: int, takes_ms: int) -> list[int]:
    """A timer of ``period_ms`` whose callback takes ``takes_ms`` of the clock; the times it
    ran at. Its sixth call fails the test (the old loop would run it without end)."""
    calls: list[int] = []

    def callback() -> None:
        calls.append(clock.now)
        assert len(calls) <= 5, "the slow timer ran on and on in one spin_once"
        clock.now += takes_ms * MS

    executor.add_timer(period_ms / 1000.0, callback)  # type: ignore[attr-defined]
    return calls


def test_a_timer_slower_than_its_period_runs_once_then_the_tasks_run() -> None:
    clock = Clock()
    executor = zenoh_runtime._Executor(clock)
    calls = slow_timer(clock, executor, period_ms=1, takes_ms=3)
    ran: list[str] = []
    executor.post(lambda: ran.append("message"))
    clock.now += 1 * MS  # the timer falls due
    executor.spin_once(0.0)
    assert calls == [11 * MS] and ran == ["message"]
    # it missed the periods due at 12 and 13 ms (it ended at 14 ms): next on its grid, 15 ms
    executor.spin_once(0.0)
    assert calls == [11 * MS]
    clock.now = 15 * MS
    executor.spin_once(0.0)
    assert calls == [11 * MS, 15 * MS]


def test_a_stop_request_between_two_due_timers_is_seen_before_the_second() -> None:
    clock = Clock()
    executor = zenoh_runtime._Executor(clock)
    first: list[int] = []

    def stopping() -> None:
        first.append(clock.now)
        executor.stop.set()  # as a signal handler does, from the node's own thread

    executor.add_timer(0.001, stopping)
    second = slow_timer(clock, executor, period_ms=1, takes_ms=0)
    clock.now += 1 * MS
    executor.spin_once(0.0)
    assert first == [11 * MS] and second == []


def test_a_timer_on_time_keeps_its_grid() -> None:
    clock = Clock()
    executor = zenoh_runtime._Executor(clock)
    calls = slow_timer(clock, executor, period_ms=2, takes_ms=0)
    for now_ms in (12, 13, 14, 17, 18):  # late by 1 ms at 17: still the 16 ms call, then 18
        clock.now = now_ms * MS
        executor.spin_once(0.0)
    assert calls == [12 * MS, 14 * MS, 17 * MS, 18 * MS]


def test_a_task_posted_by_a_task_runs_after_those_queued_before_it() -> None:
    """What ``call_soon`` relies on: each sample received posts its delivery as it arrives, so
    a solve the first delivery of a burst posts runs after the burst's other deliveries."""
    executor = zenoh_runtime._Executor(Clock())
    ran: list[str] = []

    def deliver(k: int) -> None:
        ran.append(f"in {k}")
        if k == 0:
            executor.post(lambda: ran.append("solve"))

    for k in range(3):
        executor.post(lambda k=k: deliver(k))
    executor.spin_once(0.0)
    assert ran == ["in 0", "in 1", "in 2", "solve"]
