"""``tdcm record`` on both runtimes (see conftest.py): stopped by SIGINT/SIGTERM, killed, bad input."""

from __future__ import annotations

import itertools
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml
from mcap.reader import make_reader

from tdcm_ros.bagio import BagError, from_dict, serialize
from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.bagio.typestore import typestore
from tdcm_ros.bagio.writer import BagWriter
from tdcm_ros.cli.main import main
from test.support.processes import Lines
from test.support.waiting import eventually

REPO = Path(__file__).resolve().parents[2]
RATE_HZ = 200.0

# On the runtime of TDCM_RUNTIME: publishes /count (std_msgs/Float64, data = 1, 2, ...) at
# RATE_HZ, one transient-local /latched (std_msgs/String) and, with argv[2], one /kv
# (diagnostic_msgs/KeyValue); appends "<n> <publish time ns>" per message to the file argv[1].
PUBLISHER = f"""
import os, sys, time
from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.port import QoS
from tdcm_ros.runtime.run_node import open_context

context = open_context(os.environ["TDCM_RUNTIME"])
port = context.create_port("counter")
count = port.create_publisher("/count", "std_msgs/msg/Float64")
latched = port.create_publisher("/latched", "std_msgs/msg/String",
                                QoS(depth=1, durability="transient_local"))
latched.publish(from_dict("std_msgs/msg/String", {{"data": "tdcm_base"}}))
kv = port.create_publisher("/kv", "diagnostic_msgs/msg/KeyValue") if sys.argv[2:] else None
with open(sys.argv[1], "w") as log:
    n = 0
    while True:
        n += 1
        stamp = time.time_ns()
        count.publish(from_dict("std_msgs/msg/Float64", {{"data": float(n)}}))
        if kv is not None:
            kv.publish(from_dict("diagnostic_msgs/msg/KeyValue", {{"key": "n"}}))
        log.write(f"{{n}} {{stamp}}\\n")
        log.flush()
        time.sleep({1.0 / RATE_HZ})
"""
Spawn = Callable[..., subprocess.Popen[bytes]]


def _published(log: Path) -> list[tuple[int, int]]:
    rows = [line.split() for line in log.read_text().splitlines()]
    return [(int(r[0]), int(r[1])) for r in rows if len(r) == 2]


def _start_publisher(env: dict[str, str], log: Path, *extra: str) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, "-c", PUBLISHER, str(log), *extra], env=env, cwd=REPO,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _record_until(spawn: Spawn, env: dict[str, str], tmp_path: Path, stop: signal.Signals
                  ) -> tuple[Path, list[tuple[int, int]], int, subprocess.Popen[bytes], Lines]:
    """Record a running publisher, send ``stop`` after ~200 messages; returns what happened."""
    log, bag = tmp_path / "published.txt", tmp_path / "bag"
    publisher = _start_publisher(env, log)
    try:
        eventually(lambda: log.exists() and len(_published(log)) > 0, 20.0, "the publisher")
        recorder = spawn("tdcm_ros.cli.main", "record", str(bag))
        out = Lines(recorder)
        eventually(lambda: out.has("subscribed /count") and out.has("subscribed /latched"), 20.0,
                 "the recorder to subscribe")
        first = len(_published(log))
        eventually(lambda: len(_published(log)) > first + 200, 20.0, "200 more messages")
        signalled_ns = time.time_ns()
        recorder.send_signal(stop)
        recorder.wait(20.0)
    finally:
        publisher.kill()
        publisher.wait()
    return bag, _published(log), signalled_ns, recorder, out


