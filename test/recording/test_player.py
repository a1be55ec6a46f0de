"""``tdcm bag play`` on both runtimes (see conftest.py): a peer takes what the player publishes
as raw CDR bytes and compares it with the bag (:mod:`player_peers`)."""

from __future__ import annotations

import itertools
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.bagio import deserialize
from tdcm_ros.recording.player import MAX_DEPTH, VOLATILE_DEPTH, played_depth
from tdcm_ros.runtime.port import CLOCK_QOS, CLOCK_TOPIC, CLOCK_TYPE, QoS
from test.recording.player_peers import (
    FIRST_BURST,
    GAP_S,
    SECOND_BURST,
    STEP_NS,
    T0_NS,
    TYPES,
    RawPeer,
    interrupt,
    on,
    sample_messages,
    write_bag,
)
from test.runtime.pty_helpers import run_on_terminal

Spawn = Callable[..., subprocess.Popen[bytes]]
REPO = Path(__file__).resolve().parents[2]
PLAY = ("tdcm_ros.cli.main", "bag", "play")
#: Wall time (s) between the player's publishers and its first message: lets the peer's
#: subscriptions match them (DDS discovery on rclpy; the router's declarations on zenoh).
DELAY = {"zenoh": "0.5", "rclpy": "5.0"}


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    return write_bag(tmp_path / "sample", sample_messages())


def as_received(runtime: str, payloads: list[bytes]) -> list[bytes]:
    """What a subscriber receives of ``payloads`` sent unchanged: on rclpy (Fast DDS) the RTPS
    DATA submessage pads a serialized payload with zeros to a multiple of 4 bytes, and the
    receiver cannot tell them from the payload (``ros2 bag play`` meets the same)."""
    if runtime == "zenoh":
        return payloads
    return [data + bytes(-len(data) % 4) for data in payloads]


def play(spawn: Spawn, runtime: str, bag: Path, *args: str) -> subprocess.Popen[bytes]:
    return spawn(*PLAY, str(bag), "--delay", DELAY[runtime], *args)


def test_the_peer_receives_the_bags_bytes_in_order(runtime: str, context: Any, spawn: Spawn,
                                                  bag: Path) -> None:
    messages = sample_messages()
    peer = RawPeer(context)
    for topic, type_name in TYPES.items():
        peer.subscribe(topic, type_name)
    player = play(spawn, runtime, bag, "--rate", "4")
    assert peer.spin_while_running(player, 60.0) == 0, player.stderr.read().decode()
    peer.spin_until(lambda: len(peer.got) >= len(messages), 10.0,
                    f"every message ({len(messages)}; the first ones are lost if the player's "
                    f"publishers had not matched the peer within --delay)")
    for topic in TYPES:
        assert peer.on(topic) == as_received(runtime, on(messages, topic)), topic
    assert len(peer.got) == len(messages)
    out = player.stdout.read().decode()
    assert "[playing]" not in player.stderr.read().decode()      # stderr is not a terminal
    assert "publishing /latched [std_msgs/msg/String] (reliable, transient_local, depth 1)" in out
    assert f"{len(messages)} messages published on 3 topics" in out
    # x4: the bag's 4 s gap between the bursts of /a lasts ~1 s (never less: nothing is sent
    # early; far below the unscaled 4 s)
    arrivals = peer.arrivals("/a")
    gap = arrivals[FIRST_BURST] - arrivals[FIRST_BURST - 1]
    assert GAP_S / 4 * 0.5 < gap < GAP_S * 0.75, gap


