"""``tdcm topic echo|hz|list`` against a private router, the tool in its own process."""

from __future__ import annotations

import math
import select
import subprocess
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import yaml

from tdcm_ros.bagio import from_dict
from test.support.waiting import eventually

Spawn = Callable[..., subprocess.Popen[bytes]]
BURST = 300


@pytest.fixture
def port(router: subprocess.Popen[bytes]) -> Iterator[Any]:
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    ctx = ZenohContext()
    yield ctx.create_port("test_publisher")
    ctx.close()


def documents(output: bytes) -> list[Any]:
    """The YAML documents ``topic echo`` printed (each ends with ``---``)."""
    return [doc for doc in yaml.safe_load_all(output.decode()) if doc is not None]


@pytest.mark.parametrize(("args", "expected"), [(("std_msgs/msg/String", "--once"), 1),
                                                (("--once",), 1),
                                                (("--count", "3"), 3)],
                         ids=["once_typed", "once_any_type", "count_3"])
def test_echo_prints_exactly_the_requested_number_of_a_burst(port, spawn: Spawn, args, expected):
    publisher = port.create_publisher("chatter", "std_msgs/msg/String")
    echo = spawn("tdcm_ros.cli.main", "topic", "echo", "chatter", *args)
    eventually(publisher.matched, 15.0, "topic echo to subscribe")
    # Back to back, so many samples wait in the tool's queue when the first one is printed.
    for k in range(BURST):
        publisher.publish(from_dict("std_msgs/msg/String", {"data": f"burst {k}"}))
    out, err = echo.communicate(timeout=20)
    assert echo.returncode == 0, err.decode()
    docs = documents(out)
    assert len(docs) == expected, f"{args} printed {len(docs)} messages"
    # Keep-last history may skip samples of the burst, never repeat or reorder them.
    indices = [int(doc["data"].removeprefix("burst ")) for doc in docs]
    assert indices == sorted(set(indices))


def test_list_shows_publishers_and_subscriptions_with_types(port, spawn: Spawn):
    port.create_publisher("chatter", "std_msgs/msg/String")
    port.create_subscription("/ns/wrench", "geometry_msgs/msg/WrenchStamped", lambda _: None)
    listing = spawn("tdcm_ros.cli.main", "topic", "list", "-t", "--timeout", "1.5")
    out, err = listing.communicate(timeout=30)
    assert listing.returncode == 0, err.decode()
    lines = out.decode().splitlines()
    assert "/chatter [std_msgs/msg/String]" in lines
    assert "/ns/wrench [geometry_msgs/msg/WrenchStamped]" in lines
    assert lines == sorted(lines)


def test_rate_stats_of_known_arrivals():
    from tdcm_ros.cli.topic import rate_stats

    rate, low, high, std = rate_stats([10.0, 10.1, 10.3, 10.4])
    assert rate == pytest.approx(3 / 0.4)
    assert (low, high) == (pytest.approx(0.1), pytest.approx(0.2))
    assert std == pytest.approx((2 * 0.1**2 / 9) ** 0.5)   # periods 0.1, 0.2, 0.1