def _counts(bag: Path) -> tuple[list[int], int]:
    reader = open_bag(bag)
    values = [int(m.data) for _, _, m in reader.messages(["/count"])]
    return values, reader.counts.get("/latched", 0)


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM])
def test_signal_closes_a_bag_with_every_message_before_it(
        runtime: str, spawn: Spawn, graph_env: dict[str, str], tmp_path: Path,
        stop: signal.Signals) -> None:
    bag, published, signalled_ns, recorder, out = _record_until(spawn, graph_env, tmp_path, stop)
    assert recorder.returncode == 0, recorder.stderr.read() if recorder.stderr else ""
    assert (bag / "metadata.yaml").is_file()
    values, latched_count = _counts(bag)
    assert latched_count == 1  # transient-local, published before the recorder started
    assert values == list(range(values[0], values[-1] + 1))  # no gap
    # everything published 0.2 s (loopback delivery allowance) before the signal is in the bag
    before = max(n for n, stamp in published if stamp < signalled_ns - 200_000_000)
    assert values[-1] >= before
    eventually(lambda: out.has("messages in"), 5.0, "the summary")
    assert any(line.startswith(f"/count [std_msgs/msg/Float64]: {len(values)} messages")
               for line in out.lines)
    reader = open_bag(bag)
    assert {"/count": "std_msgs/msg/Float64", "/latched": "std_msgs/msg/String"}.items() <= \
        reader.topics.items()
    # the sender's clock and sequence number reach the bag on both runtimes
    stamps = dict(published)
    rows: list[tuple[int, int, Any]] = []
    with open(next(bag.glob("*.mcap")), "rb") as stream:
        decode = typestore().deserialize_cdr
        for _, _, record in make_reader(stream).iter_messages(topics=["/count"]):
            n = int(decode(record.data, "std_msgs/msg/Float64").data)
            rows.append((stamps[n], n, record))
    assert len(rows) == len(values)
    assert all(abs(record.publish_time - sent) < 100_000_000 and record.log_time >= sent
               for sent, _, record in rows)
    assert all(b.sequence - a.sequence == m - n > 0
               for (_, n, a), (_, m, b) in itertools.pairwise(rows))


def test_sigkill_leaves_a_bag_readable_to_the_last_chunk(
        runtime: str, spawn: Spawn, graph_env: dict[str, str], tmp_path: Path) -> None:
    bag, published, killed_ns, recorder, _ = _record_until(spawn, graph_env, tmp_path,
                                                           signal.SIGKILL)
    assert recorder.returncode == -signal.SIGKILL
    assert not (bag / "metadata.yaml").exists()
    reader = open_bag(bag)
    assert any("no metadata.yaml" in w for w in reader.warnings)
    values, _ = _counts(bag)
    assert values == list(range(values[0], values[-1] + 1))
    # the loss is bounded by the flush period (0.1 s) plus delivery; 1 s is a generous bound
    before = max(n for n, stamp in published if stamp < killed_ns - 1_000_000_000)
    assert values[-1] >= before
    lost = max(n for n, stamp in published if stamp < killed_ns) - values[-1]
    print(f"SIGKILL at {RATE_HZ:.0f} Hz on {runtime} lost the last {lost} messages")


TICKS = 3000  # messages of the 1 kHz ticker (3 s)

# On the runtime of TDCM_RUNTIME: waits (up to 60 s, else exits 1) until its publisher matches
# the recorder's subscription, publishes /tick (std_msgs/UInt32, data = 0, 1, ...) TICKS times at
# 1 kHz, lets the tail be delivered for 1 s, closes and exits. The wait is what makes the head
# deterministic: "recording to" says the recorder declared its subscription, not that the zenoh
# router routes it yet, and on rclpy the recorder subscribes only once discovery has shown it
# the ticker's publisher (it takes the type from the graph; 3 s of ticks ended before that once).
TICKER = f"""
import os, sys, time
from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.run_node import open_context

context = open_context(os.environ["TDCM_RUNTIME"])
ticks = context.create_port("ticker").create_publisher("/tick", "std_msgs/msg/UInt32")
deadline = time.monotonic() + 60.0
while not ticks.matched():
    if time.monotonic() > deadline:
        sys.exit("the recorder's subscription never matched /tick")
    context.spin_for(0.02)
due = time.monotonic()
for n in range({TICKS}):
    ticks.publish(from_dict("std_msgs/msg/UInt32", {{"data": n}}))
    due += 0.001
    time.sleep(max(0.0, due - time.monotonic()))
context.spin_for(1.0)
context.close()
"""


