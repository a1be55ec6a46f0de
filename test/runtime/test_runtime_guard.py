"""Callbacks cannot kill a node: failing callbacks, failing parameter checks and hostile parameter
queries are isolated on both runtimes; a loop that dies anyway exits non-zero; ``tdcm up`` says so."""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.guard import CallbackGuard
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.port import NodeLogic, QoS
from tdcm_ros.runtime.run_node import LOOP_DIED, run_node
from test.support.processes import REPO, stop
from test.support.waiting import eventually

FRAGILE = "test.runtime.fragile_node:FragileNode"


class Sink:
    """A publisher stand-in that keeps what it is given."""

    def __init__(self) -> None:
        self.messages: list[Any] = []

    def publish(self, message: Any) -> None:
        self.messages.append(message)


def test_the_guard_logs_counts_and_reports_and_lets_interrupts_through(caplog) -> None:
    sink = Sink()
    made: list[tuple[str, str]] = []

    def factory(topic: str, type_name: str) -> Sink:
        made.append((topic, type_name))
        return sink

    guard = CallbackGuard("/n", logging.getLogger("guard_test"), factory, lambda: 5 * 10**9 + 7)

    def broken(value: int) -> int:
        return 10 // value

    wrapped = guard.wrap("subscription /x", broken)
    assert wrapped(2) == 5 and not made
    with caplog.at_level(logging.ERROR, logger="guard_test"):
        assert wrapped(0) is None
        assert wrapped(0) is None  # within the report period: counted and logged, not re-sent
    assert guard.failures == {"subscription /x": 2}
    assert "ZeroDivisionError" in caplog.text and "Traceback" in caplog.text
    assert made == [("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray")]
    status = sink.messages[0].status[0]
    assert len(sink.messages) == 1 and status.level == 2 and status.name == "/n: callbacks"
    assert "ZeroDivisionError" in status.message
    assert [(v.key, v.value) for v in status.values] == [("subscription /x", "1")]
    assert sink.messages[0].header.stamp.sec == 5

    def interrupted() -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        guard.wrap("timer", interrupted)()


class _DyingContext:
    """A context whose loop fails with an error no callback guard saw."""

    domain_id = 0

    def __init__(self) -> None:
        self.closed = False

    def create_port(self, name: str, namespace: str, overrides: Any) -> MemoryPort:
        return MemoryPort(overrides, name=name, namespace=namespace)

    def spin(self) -> None:
        raise RuntimeError("executor internals broke")

    def close(self) -> None:
        self.closed = True


class _Closing(NodeLogic):
    closed = False

    def close(self) -> None:
        _Closing.closed = True


def test_a_loop_that_dies_anyway_closes_the_node_and_exits_non_zero(monkeypatch) -> None:
    context = _DyingContext()
    monkeypatch.setattr("tdcm_ros.runtime.run_node.open_context", lambda *a, **k: context)
    assert run_node(_Closing, runtime="zenoh") == LOOP_DIED != 0
    assert _Closing.closed and context.closed


@pytest.fixture
def fragile(runtime: str, graph_env: dict[str, str]) -> Iterator[subprocess.Popen[bytes]]:
    node = subprocess.Popen([sys.executable, "-m", "tdcm_ros.runtime.run_node", FRAGILE],
                            env=graph_env, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    yield node
    if node.poll() is None:
        node.kill()
    node.wait()


def test_a_failing_callback_is_reported_and_the_node_goes_on(runtime, context, params,
                                                              fragile) -> None:
    port = context.create_port("poker")
    poke = port.create_publisher("poke", "std_msgs/msg/String")
    echoes: list[str] = []
    reports: list[Any] = []
    port.create_subscription("echo", "std_msgs/msg/String", lambda m: echoes.append(m.data))
    port.create_subscription("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                             lambda a: reports.extend(s for s in a.status
                                                      if s.name == "/fragile: callbacks"),
                             QoS(depth=100))

    def say(text: str) -> Callable[[], None]:
        return lambda: poke.publish(from_dict("std_msgs/msg/String", {"data": text}))

    eventually(lambda: "first" in echoes, 30.0, "the node's first echo", spin=context,
               action=say("first"), every=0.2)
    eventually(lambda: reports, 20.0, "the failure on /diagnostics", spin=context,
               action=say("boom"), every=0.2)
    assert "RuntimeError: boom" in reports[0].message and "subscription /poke" in reports[0].message
    eventually(lambda: "after" in echoes, 20.0, "an echo after the failure", spin=context,
               action=say("after"), every=0.2)

    node = params("/fragile")
    crashed = node.set("mode", "crash")
    assert not crashed["successful"] and "KeyError" in crashed["reason"], crashed
    assert node.get("mode") == "ok"
    assert node.set("mode", "calm") == {"successful": True, "reason": ""}
    eventually(lambda: "still" in echoes, 20.0, "an echo after the parameter crash",
               spin=context, action=say("still"), every=0.2)
    assert fragile.poll() is None