class SimulatedGraph:
    """``topic hz``'s context on simulated time: a message on the subscribed topic every
    ``period_ms`` ms; :meth:`spin_for` moves the clock (:meth:`monotonic`), delivering them."""

    def __init__(self, period_ms: int) -> None:
        self.period_ms, self.now_ms = period_ms, 0
        self.topics: list[str] = []
        self.callback: Callable[[Any], None] | None = None

    def monotonic(self) -> float:
        return self.now_ms / 1000

    def create_port(self, name: str) -> Any:
        return self

    def create_raw_subscription(self, topic: str, type_name: Any,
                                callback: Callable[[Any], None]) -> None:
        self.topics.append(topic)
        self.callback = callback

    def spin_for(self, seconds: float) -> None:
        end = self.now_ms + round(seconds * 1000)
        while (due := (self.now_ms // self.period_ms + 1) * self.period_ms) <= end:
            self.now_ms = due
            assert self.callback is not None
            self.callback(b"")
        self.now_ms = end

    def close(self) -> None:
        pass


def test_hz_reports_the_rate_of_messages_every_20_ms_once_a_second(monkeypatch, capsys):
    import argparse
    from types import SimpleNamespace

    from tdcm_ros.cli import topic

    graph = SimulatedGraph(period_ms=20)
    monkeypatch.setattr(topic, "_context", lambda: graph)
    monkeypatch.setattr(topic, "time", SimpleNamespace(monotonic=graph.monotonic))
    assert topic.run_hz(argparse.Namespace(topic="chatter", window=100, duration=3.0)) == 0
    assert graph.topics == ["chatter"] and graph.now_ms == 3000
    # 50, 100 then 150 arrivals, the window holding the last 101
    assert capsys.readouterr().out.splitlines() == [
        line for window in (50, 100, 101)
        for line in ("average rate: 50.000",
                     f"\tmin: 0.020s max: 0.020s std dev: 0.00000s window: {window}")]


def test_hz_says_no_new_messages_before_two_arrived(monkeypatch, capsys):
    import argparse
    from types import SimpleNamespace

    from tdcm_ros.cli import topic

    graph = SimulatedGraph(period_ms=1500)
    monkeypatch.setattr(topic, "_context", lambda: graph)
    monkeypatch.setattr(topic, "time", SimpleNamespace(monotonic=graph.monotonic))
    assert topic.run_hz(argparse.Namespace(topic="chatter", window=100, duration=3.5)) == 0
    out = capsys.readouterr().out.splitlines()
    # 1 s: none, 2 s: one (at 1.5 s), 3 s: two (1.5 s apart), 3.5 s: still two
    assert out[:2] == ["no new messages", "no new messages"]
    assert out[2:4] == ["average rate: 0.667",
                        "\tmin: 1.500s max: 1.500s std dev: 0.00000s window: 2"]
    assert out[4:6] == out[2:4] and len(out) == 6


def test_hz_reports_the_rate_of_a_live_publisher(port, spawn: Spawn):
    """The tool subscribed in its own process: every message it counted is one published.
    (The rate it computes from its arrival times is checked exactly above: over a live graph
    it measures the machine's scheduling, not the tool.)"""
    publisher = port.create_publisher("chatter", "std_msgs/msg/String")
    hz = spawn("tdcm_ros.cli.main", "topic", "hz", "chatter", "--duration", "3")
    eventually(publisher.matched, 15.0, "topic hz to subscribe")
    message = from_dict("std_msgs/msg/String", {"data": "tick"})
    sent = 0

    def publish() -> None:
        nonlocal sent
        if sent < 1000:
            publisher.publish(message)
            sent += 1

    eventually(lambda: hz.poll() is not None, 20.0, "topic hz to end after its 3 s",
               action=publish, every=0.02)
    out, err = hz.communicate(timeout=20)
    assert hz.returncode == 0, err.decode()
    reports = out.decode().split("average rate: ")[1:]
    assert reports, out.decode()
    rate, window = float(reports[-1].split()[0]), int(reports[-1].split()[-1])
    assert 2 <= window <= min(sent, 101) and math.isfinite(rate) and rate > 0


@pytest.mark.parametrize("argv", [["topic", "list", "--timeout", "0"],
                                  ["topic", "pub", "tension", "std_msgs/msg/Float64", "--rate", "0"]])
def test_bad_options_are_one_line_errors(argv, capsys):
    from tdcm_ros.cli.main import main

    assert main(argv) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and argv[-2] in err


def read_stderr_until(child: subprocess.Popen[bytes], phrase: str, timeout: float) -> str:
    """What ``child`` wrote to stderr up to the line holding ``phrase`` (fails after ``timeout``
    s, or if the child exits first)."""
    assert child.stderr is not None
    stderr = child.stderr
    seen: list[str] = []

    def next_line_holds_it() -> bool:
        ready, _, _ = select.select([stderr], [], [], 0.1)
        if not ready:
            return False
        seen.append(stderr.readline().decode())
        assert seen[-1], f"stderr closed before {phrase!r}: {''.join(seen)!r}"
        return phrase in seen[-1]

    eventually(next_line_holds_it, timeout, f"{phrase!r} on stderr",
               detail=lambda: repr("".join(seen)))
    return "".join(seen)


def test_echo_warns_about_an_unknown_topic_with_similar_names(port, spawn: Spawn):
    port.create_publisher("chatter", "std_msgs/msg/String")
    echo = spawn("tdcm_ros.cli.main", "topic", "echo", "chater", "--wait-matching", "0.5")
    err = read_stderr_until(echo, "does not appear to be published yet", 20.0)
    assert "WARNING: topic [/chater]" in err and "in 0.5 s" in err
    assert "similar topics: /chatter" in err
    assert echo.poll() is None  # still listening, as ros2 topic echo does


def test_echo_with_a_type_the_topic_is_not_published_as_is_an_error(port, spawn: Spawn):
    port.create_publisher("chatter", "std_msgs/msg/String")
    echo = spawn("tdcm_ros.cli.main", "topic", "echo", "chatter", "std_msgs/msg/Float64",
                 "--wait-matching", "0.5")
    _, err = echo.communicate(timeout=20)
    lines = err.decode().strip().splitlines()
    assert echo.returncode == 2 and len(lines) == 1, err.decode()
    assert "/chatter is published as std_msgs/msg/String, not std_msgs/msg/Float64" in lines[0]


def test_pub_with_another_type_than_the_graph_is_an_error_not_a_publish(port, spawn: Spawn):
    port.create_subscription("tension", "geometry_msgs/msg/WrenchStamped", lambda _: None)
    pub = spawn("tdcm_ros.cli.main", "topic", "pub", "tension", "std_msgs/msg/Float64",
                "{data: 1.0}", "--once", "--wait-matching", "0.5")
    out, err = pub.communicate(timeout=20)
    assert pub.returncode == 2, err.decode()
    assert "/tension is used as geometry_msgs/msg/WrenchStamped, not std_msgs/msg/Float64" in (
        err.decode())
    assert "publishing" not in out.decode()


def test_pub_without_a_matching_subscriber_warns_with_similar_names_and_exits_1(
        port, spawn: Spawn):
    """Issue 25: ``tdcm topic pub estop`` with the driver gone printed "publishing anyway" and
    exited 0; a publish that nothing received is a failure."""
    port.create_subscription("tension", "std_msgs/msg/Float64", lambda _: None)
    pub = spawn("tdcm_ros.cli.main", "topic", "pub", "tensoin", "std_msgs/msg/Float64",
                "{data: 1.0}", "--once", "--wait-matching", "0.5")
    out, err = pub.communicate(timeout=20)
    assert pub.returncode == 1, err.decode()
    assert "no subscriber of /tensoin matched within 0.5 s; similar topics: /tension" in (
        err.decode())
    assert "publishing #1" in out.decode()
    assert "nothing received the 1 message(s)" in err.decode()


def test_pub_to_a_subscriber_exits_0(port, spawn: Spawn):
    got: list[Any] = []
    port.create_subscription("estop", "std_msgs/msg/Empty", got.append)
    pub = spawn("tdcm_ros.cli.main", "topic", "pub", "estop", "std_msgs/msg/Empty", "{}",
                "--once", "--wait-matching", "15")
    out, err = pub.communicate(timeout=30)
    assert pub.returncode == 0, err.decode()
    assert "publishing #1" in out.decode()


def test_echo_refuses_a_negative_wait(capsys):
    from tdcm_ros.cli.main import main

    assert main(["topic", "echo", "chatter", "--wait-matching", "-1"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--wait-matching = -1.0 s must be >= 0" in err


def test_the_readme_example_header_auto_reaches_model_node_and_each_message_is_printed(
        context, spawn: Spawn):
    """``{header: auto}`` stamps each message as it is sent, so model_node solves it (an unset
    stamp is dropped as unstamped); every message is printed as one line of YAML."""
    tips: list[Any] = []
    context.create_port("probe").create_subscription("tip_pose", "geometry_msgs/msg/PoseStamped",
                                                     tips.append)
    spawn("tdcm_ros.runtime.run_node", "tdcm_ros.nodes.model_node:ModelNode")
    pub = spawn("tdcm_ros.cli.main", "topic", "pub", "tension",
                "geometry_msgs/msg/WrenchStamped", "{header: auto, wrench: {force: {z: 20.0}}}",
                "--rate", "10", "--times", "40", "--wait-matching", "30")
    eventually(lambda: tips, 60.0, "tip_pose for a stamped tension", spin=context)
    out, err = pub.communicate(timeout=60)
    assert pub.returncode == 0, err.decode()
    lines = [line for line in out.decode().splitlines() if line.startswith("publishing #")]
    assert len(lines) == 40
    first = yaml.safe_load(lines[0].split(": ", 1)[1])
    assert first["wrench"]["force"]["z"] == 20.0 and first["header"]["stamp"]["sec"] > 0
    stamps = [yaml.safe_load(line.split(": ", 1)[1])["header"]["stamp"] for line in lines]
    assert len({(s["sec"], s["nanosec"]) for s in stamps}) == 40  # stamped at each publish


def test_echo_of_a_transient_local_topic_prints_the_latest_message_it_missed(port, spawn: Spawn):
    """As ros2 topic echo: every publisher transient local, so the tool subscribes so too and
    gets the message published before it started (e.g. the controller's latched target)."""
    from tdcm_ros.runtime import QoS

    latched = port.create_publisher("latched", "std_msgs/msg/String",
                                    QoS(depth=1, durability="transient_local"))
    latched.publish(from_dict("std_msgs/msg/String", {"data": "sent before the tool"}))
    echo = spawn("tdcm_ros.cli.main", "topic", "echo", "latched", "--once")
    out, err = echo.communicate(timeout=20)
    assert echo.returncode == 0, err.decode()
    assert documents(out) == [{"data": "sent before the tool"}]