def test_offset_topic_selection_and_remapping(runtime: str, context: Any, spawn: Spawn,
                                              bag: Path) -> None:
    messages = sample_messages()
    peer = RawPeer(context)
    for topic in ("/a", "/b", "/renamed"):
        peer.subscribe(topic, TYPES["/a"] if topic == "/renamed" else TYPES[topic])
    player = play(spawn, runtime, bag, "--rate", "4", "--start-offset", "1.0",
                  "--topics", "/a", "/latched", "--remap", "/a:=/renamed")
    assert peer.spin_while_running(player, 60.0) == 0, player.stderr.read().decode()
    expected = [data for topic, stamp, data in messages
                if topic == "/a" and stamp >= T0_NS + 1_000_000_000]
    assert 0 < len(expected) < FIRST_BURST + SECOND_BURST
    peer.spin_until(lambda: len(peer.on("/renamed")) >= len(expected), 10.0, "/renamed")
    assert peer.on("/renamed") == as_received(runtime, expected)
    assert peer.on("/a") == [] and peer.on("/b") == []
    out = player.stdout.read().decode()
    assert "publishing /renamed [std_msgs/msg/String] (reliable, volatile, depth 1000) from /a" in out
    # /latched's only message lies before the offset: nothing of it is played
    assert f"{len(expected)} messages published on 2 topics" in out


def test_a_late_subscriber_gets_the_transient_local_topic_and_ctrl_c_exits_130(
        runtime: str, context: Any, spawn: Spawn, bag: Path) -> None:
    messages = sample_messages()
    peer = RawPeer(context)
    peer.subscribe("/a", TYPES["/a"])
    player = play(spawn, runtime, bag)
    peer.spin_until(lambda: len(peer.on("/a")) >= 3, 30.0, "the first /a messages")
    # /latched went out before this subscription existed: the recorded QoS keeps it for us
    peer.subscribe("/latched", TYPES["/latched"], QoS(depth=1, durability="transient_local"))
    peer.spin_until(lambda: len(peer.on("/latched")) == 1, 10.0, "/latched as a late joiner")
    assert peer.on("/latched") == as_received(runtime, on(messages, "/latched"))
    assert player.poll() is None            # still in the first burst or the gap
    status, err = interrupt(player)
    assert status == 130, err
    assert "Traceback" not in err


def test_loop_plays_the_bag_again_until_ctrl_c(runtime: str, context: Any, spawn: Spawn,
                                               bag: Path) -> None:
    first = as_received(runtime, on(sample_messages(), "/a"))
    peer = RawPeer(context)
    peer.subscribe("/a", TYPES["/a"])
    player = play(spawn, runtime, bag, "--rate", "8", "--loop", "--topics", "a", "--quiet")
    peer.spin_until(lambda: len(peer.on("/a")) > 2 * len(first), 60.0, "a third pass")
    status, err = interrupt(player)
    assert status == 130 and "Traceback" not in err, err
    got = peer.on("/a")
    assert got == (first * 4)[:len(got)]


def test_clock_carries_the_bag_time(runtime: str, context: Any, spawn: Spawn,
                                    bag: Path) -> None:
    messages = sample_messages()
    peer = RawPeer(context)
    peer.subscribe(CLOCK_TOPIC, CLOCK_TYPE, CLOCK_QOS)
    player = play(spawn, runtime, bag, "--rate", "2", "--clock", "50")
    assert peer.spin_while_running(player, 60.0) == 0, player.stderr.read().decode()
    ticks = [deserialize(data, CLOCK_TYPE).clock for data in peer.on(CLOCK_TOPIC)]
    times = [int(c.sec) * 10**9 + int(c.nanosec) for c in ticks]
    # ~3 s of playing at 50 Hz; best effort and keep-last 1: some may be lost; the player sends
    # them in order, and only the moment zenoh's gossip opens a direct link between the two peers
    # (samples in flight through the router overtaken) may swap one (seen once in ~10 runs)
    assert len(times) > 75
    assert sum(later < earlier for earlier, later in itertools.pairwise(times)) <= 1
    assert T0_NS <= times[0] < T0_NS + STEP_NS
    assert times[-1] >= messages[-1][1] - 2 * STEP_NS
    assert times[-1] <= messages[-1][1] + 2 * STEP_NS


def _stderr_on_a_terminal(env: dict[str, str], *argv: str) -> str:
    """Run ``tdcm bag play`` with stderr on a pseudo-terminal; what it wrote there."""
    import sys

    status, _, terminal = run_on_terminal([sys.executable, "-m", *PLAY, *argv], env=env, cwd=REPO,
                                          timeout=60, columns=None)
    assert status == 0
    return terminal