def test_hostile_parameter_queries_get_errors_and_the_node_goes_on(context, zenoh_env) -> None:
    """Bodies that are no CDR request of the embedded runtime's rcl_interfaces parameter services
    (rclpy's own services are rclpy's business) get an error reply; the node goes on."""
    node = subprocess.Popen([sys.executable, "-m", "tdcm_ros.runtime.run_node", FRAGILE],
                            env=zenoh_env, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        from tdcm_ros.bagio import service_type_hash
        from tdcm_ros.runtime import wire
        from tdcm_ros.runtime.param_client import ParameterClient
        from tdcm_ros.runtime.param_services import SERVICES

        eventually(lambda: _served(context, SERVICES), 30.0,
                   "the SS tokens of the six parameter services /fragile/*",
                   detail=lambda: _server_tokens(context))
        gid = bytes(range(16))
        for body in ("null", "[]", "7", '"x"', '{"name": 5}', "{not json", '{"name": null}'):
            for seq, (service, type_name) in enumerate(SERVICES.items(), start=1):
                key = wire.topic_key(0, f"/fragile/{service}", type_name,
                                     service_type_hash(type_name))
                replies = list(context.session.get(
                    key, payload=body.encode(), timeout=5.0,
                    attachment=wire.encode_attachment(seq, time.time_ns(), gid)))
                assert replies and all(r.ok is None and r.err is not None for r in replies), (
                    service, body)
        assert node.poll() is None
        assert ParameterClient(context, "/fragile").get("mode") == "ok"
    finally:
        node.kill()
        node.wait()


def _server_tokens(context: Any) -> list[str]:
    """The ``SS`` (service server) liveliness tokens on the graph."""
    return [str(r.ok.key_expr) for r in context.session.liveliness().get("@ros2_lv/**",
                                                                       timeout=1.0)
            if r.ok is not None and "/SS/" in str(r.ok.key_expr)]


def _served(context: Any, services: Any) -> bool:
    """Whether /fragile serves each of ``services`` (its SS token is on the graph)."""
    tokens = _server_tokens(context)
    return all(any(f"%fragile%{service}/" in t for t in tokens) for service in services)


def _children(pid: int) -> list[int]:
    found: list[int] = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        found += [int(p) for p in (task / "children").read_text().split()]
    return found


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_tdcm_up_reports_a_dead_node_and_exits_non_zero(runtime, context, spawn) -> None:
    launcher = spawn("tdcm_ros.cli.main", "up", "--nodes", "talker", "--runtime", runtime)
    heard: list[str] = []
    context.create_port("listener").create_subscription(
        "chatter", "std_msgs/msg/String", lambda m: heard.append(m.data))
    eventually(lambda: heard, 30.0, "the talker's first message on chatter", spin=context)
    assert len(_children(launcher.pid)) == 1  # the talker, the graph running
    os.kill(_children(launcher.pid)[0], signal.SIGKILL)
    status = launcher.wait(30)  # every node has exited: tdcm up ends by itself
    assert launcher.stderr is not None
    log = launcher.stderr.read().decode()
    assert "node talker exited with status -9 while the graph runs" in log, log
    assert status == 1
    assert stop(launcher) == 1