def _last_tick(bag: Path) -> int:
    """The last /tick the recorder has written so far (-1: none yet or not readable yet)."""
    try:
        values = [int(m.data) for _, _, m in open_bag(bag).messages(["/tick"])]
    except (BagError, OSError):
        return -1
    return values[-1] if values else -1


def test_a_named_topic_is_recorded_from_its_first_message_to_its_last(
        runtime: str, spawn: Spawn, graph_env: dict[str, str], tmp_path: Path) -> None:
    """A 1 kHz publisher that starts after the recorder: zenoh loses 0 at the head (the topic is
    subscribed, and routed by the router, before any publisher exists); both lose 0 at the tail
    (SIGINT comes once the last tick is in the bag)."""
    bag = tmp_path / "bag"
    recorder = spawn("tdcm_ros.cli.main", "record", str(bag), "tick")
    out = Lines(recorder)
    eventually(lambda: out.has("recording to"), 20.0, "the recorder to start")
    ticker = subprocess.run([sys.executable, "-c", TICKER], check=False, env=graph_env,
                            cwd=REPO, capture_output=True, timeout=120.0)
    assert ticker.returncode == 0, ticker.stderr.decode()
    # the ticker has sent its last tick, which may still be on its way (through the router, or
    # in the recorder's queue on a loaded machine): a SIGINT now would close the recorder's
    # session before it arrives. The bag is readable while it is written (to its last chunk).
    eventually(lambda: _last_tick(bag) == TICKS - 1, 30.0, "the recorder to write the last tick",
               detail=lambda: f"its last tick so far: {_last_tick(bag)}")
    recorder.send_signal(signal.SIGINT)
    recorder.wait(20.0)
    assert recorder.returncode == 0, recorder.stderr.read() if recorder.stderr else ""
    values = [int(m.data) for _, _, m in open_bag(bag).messages(["/tick"])]
    print(f"1 kHz ticker on {runtime}: lost {values[0] if values else TICKS} at the head, "
          f"{TICKS - 1 - values[-1] if values else TICKS} at the tail of {TICKS}")
    assert values == list(range(values[0], TICKS))  # contiguous, nothing lost at the tail
    if runtime == "zenoh":
        assert values[0] == 0


def test_named_topics_keep_the_offered_qos_and_the_latched_message(
        runtime: str, spawn: Spawn, graph_env: dict[str, str], tmp_path: Path) -> None:
    """Named topics of a publisher running before the recorder: the transient-local message
    published before the start is recorded, and the bag carries the offered QoS."""
    log, bag = tmp_path / "published.txt", tmp_path / "bag"
    publisher = _start_publisher(graph_env, log)
    try:
        eventually(lambda: log.exists() and len(_published(log)) > 0, 20.0, "the publisher")
        recorder = spawn("tdcm_ros.cli.main", "record", str(bag), "count", "latched")
        out = Lines(recorder)
        eventually(lambda: out.has("subscribed /count") and out.has("subscribed /latched"), 20.0,
                 "the recorder to subscribe")
        first = len(_published(log))
        eventually(lambda: len(_published(log)) > first + 50, 20.0, "50 more messages")
        recorder.send_signal(signal.SIGINT)
        recorder.wait(20.0)
    finally:
        publisher.kill()
        publisher.wait()
    assert recorder.returncode == 0
    values, latched_count = _counts(bag)
    assert latched_count == 1 and values == list(range(values[0], values[-1] + 1))
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    qos = {t["topic_metadata"]["name"]: t["topic_metadata"]["offered_qos_profiles"][0]
           for t in meta["topics_with_message_count"]}
    assert qos["/latched"]["durability"] == "transient_local"
    assert qos["/count"]["durability"] == "volatile"
    if runtime == "zenoh":  # DDS discovery does not carry the depth (see README)
        assert qos["/latched"]["depth"] == 1

# rclpy only: on zenoh the recorder needs no per-type code, so every type it can name is recorded.
@pytest.mark.parametrize("runtime", [pytest.param("rclpy", marks=pytest.mark.rclpy)],
                         indirect=True)
