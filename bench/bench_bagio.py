"""Bag I/O benchmark (issue 6): write/read throughput of a 10-minute trial and recording loss.

Run: ``python bench/bench_bagio.py [--minutes 10] [--kills 3] [--results FILE]``. Prints

- write throughput of :class:`BagWriter` (messages/s) for a trial at 1 kHz tension
  (WrenchStamped) + 100 Hz markers (Markers, 3 markers): 660k messages for 10 minutes;
- read throughput of ``open_bag``: raw CDR (``raw_messages``) and decoded (``messages``);
- how many messages ``tdcm record`` loses when it is stopped by SIGINT or SIGKILL while a
  publisher sends the same mix live (1 kHz + 100 Hz) over the embedded zenoh runtime
  (a private router on a free port). "Lost" = published before the signal, absent from the bag.

``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from results import BenchResults, Column, add_results_argument

from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.bagio.writer import DEFAULT_CHUNK_SIZE, DEFAULT_FLUSH_PERIOD_S, BagWriter

REPO = Path(__file__).resolve().parents[1]
T0 = 1_700_000_000_000_000_000
TENSION_HZ, MARKERS_HZ = 1000, 100

# Publishes /tension at 1 kHz and /markers at 100 Hz (data: sequence numbers in force.z and
# frame_number); logs "<topic> <n> <time ns>" per message to argv[1].
PUBLISHER = """
import sys, time
from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.zenoh_runtime import ZenohContext

port = ZenohContext().create_port("bench_publisher")
tension = port.create_publisher("/tension", "geometry_msgs/msg/WrenchStamped")
markers = port.create_publisher("/markers", "mocap4r2_msgs/msg/Markers")
period, start, n = 0.001, time.monotonic(), 0
with open(sys.argv[1], "w") as log:
    while True:
        n += 1
        tension.publish(from_dict("geometry_msgs/msg/WrenchStamped",
                                  {"wrench": {"force": {"z": float(n)}}}))
        log.write(f"t {n} {time.time_ns()}\\n")
        if n % 10 == 0:
            markers.publish(from_dict("mocap4r2_msgs/msg/Markers", {"frame_number": n // 10,
                "markers": [{"marker_name": f"m{j}"} for j in (1, 2, 3)]}))
            log.write(f"m {n // 10} {time.time_ns()}\\n")
        log.flush()
        time.sleep(max(0.0, start + n * period - time.monotonic()))
