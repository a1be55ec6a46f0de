"""Nodes in separate processes: the talker, ``tdcm up`` and ``tdcm param`` on both runtimes;
wire-level checks (attachments, liveliness tokens, transient-local cache) on zenoh only."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict, to_dict
from tdcm_ros.runtime.port import QoS
from test.support.processes import stop
from test.support.waiting import eventually

Spawn = Callable[..., subprocess.Popen[bytes]]
TALKER = "tdcm_ros.nodes.talker:Talker"



def test_message_equality_across_processes(context: Any, spawn: Spawn) -> None:
    values = ("{header: {frame_id: tdcm_base, stamp: {sec: 5, nanosec: 7}}, "
              "wrench: {force: {z: 20.0}}}")
    port = context.create_port("listener")
    got: list[Any] = []
    raw: list[Any] = []
    port.create_subscription("tension", "geometry_msgs/msg/WrenchStamped", got.append)
    port.create_raw_subscription("tension", "geometry_msgs/msg/WrenchStamped", raw.append)
    spawn("tdcm_ros.cli.main", "topic", "pub", "tension", "geometry_msgs/msg/WrenchStamped",
          values, "--rate", "20")
    eventually(lambda: len(got) >= 2 and len(raw) >= 2, 15.0, "tension messages", spin=context)
    expected = from_dict("geometry_msgs/msg/WrenchStamped",
                         {"header": {"frame_id": "tdcm_base", "stamp": {"sec": 5, "nanosec": 7}},
                          "wrench": {"force": {"z": 20.0}}})
    assert to_dict(got[0]) == to_dict(expected)
    first, second = raw[0].attachment, raw[1].attachment
    assert second.sequence_number == first.sequence_number + 1 and first.gid == second.gid
    assert abs(first.source_timestamp_ns - time.time_ns()) < 30e9

    from tdcm_ros.runtime.zenoh_query import graph_tokens

    def publishers() -> list[tuple[str, str, str]]:
        """Publisher tokens but those every ROS node has (``/parameter_events``, ``/rosout``)."""
        return [(t.topic, t.type_name, t.node_name) for t in graph_tokens(context.session, 0)
                if t.kind == "MP" and t.topic not in ("/parameter_events", "/rosout")]

    eventually(lambda: publishers() == [("/tension", "geometry_msgs/msg/WrenchStamped",
                                       "_tdcm_topic")], 10.0, "the publisher's liveliness token")


def test_parameter_change_at_runtime(runtime: str, context: Any, spawn: Spawn, params: Any,
                                     tmp_path: Path) -> None:
    path = tmp_path / "params.yaml"
    path.write_text("talker:\n  ros__parameters:\n    period: 0.05\n    prefix: p1\n")
    texts: list[str] = []
    context.create_port("listener").create_subscription(
        "chatter", "std_msgs/msg/String", lambda m: texts.append(m.data), QoS(depth=50))
    spawn("tdcm_ros.runtime.run_node", TALKER, "--params", str(path))
    eventually(lambda: any(t.startswith("p1 ") for t in texts), 15.0, "p1 messages", spin=context)

    talker = params("/talker")
    assert {"period", "prefix"} <= set(talker.names())
    assert talker.set("prefix", "p2") == {"successful": True, "reason": ""}
    eventually(lambda: texts[-1].startswith("p2 "), 5.0, "p2 messages", spin=context)
    bad = talker.set("period", -1.0)
    assert not bad["successful"] and "out of range" in bad["reason"] and "period" in bad["reason"]
    assert talker.get("period") == 0.05


def tdcm_param(env: dict[str, str], *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "param", *argv],
                          env=env, capture_output=True, text=True, timeout=60, check=False)


def tdcm_param_served(env: dict[str, str], *argv: str) -> subprocess.CompletedProcess[str]:
    """``tdcm param argv`` run again until it succeeds: the node's services are discovered
    by a fresh process (30 s at most)."""
    last: list[subprocess.CompletedProcess[str]] = []

    def ran() -> subprocess.CompletedProcess[str] | None:
        last[:] = [tdcm_param(env, *argv)]
        return last[0] if last[0].returncode == 0 else None

    return eventually(ran, 30.0, f"'tdcm param {' '.join(argv)}' to succeed",
                      detail=lambda: last[0].stderr if last else "")


def test_tdcm_param_lists_gets_and_sets(runtime: str, graph_env: dict[str, str],
                                        spawn: Spawn) -> None:
    spawn("tdcm_ros.runtime.run_node", TALKER)
    listing = tdcm_param_served(graph_env, "list", "talker")
    assert "  period: 0.5  # " in listing.stdout and "  prefix: " in listing.stdout
    assert tdcm_param(graph_env, "set", "/talker", "period", "0.2").stdout.strip() == (
        "Set parameter successful")
    assert tdcm_param(graph_env, "get", "talker", "period").stdout.strip() == "0.2"
    bad = tdcm_param(graph_env, "set", "talker", "period", "-1")
    assert bad.returncode == 2 and "period" in bad.stderr and "out of range" in bad.stderr
    assert tdcm_param(graph_env, "get", "talker", "period").stdout.strip() == "0.2"
    missing = tdcm_param(graph_env, "get", "nobody", "period", "--runtime", runtime)
    assert missing.returncode != 0 and "nobody" in missing.stderr


def test_tdcm_param_describes_and_dumps(runtime: str, graph_env: dict[str, str], spawn: Spawn,
                                        tmp_path: Path) -> None:
    """``describe`` shows the spec's type and range from the node's descriptor; ``dump`` prints
    a parameter file the package's reader takes back."""
    from tdcm_ros.runtime.params import node_parameters

    spawn("tdcm_ros.runtime.run_node", TALKER)
    described = tdcm_param_served(graph_env, "describe", "talker", "period")
    assert described.stdout.splitlines()[:2] == ["Parameter name: period", "  Type: double"]
    assert "    Min value: 0.001\n    Max value: 60.0" in described.stdout
    assert tdcm_param(graph_env, "set", "talker", "prefix", "dumped").returncode == 0
    dump = tdcm_param(graph_env, "dump", "talker")
    assert dump.returncode == 0 and dump.stdout.startswith("/talker:\n  ros__parameters:\n")
    (tmp_path / "dump.yaml").write_text(dump.stdout)
    values = node_parameters([tmp_path / "dump.yaml"], "/talker")
    assert (values["period"], values["prefix"], values["use_sim_time"]) == (0.5, "dumped", False)