def test_a_type_without_an_rclpy_class_is_reported_and_skipped(
        runtime: str, graph_env: dict[str, str], tmp_path: Path) -> None:
    shadow = tmp_path / "shadow" / "diagnostic_msgs"   # the package, without its msg classes
    (shadow / "msg").mkdir(parents=True)
    (shadow / "__init__.py").write_text("")
    (shadow / "msg" / "__init__.py").write_text("")
    log, bag = tmp_path / "published.txt", tmp_path / "bag"
    publisher = _start_publisher(graph_env, log, "kv")
    env = {**graph_env, "PYTHONPATH": os.pathsep.join([str(shadow.parent),
                                                       graph_env["PYTHONPATH"]])}
    recorder = subprocess.Popen([sys.executable, "-m", "tdcm_ros.cli.main", "record", str(bag),
                                 "count", "kv"], env=env, cwd=REPO,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        out = Lines(recorder)
        eventually(lambda: out.has("subscribed /count"), 20.0, "the recorder to subscribe")
        eventually(lambda: len(_published(log)) > 100, 20.0, "100 messages")
        recorder.send_signal(signal.SIGINT)
        recorder.wait(20.0)
    finally:
        for child in (publisher, recorder):
            if child.poll() is None:
                child.kill()
            child.wait()
    assert recorder.returncode == 0
    assert recorder.stderr is not None
    err = recorder.stderr.read().decode()
    assert "not recording /kv [diagnostic_msgs/msg/KeyValue]" in err and "importable" in err, err
    assert open_bag(bag).topics == {"/count": "std_msgs/msg/Float64"}
    assert "never published: /kv" in err


def _one_line_error(capsys: pytest.CaptureFixture[str], args: list[str], text: str) -> None:
    """``tdcm ARGS`` exits 2 with one line on stderr naming ``text`` (no traceback)."""
    assert main(args) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and text in lines[0], lines


def test_record_refuses_an_existing_bag(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "bag").mkdir()
    _one_line_error(capsys, ["record", str(tmp_path / "bag")], "refusing to overwrite")
    _one_line_error(capsys, ["record", str(tmp_path / "new"), "--duration", "-1"], "--duration")
    assert not (tmp_path / "new").exists()


def test_bag_info_bad_inputs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _one_line_error(capsys, ["bag", "info", str(tmp_path / "absent")], "no such bag")
    (tmp_path / "corrupt.mcap").write_bytes(b"\x89MCAP0\r\n" + bytes(range(256)) * 4)
    _one_line_error(capsys, ["bag", "info", str(tmp_path / "corrupt.mcap")],
                    "no message can be recovered")
    (tmp_path / "notes.txt").write_text("not a bag")
    _one_line_error(capsys, ["bag", "info", str(tmp_path / "notes.txt")], "not a bag")
    with BagWriter(tmp_path / "empty") as writer:
        writer.add_topic("/tension", "geometry_msgs/msg/WrenchStamped")
    _one_line_error(capsys, ["bag", "info", str(tmp_path / "empty")], "empty bag")


def test_bag_info_lists_topics(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with BagWriter(tmp_path / "bag") as writer:
        writer.add_topic("/x", "std_msgs/msg/Float64")
        writer.write("/x", 1, serialize(from_dict("std_msgs/msg/Float64", {"data": 1.0})))
    assert main(["bag", "info", str(tmp_path / "bag")]) == 0
    assert "  /x [std_msgs/msg/Float64]: 1" in capsys.readouterr().out.splitlines()


def test_recorder_in_process_stops_at_max_messages(runtime: str, tmp_path: Path) -> None:
    """The Recorder class: named topic (short name), max_messages, a topic that never appears."""
    from tdcm_ros.recording import Recorder
    from tdcm_ros.runtime.run_node import open_context

    context = open_context(runtime)
    publisher = context.create_port("counter").create_publisher("/count", "std_msgs/msg/Float64")
    stop = threading.Event()

    def publish() -> None:
        n = 0
        while not stop.is_set():
            n += 1
            publisher.publish(from_dict("std_msgs/msg/Float64", {"data": float(n)}))
            time.sleep(0.005)

    thread = threading.Thread(target=publish, daemon=True)
    thread.start()
    try:
        recorder = Recorder(BagWriter(tmp_path / "bag"), ["count", "/absent"], runtime=runtime,
                            max_messages=20)
        recorder.run(duration_s=30.0)
        assert recorder.stopping and recorder.total == 20
        recorder.close()
    finally:
        stop.set()
        thread.join()
        context.close()
    assert recorder.missing == ["/absent"]
    values = [m.data for _, _, m in open_bag(tmp_path / "bag").messages()]
    assert len(values) == 20 and values == [values[0] + i for i in range(20)]


def test_recorder_refuses_an_unknown_runtime(tmp_path: Path) -> None:
    from tdcm_ros.errors import InputError
    from tdcm_ros.recording import Recorder

    with BagWriter(tmp_path / "bag") as writer, pytest.raises(
            InputError, match="runtime = 'dds'.*allowed: zenoh, rclpy"):
        Recorder(writer, runtime="dds")


def test_a_recording_that_wrote_nothing_exits_non_zero(runtime: str, spawn: Spawn,
                                                       tmp_path: Path) -> None:
    recorder = spawn("tdcm_ros.cli.main", "record", str(tmp_path / "bag"), "/never_published",
                     "--duration", "1")
    recorder.wait(30.0)
    err = recorder.stderr.read().decode() if recorder.stderr else ""
    assert recorder.returncode == 1, err
    assert "no message was recorded; the bag is empty" in err


# On the zenoh runtime: once its publisher matches, 3,000 strings of 1 KiB (random hex: zstd
# halves them) on /tick as fast as it can (1.5 MiB in the bag: past the recorder's file-size
# limit below).
BIG_TICKER = """
import os
from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.run_node import open_context

context = open_context("zenoh")
ticks = context.create_port("ticker").create_publisher("/tick", "std_msgs/msg/String")
while not ticks.matched():
    context.spin_for(0.02)
for n in range(3000):
    ticks.publish(from_dict("std_msgs/msg/String", {"data": f"{n:08d}" + os.urandom(508).hex()}))
context.spin_for(1.0)
context.close()
"""


def test_a_full_disk_stops_the_recording_with_a_readable_bag_and_a_summary(
        zenoh_env: dict[str, str], router: subprocess.Popen[bytes], tmp_path: Path) -> None:
    """The recorder under a file-size limit (``RLIMIT_FSIZE``: a write fails as on a full disk)
    while 3 MiB of strings arrive: it stops by itself, exits 3, says what the bag keeps and how
    many received messages were lost, and the bag reads back as that many messages, with
    ``metadata.yaml``."""
    import resource

    from tdcm_ros.bagio.writer import RESERVE_BYTES

    limit = RESERVE_BYTES + 100_000  # bytes per file (the reserve file must fit)

    def limited() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    bag = tmp_path / "bag"
    recorder = subprocess.Popen([sys.executable, "-m", "tdcm_ros.cli.main", "record", str(bag),
                                 "tick"], env=zenoh_env, cwd=REPO, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE,
                                preexec_fn=limited)  # noqa: PLW1509 - it only sets a limit
    try:
        out = Lines(recorder)
        eventually(lambda: out.has("recording to"), 20.0, "the recorder to start")
        ticker = subprocess.run([sys.executable, "-c", BIG_TICKER], check=False,
                                env=zenoh_env, cwd=REPO, capture_output=True, timeout=120.0)
        assert ticker.returncode == 0, ticker.stderr.decode()
        status = recorder.wait(30)
    finally:
        if recorder.poll() is None:
            recorder.kill()
            recorder.wait()
    assert recorder.stderr is not None and recorder.stdout is not None
    err = recorder.stderr.read().decode()
    assert status == 3, (err, out.lines)
    assert "File too large" in err and "stopping the recording" in err, err
    kept = int(err.split("the bag keeps the ")[1].split()[0])
    lost = int(err.split("metadata.yaml written); ")[1].split()[0])
    values = [int(m.data[:8]) for _, _, m in open_bag(bag).messages(["/tick"])]
    assert len(values) == kept > 0 and values == sorted(values) and lost > 0
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["message_count"] == kept