"""


def trial_messages(minutes: float) -> list[tuple[str, int, bytes]]:
    """(topic, log time, CDR) of a trial, serialised once per distinct payload shape."""
    out = []
    for i in range(int(minutes * 60 * TENSION_HZ)):
        stamp = T0 + i * 1_000_000
        wrench = from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9},
                       "frame_id": "tdcm_tendon"}, "wrench": {"force": {"z": 5.0 + i % 100}}})
        out.append(("/tension", stamp, serialize(wrench)))
        if i % (TENSION_HZ // MARKERS_HZ) == 0:
            markers = from_dict("mocap4r2_msgs/msg/Markers", {
                "header": {"frame_id": "mocap"}, "frame_number": i,
                "markers": [{"marker_name": f"m{j}", "translation": {"x": 0.001 * j, "z": 0.02}}
                            for j in (1, 2, 3)]})
            out.append(("/markers", stamp + 1, serialize(markers)))
    return out


def bench_files(minutes: float, folder: Path, results: BenchResults) -> None:
    messages = trial_messages(minutes)
    bag = folder / "trial"
    start = time.perf_counter()
    with BagWriter(bag) as writer:
        writer.add_topic("/tension", "geometry_msgs/msg/WrenchStamped")
        writer.add_topic("/markers", "mocap4r2_msgs/msg/Markers")
        for topic, stamp, data in messages:
            writer.write(topic, stamp, data)
    write_s = time.perf_counter() - start
    size = sum(f.stat().st_size for f in bag.iterdir())
    print(f"trial: {minutes:g} min, {len(messages)} messages, bag {size / 1e6:.1f} MB "
          f"(chunk {DEFAULT_CHUNK_SIZE // 1024} KiB, flush period {DEFAULT_FLUSH_PERIOD_S} s, zstd)")
    print(f"write:          {write_s:6.2f} s  {len(messages) / write_s:9.0f} messages/s")
    start = time.perf_counter()
    reader = open_bag(bag)
    count = sum(1 for _ in reader.raw_messages())
    raw_s = time.perf_counter() - start
    print(f"read raw CDR:   {raw_s:6.2f} s  {count / raw_s:9.0f} messages/s (open_bag + "
          f"raw_messages)")
    start = time.perf_counter()
    count = sum(1 for _ in reader.messages())
    decoded_s = time.perf_counter() - start
    print(f"read decoded:   {decoded_s:6.2f} s  {count / decoded_s:9.0f} messages/s (messages(), "
          f"rosbags objects)")
    results.table(
        f"Bag write and read: a {minutes:g} min trial",
        [Column("step"), Column("time", "s", ".2f"), Column("throughput", "messages/s", ",.0f")],
        [["write (BagWriter)", write_s, len(messages) / write_s],
         ["read raw CDR (open_bag + raw_messages)", raw_s, count / raw_s],
         ["read decoded (messages(), rosbags objects)", decoded_s, count / decoded_s]],
        note=f"{len(messages)} messages ({TENSION_HZ} Hz tension + {MARKERS_HZ} Hz markers), bag "
             f"{size / 1e6:.1f} MB (chunk {DEFAULT_CHUNK_SIZE // 1024} KiB, flush period "
             f"{DEFAULT_FLUSH_PERIOD_S} s, zstd)")


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _wait(predicate: object, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():  # type: ignore[operator]
        if time.monotonic() > deadline:
            raise TimeoutError("benchmark child did not start")
        time.sleep(0.05)


def _published(log: Path) -> list[tuple[str, int, int]]:
    rows = [line.split() for line in log.read_text().splitlines()]
    return [(r[0], int(r[1]), int(r[2])) for r in rows if len(r) == 3]


def record_once(folder: Path, env: dict[str, str], stop: signal.Signals, seconds: float
                ) -> tuple[int, int]:
    """Record the live publisher, send ``stop`` after ``seconds``; (published, lost)."""
    log, bag = folder / f"log_{stop.name}_{time.monotonic_ns()}", folder / f"bag_{time.monotonic_ns()}"
    publisher = subprocess.Popen([sys.executable, "-c", PUBLISHER, str(log)], env=env, cwd=REPO)
    recorder = subprocess.Popen([sys.executable, "-m", "tdcm_ros.cli.main", "record", str(bag)],
                                env=env, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    try:
        assert recorder.stdout is not None
        subscribed = 0
        while subscribed < 2:  # wait for both topics
            line = recorder.stdout.readline().decode()
            if not line:
                raise RuntimeError("tdcm record exited early")
            subscribed += line.startswith("subscribed")
        time.sleep(seconds)
        signalled = time.time_ns()
        recorder.send_signal(stop)
        recorder.wait(30)
    finally:
        publisher.kill()
        publisher.wait()
        if recorder.poll() is None:
            recorder.kill()
    reader = open_bag(bag)
    recorded = {("t", int(m.wrench.force.z)) for _, _, m in reader.messages(["/tension"])}
    recorded |= {("m", int(m.frame_number)) for _, _, m in reader.messages(["/markers"])}
    before = [(kind, n) for kind, n, stamp in _published(log) if stamp < signalled]
    first = {kind: min(n for k, n in recorded if k == kind) for kind in ("t", "m")}
    expected = [(kind, n) for kind, n in before if n >= first[kind]]
    return len(expected), sum(1 for item in expected if item not in recorded)


def bench_recording(kills: int, seconds: float, folder: Path, results: BenchResults) -> None:
    port = _free_port()
    env = {**os.environ, "TDCM_ZENOH_ENDPOINT": f"tcp/127.0.0.1:{port}", "ROS_DOMAIN_ID": "0",
           "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    router = subprocess.Popen([sys.executable, "-m", "tdcm_ros.runtime.router", "--listen",
                               f"tcp/127.0.0.1:{port}"], env=env, cwd=REPO,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        _wait(lambda: _connectable(port), 15.0)
        rows = []
        for stop in (signal.SIGINT, signal.SIGKILL):
            runs = [record_once(folder, env, stop, seconds) for _ in range(kills)]
            lost = [lost for _, lost in runs]
            print(f"tdcm record stopped by {stop.name} after {seconds:g} s at "
                  f"{TENSION_HZ} Hz + {MARKERS_HZ} Hz, {kills} runs: published before the "
                  f"signal {statistics.mean(p for p, _ in runs):.0f}, lost min/mean/max "
                  f"{min(lost)}/{statistics.mean(lost):.1f}/{max(lost)}")
            rows.append([stop.name, kills, statistics.mean(p for p, _ in runs), min(lost),
                         statistics.mean(lost), max(lost)])
        results.table(
            f"tdcm record stopped by a signal after {seconds:g} s",
            [Column("signal"), Column("runs"), Column("published before the signal", format=".0f"),
             Column("lost, min"), Column("lost, mean", format=".1f"), Column("lost, max")], rows,
            note=f"a live publisher at {TENSION_HZ} Hz + {MARKERS_HZ} Hz over the embedded zenoh "
                 "runtime (a private router); published before the signal: mean over the runs; "
                 "lost: published before the signal, absent from the bag")
    finally:
        router.send_signal(signal.SIGINT)
        router.wait(10)


def _connectable(port: int) -> bool:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=0.2):
            return True
    except OSError:
        return False


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0, help="trial length (min)")
    parser.add_argument("--kills", type=int, default=3, help="recordings per stop signal")
    parser.add_argument("--seconds", type=float, default=3.0, help="recording length (s)")
    add_results_argument(parser, "bench_bagio")
    args = parser.parse_args()
    results = BenchResults("bench_bagio")
    with tempfile.TemporaryDirectory() as tmp:
        bench_files(args.minutes, Path(tmp), results)
        if args.kills > 0:
            bench_recording(args.kills, args.seconds, Path(tmp), results)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
