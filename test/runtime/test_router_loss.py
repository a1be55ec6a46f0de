"""The graph's router lost (``kill -9``): a zenoh node sees it (``graph_hubs``) and sees it
come back; ``tdcm up`` reports the death of the router it started and restarts it, the nodes
reconnecting, or with ``--on-router-exit stop`` stops the graph and exits 1. What the driver does
with a lost graph is tested in-process on simulated time
(``test/nodes/test_tension_driver_logic.py::test_a_lost_graph_releases_after_the_timeout...``)."""

from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tdcm_ros.runtime.zenoh_runtime import ZenohContext
from test.support.cli import tdcm
from test.support.processes import Lines, listening
from test.support.waiting import eventually

Spawn = Callable[..., subprocess.Popen[bytes]]


def router_pid(port: int) -> int:
    """The pid of the router process listening on ``port`` (found by its command line)."""
    wanted = f"tcp/127.0.0.1:{port}"
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            argv = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if b"tdcm_ros.runtime.router" in argv and wanted.encode() in argv:
            return int(entry.name)
    raise AssertionError(f"no router process listens on {wanted}")


def test_a_zenoh_node_sees_its_router_go_and_come_back(
        zenoh_env: dict[str, str], router: subprocess.Popen[bytes], spawn: Spawn) -> None:
    context = ZenohContext()
    try:
        port = context.create_port("watcher")
        first = eventually(port.graph_hubs, 15.0, "the router connected")
        router.kill()
        router.wait(10)
        eventually(lambda: not port.graph_hubs(), 15.0, "the router seen gone")
        spawn("tdcm_ros.runtime.router", "--listen", zenoh_env["TDCM_ZENOH_ENDPOINT"])
        second = eventually(port.graph_hubs, 30.0, "the session reconnected to a new router")
        assert second.isdisjoint(first)  # a new router has a new id: a driver sees the restart
    finally:
        context.close()


def _chatter_heard(context: ZenohContext) -> list[Any]:
    heard: list[Any] = []
    context.create_port("listener").create_subscription("chatter", "std_msgs/msg/String",
                                                        heard.append)
    return heard


def test_tdcm_up_restarts_its_router_and_the_nodes_reconnect(
        zenoh_env: dict[str, str], spawn: Spawn) -> None:
    """The router tdcm up started is killed: the launcher logs its death, starts it again on the
    same endpoint, and a peer hears the talker through the new router; Ctrl-C then exits 0."""
    port = int(zenoh_env["ZENOH_TEST_PORT"])
    up = spawn("tdcm_ros.cli.main", "up", "--nodes", "talker")
    log = Lines(up, "stderr")
    eventually(lambda: listening(port), 30.0, "the router of tdcm up")
    context = ZenohContext()
    try:
        heard = _chatter_heard(context)
        eventually(lambda: heard, 30.0, "the talker", spin=context)
        os.kill(router_pid(port), signal.SIGKILL)
        eventually(lambda: log.has("zenoh router restarted"), 30.0, "the router restarted",
                   detail=log.tail)
        assert log.has("exited with status -9; every zenoh node is cut off")
        before = len(heard)
        eventually(lambda: len(heard) > before + 2, 30.0, "the talker through the new router",
                   spin=context, detail=log.tail)
    finally:
        context.close()
    up.send_signal(signal.SIGINT)
    assert up.wait(30) == 0, log.tail()


def test_tdcm_up_on_router_exit_stop_stops_the_graph_and_exits_1(
        zenoh_env: dict[str, str], spawn: Spawn) -> None:
    port = int(zenoh_env["ZENOH_TEST_PORT"])
    up = spawn("tdcm_ros.cli.main", "up", "--nodes", "talker", "--on-router-exit", "stop")
    log = Lines(up, "stderr")
    eventually(lambda: listening(port) and log.has("starting talker"), 30.0, "tdcm up")
    os.kill(router_pid(port), signal.SIGKILL)
    assert up.wait(30) == 1, log.tail()
    assert log.has("stopping the graph (--on-router-exit stop)")


def test_an_unknown_router_exit_action_is_refused() -> None:
    result = tdcm("up", "--on-router-exit", "ignore")
    assert result.returncode == 2 and "--on-router-exit" in result.stderr