def test_tdcm_param_set_reads_exponent_floats(runtime: str, graph_env: dict[str, str],
                                               spawn: Spawn) -> None:
    """``tdcm param set NODE NAME 1.0e9``: an exponent without a dot or a sign is a float (YAML
    1.2), not YAML 1.1's string, which the node rejects."""
    spawn("tdcm_ros.runtime.run_node", TALKER)
    tdcm_param_served(graph_env, "list", "talker")
    for text, value in (("2e-1", "0.2"), ("2.5e-1", "0.25"), ("1E0", "1.0")):
        done = tdcm_param(graph_env, "set", "talker", "period", text)
        assert done.returncode == 0, f"{text}: {done.stderr}"
        assert tdcm_param(graph_env, "get", "talker", "period").stdout.strip() == value


def test_subscriber_survives_publisher_restart(runtime: str, context: Any, spawn: Spawn,
                                               tmp_path: Path) -> None:
    texts: list[str] = []
    context.create_port("listener").create_subscription(
        "chatter", "std_msgs/msg/String", lambda m: texts.append(m.data))
    first = spawn("tdcm_ros.runtime.run_node", TALKER)
    eventually(lambda: len(texts) >= 1, 30.0, "the first talker", spin=context)
    assert stop(first) == 0
    second = tmp_path / "second.yaml"
    second.write_text("talker:\n  ros__parameters:\n    prefix: second\n")
    spawn("tdcm_ros.runtime.run_node", TALKER, "--params", str(second))
    eventually(lambda: any(t.startswith("second ") for t in texts), 30.0,
               "the restarted talker", spin=context)


def _children(pid: int) -> list[int]:
    found: list[int] = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        found += [int(p) for p in (task / "children").read_text().split()]
    return found


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_tdcm_up_sigint_stops_every_child(runtime: str, context: Any, spawn: Spawn) -> None:
    launcher = spawn("tdcm_ros.cli.main", "up", "--nodes", "talker", "--runtime", runtime)
    # The talker alone: on zenoh the fixture's router already listens on the endpoint.
    eventually(lambda: len(_children(launcher.pid)) == 1, 15.0, "the talker process")
    children = _children(launcher.pid)
    texts: list[str] = []
    context.create_port("listener").create_subscription(
        "chatter", "std_msgs/msg/String", lambda m: texts.append(m.data))
    eventually(lambda: any(t.startswith("hello") for t in texts), 20.0, "the talker", spin=context)
    launcher.send_signal(signal.SIGINT)
    assert launcher.wait(15) == 0
    assert not [pid for pid in children if _alive(pid)]


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_tdcm_up_starts_a_router_when_none_listens(zenoh_env: dict[str, str],
                                                   spawn: Spawn) -> None:
    launcher = spawn("tdcm_ros.cli.main", "up", "--nodes", "talker")
    eventually(lambda: len(_children(launcher.pid)) == 2, 15.0, "router and talker processes")
    children = _children(launcher.pid)
    echo = spawn("tdcm_ros.cli.main", "topic", "echo", "chatter", "--once")
    assert b"data: hello" in echo.communicate(timeout=20)[0]
    launcher.send_signal(signal.SIGINT)
    assert launcher.wait(15) == 0
    assert not [pid for pid in children if _alive(pid)]


def test_transient_local_reaches_late_subscriber(context: Any) -> None:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    latched = QoS(depth=1, durability="transient_local")
    publisher = context.create_port("latched").create_publisher("config", "std_msgs/msg/String",
                                                                latched)
    publisher.publish(from_dict("std_msgs/msg/String", {"data": "v1"}))
    late = ZenohContext()
    try:
        got: list[str] = []
        late.create_port("late").create_subscription("config", "std_msgs/msg/String",
                                                     lambda m: got.append(m.data), latched)
        eventually(lambda: got == ["v1"], 10.0, "the cached sample", spin=late)
    finally:
        late.close()