def test_a_progress_line_on_a_terminal_unless_quiet(router: Any, zenoh_env: dict[str, str],
                                                    bag: Path) -> None:
    shown = _stderr_on_a_terminal(zenoh_env, str(bag), "--rate", "4")
    assert "\r[playing] " in shown and f"/ 5.97 s  x4  {len(sample_messages())} messages" in shown
    assert "[playing]" not in _stderr_on_a_terminal(zenoh_env, str(bag), "--rate", "4",
                                                    "--quiet")


@pytest.mark.parametrize(("offered", "durability", "played"), [
    (10, "volatile", VOLATILE_DEPTH),        # recorded shallow: deepened
    (5000, "volatile", 5000),                # recorded deeper: kept
    (10**6, "volatile", MAX_DEPTH),
    (1, "transient_local", 1),               # what a late joiner gets: as recorded
    (0, "transient_local", 1),
    (10**6, "transient_local", MAX_DEPTH),
])
def test_a_volatile_topic_is_played_with_a_deep_history(offered: int, durability: str,
                                                         played: int) -> None:
    """A reliable keep-last writer drops unacknowledged samples once its history is full: a
    volatile topic recorded at depth 10 is played at least 1000 deep, so a reader starved of CPU
    for a moment loses nothing; a transient-local one keeps its recorded depth."""
    assert played_depth(offered, durability) == played


@pytest.mark.parametrize(("args", "expected"), [
    (["--rate", "0"], "rate = 0.0 is out of range; allowed: (0, inf)"),
    (["--rate", "nan"], "rate = nan is out of range"),
    (["--start-offset", "-1"], "start_offset_s = -1.0 s is out of range; allowed: [0, inf) s"),
    (["--start-offset", "60"], "start_offset_s = 60.0 s is out of range; allowed: [0, 5.975] s"),
    (["--clock", "-5"], "clock_hz = -5.0 Hz is out of range; allowed: 0 (off) or (0, 10000] Hz"),
    (["--remap", "/a=/b"], "--remap '/a=/b' is invalid; allowed: OLD:=NEW"),
    (["--topics", "/nope"], "no topic '/nope'; topics: /a [std_msgs/msg/String]"),
])
def test_bad_input_is_one_line_naming_the_parameter(bag: Path, args: list[str],
                                                    expected: str) -> None:
    import sys

    done = subprocess.run([sys.executable, "-m", *PLAY, str(bag), *args, "--runtime", "zenoh"],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 2, done.stderr
    assert expected in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def _reader(context: Any, name: str, topic: str, *, sim_time: bool) -> None:
    """A node of the test's runtime subscribed to ``topic``, on ``/clock`` if ``sim_time``."""
    from test.support.plain_rclpy import PlainRclpyContext

    if isinstance(context, PlainRclpyContext):
        from rclpy.parameter import Parameter

        port = context.create_port(name)
        port.node.set_parameters([Parameter("use_sim_time", value=sim_time)])
    else:
        port = context.create_port(name, overrides={"use_sim_time": sim_time})
    port.create_subscription(topic, TYPES[topic], lambda _: None)


def test_clock_names_each_reader_of_a_played_topic_on_wall_time(
        runtime: str, context: Any, spawn: Spawn, bag: Path) -> None:
    """With ``--clock``, a node that reads a played topic on wall time drops the bag's stamps
    as stale: the player names it; nodes on /clock and hidden tools are not named."""
    _reader(context, "wall_reader", "/a", sim_time=False)
    _reader(context, "sim_reader", "/b", sim_time=True)
    _reader(context, "_tool_reader", "/latched", sim_time=False)
    player = play(spawn, runtime, bag, "--clock", "50")
    assert RawPeer(context).spin_while_running(player, 60.0) == 0
    stderr = player.stderr.read().decode()
    assert ("WARNING: /wall_reader reads /a on wall time (use_sim_time false)" in stderr), stderr
    assert "sim_reader" not in stderr and "_tool_reader" not in stderr
