"""Tension -> ``midline`` end-to-end latency of ``model_node`` across processes (issue 4).

Run: ``python bench/bench_latency.py [--runtime zenoh|rclpy|both] [--rates 100 500 1000]
[--duration 10] [--results FILE]`` or ``python bench/bench_latency.py --soak [--soak-duration 60]
[--soak-rate 1000] [--results FILE]``.
``--runtime`` defaults to ``both``: the runtimes are interleaved per rate (zenoh 100, rclpy 100,
zenoh 500, ...) in the same run, and a table of rclpy/zenoh ratios of p50 and p99 per rate
follows. Where rclpy is not importable (run it with the ROS virtual environment's Python,
``.ros/venv``, which ``bash .ci/ros.sh --prepare`` builds, its workspace sourced) the bench says
so and measures zenoh alone.

Per phase (one runtime, one rate) it starts a fresh stack, each its own process, as ``tdcm up``
does: on zenoh a private router (``tdcm_ros.runtime.router``) and ``model_node --runtime zenoh``;
on rclpy ``model_node --runtime rclpy`` and nothing else (DDS discovery; the caller's
``ROS_DOMAIN_ID`` and ``ROS_AUTOMATIC_DISCOVERY_RANGE`` apply). Only one stack runs at a time. A
tension publisher process on the same runtime sends ``geometry_msgs/WrenchStamped`` on ``tension``
(CDR bytes serialised once; the send time, ``time.time_ns``, is written into the header stamp
right before each publish). model_node stamps its outputs with the input's stamp, so this process
measures latency = receive time of a ``midline`` minus its stamp. The receive time is taken first
thing in the callback: on zenoh a session subscriber's callback (zenoh's thread), on rclpy a raw
subscription's callback (``RclpyNodePort.create_raw_subscription``, run by this process's
executor, so it includes this process's executor delay); the stamp is parsed from the CDR bytes.
Per phase it prints p50, p99 and max latency (ms), delivered/sent (inputs that produced a
midline; the rest were coalesced by the keep-latest node or lost), the coalesced inputs (newer
ones arrived during a solve: the node's cumulative ``coalesced`` counter), ``lost`` (sent minus
every tension the node's cumulative counters account for: solved, coalesced, dropped
(``dropped_<reason>``) and failed solves (``model_<kind>``); so inputs that never reached its
callback, e.g. beyond its subscription's depth of 100), the one-hop transport latency (``hop``:
publisher -> this process's listener on ``tension``, the same measurement without the node),
model_node's CPU (all its threads, so above 100 % is possible) and that CPU per solve (ms), and
the 1-min load average (the figures are only as good as an idle machine). The counters are the
union of the values of every ``model_node: ...`` status of one ``/diagnostics`` array (input
and solver), taken before and after the phase. ``--soak`` also samples model_node's RSS
(``VmRSS``) once a second and prints start, end and max RSS and the least-squares slope, per runtime.
``--results FILE`` also writes the printed figures as tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.bagio import from_dict, serialize, type_hash

MODEL = "tdcm_ros.nodes.model_node:ModelNode"
TENSION_N = 12.0
TENSION_TYPE = "geometry_msgs/msg/WrenchStamped"
RUNTIMES = ("zenoh", "rclpy")
NO_RCLPY = ("run this with the ROS virtual environment's Python, .ros/venv/bin/python, which "
            "`bash .ci/ros.sh --prepare` builds, its .ros/ws/install/setup.bash sourced")
_STAMP = struct.Struct("<iI")  # header.stamp (sec, nanosec) right after the 4-byte CDR header
_CDR_LE = b"\x00\x01"          # little-endian plain CDR encapsulation


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def rss_kib(pid: int) -> int:
    """Resident set size of ``pid`` (KiB) from ``/proc/<pid>/status``."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise RuntimeError(f"no VmRSS for pid {pid}")


def cpu_s(pid: int) -> float:
    """User + system CPU time (s) of ``pid`` from ``/proc/<pid>/stat``."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def rclpy_available() -> bool:
    return importlib.util.find_spec("rclpy") is not None


def open_context(runtime: str) -> Any:
    from tdcm_ros.runtime.run_node import open_context as open_runtime

    return open_runtime(runtime)


# -- publisher process ------------------------------------------------------------------------

def _ready(runtime: str, port: Any, publisher: Any) -> bool:
    """The publisher reaches model_node: zenoh key matched; on rclpy both subscribers discovered
    (model_node and this bench's one-hop listener)."""
    if runtime == "rclpy":
        return bool(port.node.count_subscribers(publisher.topic) >= 2)
    return bool(publisher.matched())


def publish(runtime: str, rate: float, duration: float, wait: float) -> None:
    """Publish ``tension`` at ``rate`` Hz for ``duration`` s; print a JSON summary on stdout."""
    context = open_context(runtime)
    try:
        port = context.create_port("bench_tension")
        publisher = port.create_publisher("tension", TENSION_TYPE)
        deadline = time.monotonic() + wait
        while not _ready(runtime, port, publisher):
            if time.monotonic() > deadline:
                raise SystemExit("bench publisher: no subscriber on `tension`")
            time.sleep(0.01)
        time.sleep(0.3)  # let the route settle
        message = from_dict(TENSION_TYPE, {
            "header": {"frame_id": "tdcm_tendon"}, "wrench": {"force": {"z": TENSION_N}}})
        data = bytearray(serialize(message, TENSION_TYPE))
        if data[:2] != _CDR_LE:
            raise SystemExit("bench publisher: expected little-endian CDR")
        period_ns = int(1e9 / rate)
        count = round(rate * duration)
        start = time.monotonic_ns()
        first_ns = last_ns = 0
        for k in range(count):
            due = start + k * period_ns
            while (left := due - time.monotonic_ns()) > 0:
                time.sleep(left / 1e9)
            now = time.time_ns()
            _STAMP.pack_into(data, 4, *divmod(now, 1_000_000_000))
            publisher.publish_cdr(bytes(data))
            first_ns = first_ns or now
            last_ns = now
        elapsed = (time.monotonic_ns() - start) / 1e9
        time.sleep(0.2)
    finally:
        context.close()
    print(json.dumps({"sent": count, "first_ns": first_ns, "last_ns": last_ns,
                      "elapsed_s": elapsed}), flush=True)


# -- bench process ----------------------------------------------------------------------------

@dataclass
class Phase:
    """Figures of one publishing run."""

    runtime: str
    rate: float
    sent: int
    latencies_ms: np.ndarray
    hop_ms: np.ndarray
    coalesced: int
    solved: int
    lost: int
    load: tuple[float, float]
    cpu_node: float
    elapsed_s: float
    rss_kib: list[tuple[float, int]] = field(default_factory=list)

    def percentile(self, q: float) -> float:
        return float(np.percentile(self.latencies_ms, q)) if len(self.latencies_ms) else np.nan


class Bench:
    """model_node (and on zenoh a router) as children; the measuring side in this process."""

    def __init__(self, runtime: str, params: Path | None) -> None:
        from tdcm_ros.runtime.port import QoS

        self.runtime = runtime
        self.env = {**os.environ, "TDCM_RUNTIME": runtime}
        self.env.pop("TDCM_ZENOH_CONFIG", None)
        self.children: list[subprocess.Popen[bytes]] = []
        self.node: subprocess.Popen[bytes] | None = None
        if runtime == "zenoh":
            self.port = free_port()
            self.env["TDCM_ZENOH_ENDPOINT"] = f"tcp/127.0.0.1:{self.port}"
            os.environ["TDCM_ZENOH_ENDPOINT"] = self.env["TDCM_ZENOH_ENDPOINT"]
            os.environ.pop("TDCM_ZENOH_CONFIG", None)
            self._spawn("-m", "tdcm_ros.runtime.router", "--listen",
                        self.env["TDCM_ZENOH_ENDPOINT"])
            self._wait(lambda: self._listening(), 15.0, "the router")
        extra = ["--params", str(params)] if params else []
        self.node = self._spawn("-m", "tdcm_ros.runtime.run_node", MODEL, "--runtime", runtime,
                                *extra)
        self.lock = threading.Lock()
        self.received: list[tuple[int, int]] = []   # (receive ns, stamp ns) of each midline
        self.inputs: list[tuple[int, int]] = []     # the same for each `tension` (one hop)
        self.counters: dict[str, int] = {}  # of the newest /diagnostics array
        self.diag_ns = 0
        self.context = open_context(runtime)
        port = self.context.create_port("bench_latency")
        self.subscribers: list[Any] = []
        for topic, type_name, into in (("midline", "nav_msgs/msg/Path", self.received),
                                       ("tension", TENSION_TYPE, self.inputs)):
            if runtime == "zenoh":  # straight on the session: zenoh's thread, no executor
                from tdcm_ros.runtime import wire

                self.subscribers.append(self.context.session.declare_subscriber(
                    wire.topic_key(self.context.domain_id, topic, type_name,
                                   type_hash(type_name)),
                    self._stamped(into, lambda sample: sample.payload.to_bytes())))
            else:  # raw CDR, deep enough that this listener never drops
                port.create_raw_subscription(topic, type_name,
                                             self._stamped(into, lambda sample: sample.data),
                                             QoS(depth=2000))
        port.create_subscription("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                                 self._on_diagnostics)
        self._wait(lambda: self.diag_ns > 0, 30.0, "model_node's first /diagnostics",
                   spin=True)

    def _spawn(self, *args: str, output: bool = False) -> subprocess.Popen[bytes]:
        child = subprocess.Popen([sys.executable, *args], env=self.env,
                                 stdout=subprocess.PIPE if output else subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        self.children.append(child)
        return child

    def _listening(self) -> bool:
        try:
            with socket.create_connection(("127.0.0.1", self.port), timeout=0.2):
                return True
        except OSError:
            return False

    def _wait(self, predicate: Any, timeout: float, what: str, spin: bool = False) -> None:
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline or self.node_exited():
                raise SystemExit(f"bench ({self.runtime}): timed out after {timeout} s waiting "
                                 f"for {what}")
            if spin:
                self.context.spin_for(0.05)
            else:
                time.sleep(0.05)

    def node_exited(self) -> bool:
        return self.node is not None and self.node.poll() is not None

    def _stamped(self, into: list[tuple[int, int]],
                 payload: Callable[[Any], bytes]) -> Callable[[Any], None]:
        """Callback recording (receive time, header stamp); the time is taken first."""
        def on_sample(sample: Any) -> None:
            now = time.time_ns()
            sec, nanosec = _STAMP.unpack_from(payload(sample), 4)
            with self.lock:
                into.append((now, sec * 1_000_000_000 + nanosec))
        return on_sample

    def _on_diagnostics(self, message: Any) -> None:
        if counters := node_counters(message):
            self.counters = counters
            self.diag_ns = message.header.stamp.sec * 1_000_000_000 + \
                message.header.stamp.nanosec

    def fresh_counters(self, after_ns: int) -> dict[str, int]:
        """Counters from a ``/diagnostics`` published after ``after_ns``."""
        self._wait(lambda: self.diag_ns > after_ns, 10.0, "fresh /diagnostics", spin=True)
        return dict(self.counters)

    def run(self, rate: float, duration: float, sample_rss: bool = False) -> Phase:
        """Publish at ``rate`` Hz for ``duration`` s from a child process; collect figures."""
        assert self.node is not None
        before = self.fresh_counters(time.time_ns())
        with self.lock:
            self.received.clear()
            self.inputs.clear()
        load0 = os.getloadavg()[0]
        cpu0 = cpu_s(self.node.pid)
        publisher = self._spawn(__file__, "--publish", str(rate), str(duration),
                                "--runtime", self.runtime, output=True)
        rss: list[tuple[float, int]] = []
        t0 = time.monotonic()
        next_rss = t0
        while publisher.poll() is None:
            if sample_rss and time.monotonic() >= next_rss:
                rss.append((time.monotonic() - t0, rss_kib(self.node.pid)))
                next_rss += 1.0
            self.context.spin_for(0.05)
            if self.node_exited():
                raise SystemExit(f"bench: model_node ({self.runtime}) exited")
        out = publisher.stdout.read() if publisher.stdout else b""
        if publisher.returncode != 0:
            raise SystemExit(f"bench: publisher ({self.runtime}) failed ({publisher.returncode})")
        summary = json.loads(out.decode().strip().splitlines()[-1])
        if sample_rss:
            rss.append((time.monotonic() - t0, rss_kib(self.node.pid)))
        self.context.spin_for(0.3)  # the last outputs
        after = self.fresh_counters(time.time_ns())
        with self.lock:
            samples = [(recv, stamp) for recv, stamp in self.received
                       if summary["first_ns"] <= stamp <= summary["last_ns"]]
            hop = np.array([(recv - stamp) / 1e6 for recv, stamp in self.inputs])
        latencies = np.array([(recv - stamp) / 1e6 for recv, stamp in samples])
        delta = {key: value - before.get(key, 0) for key, value in after.items()}
        return Phase(self.runtime, rate, summary["sent"], latencies, hop,
                     delta.get("coalesced", 0), delta.get("solved", 0),
                     summary["sent"] - accounted_inputs(delta),
                     (load0, os.getloadavg()[0]), cpu_s(self.node.pid) - cpu0,
                     summary["elapsed_s"], rss)

    def close(self) -> None:
        for subscriber in self.subscribers:
            subscriber.undeclare()
        self.context.close()
        for child in reversed(self.children):
            if child.poll() is None:
                child.send_signal(2)
                try:
                    child.wait(5)
                except subprocess.TimeoutExpired:
                    child.kill()
                    child.wait()


def node_counters(message: Any) -> dict[str, int]:
    """The counters of every ``model_node: ...`` status of a ``/diagnostics`` array (input and
    solver: each status holds some of them), by key."""
    return {v.key: int(v.value) for status in message.status
            if status.name.startswith("model_node: ") for v in status.values if v.value.isdigit()}


def accounted_inputs(counters: dict[str, int]) -> int:
    """Tensions model_node's cumulative counters account for: solved, coalesced, dropped and
    failed solves (not the windowed ``*_in_window``, the rolls ``dropped_roll_*`` nor the band's
    failures ``model_band_*``, which are no inputs of their own)."""
    return sum(value for key, value in counters.items()
               if not key.endswith("_in_window") and not key.startswith(("dropped_roll_",
                                                                          "model_band_"))
               and (key in ("solved", "coalesced") or key.startswith(("dropped_", "model_"))))


@contextmanager
def bench(runtime: str) -> Iterator[Bench]:
    """A running :class:`Bench`: model_node draws its midline for every solve
    (``output.visual_rate_hz`` 0, so each input has an output to time)."""
    with tempfile.TemporaryDirectory() as tmp:
        params = Path(tmp) / "model_node.yaml"
        lines = ["model_node:", "  ros__parameters:", "    output:", "      visual_rate_hz: 0.0"]
        params.write_text("\n".join(lines) + "\n")
        runner = Bench(runtime, params)
        try:
            yield runner
        finally:
            runner.close()


def measure(runtime: str, rate: float, duration: float, warmup: float,
            sample_rss: bool = False) -> Phase:
    """One phase on a fresh stack: warm up at 100 Hz (not reported), then ``rate`` Hz."""
    with bench(runtime) as runner:
        if warmup > 0:
            runner.run(100.0, warmup)
        return runner.run(rate, duration, sample_rss)


def row(phase: Phase) -> str:
    lat = phase.latencies_ms
    delivered = len(lat)
    figures = (f"{phase.percentile(50):7.2f} {phase.percentile(99):7.2f} {lat.max():8.2f}"
               if delivered else f"{'-':>7} {'-':>7} {'-':>8}")
    hop = (f"{np.percentile(phase.hop_ms, 50):5.2f} {np.percentile(phase.hop_ms, 99):5.2f}"
           if len(phase.hop_ms) else f"{'-':>5} {'-':>5}")
    return (f"{phase.runtime:>7} {phase.rate:7.0f} {figures} {delivered:7d}/{phase.sent:<7d} "
            f"{phase.coalesced:9d} {phase.lost:5d} {hop} "
            f"{phase.cpu_node / phase.elapsed_s * 100:7.0f}% {cpu_per_solve_ms(phase):9.3f} "
            f"{phase.load[0]:5.2f}->{phase.load[1]:.2f}")


def cpu_per_solve_ms(phase: Phase) -> float:
    """model_node's CPU (all threads) over the phase per solve (ms): what one input that is
    solved costs it, receiving the coalesced ones included."""
    return phase.cpu_node / phase.solved * 1e3 if phase.solved else float("nan")


PHASE_COLUMNS = [Column("runtime"), Column("rate", "Hz", ",.0f"), Column("p50", "ms", ".2f"),
                 Column("p99", "ms", ".2f"), Column("max", "ms", ".2f"), Column("delivered"),
                 Column("sent"), Column("coalesced"), Column("lost"),
                 Column("hop p50", "ms", ".2f"), Column("hop p99", "ms", ".2f"),
                 Column("node CPU", "% of a core", ".0f"),
                 Column("node CPU per solve", "ms", ".3f"), Column("load average", format=".2f"),
                 Column("→ at the end", format=".2f")]
"""The columns of :func:`phase_row`: the figures :func:`row` prints."""


def phase_row(phase: Phase) -> list[object]:
    """The figures of :func:`row` as cells of :data:`PHASE_COLUMNS` (``None``: none measured)."""
    lat, hop = phase.latencies_ms, phase.hop_ms
    return [phase.runtime, phase.rate,
            *((phase.percentile(50), phase.percentile(99), float(lat.max())) if len(lat)
              else (None, None, None)),
            len(lat), phase.sent, phase.coalesced, phase.lost,
            *((float(np.percentile(hop, 50)), float(np.percentile(hop, 99))) if len(hop)
              else (None, None)),
            phase.cpu_node / phase.elapsed_s * 100, cpu_per_solve_ms(phase), phase.load[0],
            phase.load[1]]


HEADER = (f"{'runtime':>7} {'rate Hz':>7} {'p50 ms':>7} {'p99 ms':>7} {'max ms':>8} "
          f"{'delivered/sent':>15} {'coalesced':>9} {'lost':>5} {'hop p50':>5} {'p99':>5} "
          f"{'node CPU':>8} {'CPU/solve':>9} load1")


def ratio_table(phases: list[Phase]) -> list[list[object]]:
    """rclpy/zenoh ratios of p50 and p99 (and of the one-hop p99) per rate; returns the rows
    printed."""
    by_key = {(p.runtime, p.rate): p for p in phases}
    print("\nrclpy/zenoh ratio (same run, interleaved per rate)")
    print(f"{'rate Hz':>7} {'p50 zenoh':>9} {'p50 rclpy':>9} {'ratio':>6} "
          f"{'p99 zenoh':>9} {'p99 rclpy':>9} {'ratio':>6} {'hop p99 ratio':>13}")
    rows: list[list[object]] = []
    for rate in dict.fromkeys(p.rate for p in phases):
        zenoh, rclpy = by_key.get(("zenoh", rate)), by_key.get(("rclpy", rate))
        if zenoh is None or rclpy is None:
            continue
        z50, r50, z99, r99 = (zenoh.percentile(50), rclpy.percentile(50), zenoh.percentile(99),
                              rclpy.percentile(99))
        hop = (np.percentile(rclpy.hop_ms, 99) / np.percentile(zenoh.hop_ms, 99)
               if len(rclpy.hop_ms) and len(zenoh.hop_ms) else np.nan)
        print(f"{rate:7.0f} {z50:9.2f} {r50:9.2f} {r50 / z50:6.2f} "
              f"{z99:9.2f} {r99:9.2f} {r99 / z99:6.2f} {hop:13.2f}", flush=True)
        rows.append([rate, z50, r50, r50 / z50, z99, r99, r99 / z99, hop])
    return rows


RATIO_COLUMNS = [Column("rate", "Hz", ",.0f"), Column("p50 zenoh", "ms", ".2f"),
                 Column("p50 rclpy", "ms", ".2f"), Column("ratio", format=".2f"),
                 Column("p99 zenoh", "ms", ".2f"), Column("p99 rclpy", "ms", ".2f"),
                 Column("ratio", format=".2f"), Column("hop p99 ratio", format=".2f")]


def soak_report(phase: Phase, results: BenchResults) -> None:
    times = np.array([t for t, _ in phase.rss_kib])
    kib = np.array([k for _, k in phase.rss_kib], dtype=float)
    slope = np.polyfit(times, kib, 1)[0] if len(times) > 1 else 0.0
    half = times >= times[-1] / 2
    late = np.polyfit(times[half], kib[half], 1)[0] if half.sum() > 1 else 0.0
    print(f"model_node ({phase.runtime}) RSS: start {kib[0] / 1024:.1f} MiB, end "
          f"{kib[-1] / 1024:.1f} MiB, max {kib.max() / 1024:.1f} MiB, slope {slope:+.2f} KiB/s "
          f"over the run ({late:+.2f} KiB/s over the second half), {len(kib)} samples")
    every = max(1, len(kib) // 12)
    series = " ".join(f"{k / 1024:.1f}" for k in kib[::every])
    print(f"RSS (MiB) every ~{every} s: {series}")
    print(f"coalesced inputs (from /diagnostics): {phase.coalesced} of {phase.sent} sent; "
          f"solved {phase.solved}; lost {phase.lost}")
    results.table(
        f"model_node ({phase.runtime}) RSS over the soak",
        [Column("start", "MiB", ".1f"), Column("end", "MiB", ".1f"), Column("max", "MiB", ".1f"),
         Column("slope", "KiB/s", "+.2f"), Column("slope, second half", "KiB/s", "+.2f"),
         Column("samples"), Column("solved"), Column("coalesced"), Column("lost")],
        [[kib[0] / 1024, kib[-1] / 1024, kib.max() / 1024, slope, late, len(kib), phase.solved,
          phase.coalesced, phase.lost]],
        note=f"RSS (MiB) every ~{every} s: {series}")


def fmt_load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def describe(runtimes: list[str]) -> str:
    """Header line: date, CPUs, load average, runtimes (and the rclpy RMW and domain)."""
    parts = [datetime.now().astimezone().isoformat(timespec="seconds"),
             f"{os.cpu_count()} CPUs, load average {fmt_load()}",
             f"runtimes {', '.join(runtimes)}"]
    if "rclpy" in runtimes:
        from rclpy.utilities import get_rmw_implementation_identifier

        parts.append(f"rclpy on {get_rmw_implementation_identifier()}, ROS_DOMAIN_ID "
                     f"{os.environ.get('ROS_DOMAIN_ID', '(unset: 0)')}, "
                     f"ROS_AUTOMATIC_DISCOVERY_RANGE "
                     f"{os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE', '(unset)')}")
    parts.append(f"tension {TENSION_N} N, paper-experiment, model_node's defaults but "
                 "output.visual_rate_hz 0 (a midline per solve)")
    return "; ".join(parts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runtime", choices=[*RUNTIMES, "both"], default=None,
                        help="runtime(s) to measure (default: both; zenoh alone, said so, "
                             "where rclpy is not importable)")
    parser.add_argument("--rates", type=float, nargs="+", default=[100.0, 500.0, 1000.0],
                        help="input rates (Hz)")
    parser.add_argument("--duration", type=float, default=10.0, help="seconds per rate")
    parser.add_argument("--warmup", type=float, default=2.0,
                        help="seconds at 100 Hz before each phase (not reported)")
    parser.add_argument("--soak", action="store_true", help="memory soak instead of the rates")
    parser.add_argument("--soak-rate", type=float, default=1000.0, help="soak input rate (Hz)")
    parser.add_argument("--soak-duration", type=float, default=60.0, help="soak length (s)")
    parser.add_argument("--publish", nargs=2, type=float, metavar=("RATE", "DURATION"),
                        help=argparse.SUPPRESS)
    add_results_argument(parser, "bench_latency")
    args = parser.parse_args()
    if args.publish:
        publish(args.runtime or "zenoh", *args.publish, wait=20.0)
        return
    runtimes = list(RUNTIMES) if args.runtime in (None, "both") else [args.runtime]
    if "rclpy" in runtimes and not rclpy_available():
        if args.runtime is not None:
            parser.error(f"--runtime {args.runtime} needs rclpy ({NO_RCLPY})")
        print(f"rclpy is not importable ({NO_RCLPY}): measuring zenoh only", flush=True)
        runtimes = ["zenoh"]
    if min([*args.rates, args.soak_rate]) <= 0 or min(args.duration, args.soak_duration) <= 0:
        parser.error("rates and durations must be > 0")
    results = BenchResults("bench_latency")
    described = describe(runtimes)
    print(described, flush=True)
    if args.soak:
        for runtime in runtimes:
            phase = measure(runtime, args.soak_rate, args.soak_duration, args.warmup,
                            sample_rss=True)
            print(f"soak ({runtime}): {args.soak_rate:g} Hz for {args.soak_duration:g} s")
            print(HEADER)
            print(row(phase))
            results.table(f"Soak ({runtime}): {args.soak_rate:g} Hz for {args.soak_duration:g} s",
                          PHASE_COLUMNS, [phase_row(phase)], note=described)
            soak_report(phase, results)
        if args.results:
            results.write(args.results)
        return
    print(HEADER, flush=True)
    phases = []
    for rate in args.rates:
        for runtime in runtimes:
            phases.append(measure(runtime, rate, args.duration, args.warmup))
            print(row(phases[-1]), flush=True)
    ratios = ratio_table(phases) if len(runtimes) > 1 else []
    end = fmt_load()
    print(f"load average at the end {end}")
    results.table(
        f"Tension → midline latency, {args.duration:g} s per rate",
        PHASE_COLUMNS, [phase_row(phase) for phase in phases],
        note=f"{described}; load average at the end {end}. Delivered: inputs that produced a "
             "midline; coalesced: inputs replaced by a newer one that arrived during a solve "
             "(the node's cumulative /diagnostics counter); lost: sent minus every input its "
             "counters account for (solved, coalesced, dropped, failed); hop: publisher → this "
             "bench's own listener on tension (the machine's own stalls); node CPU: all of "
             "model_node's threads, and per solve; load average: 1 min, at the start and end "
             "of the phase.")
    if ratios:
        results.table("rclpy/zenoh ratio (same run, interleaved per rate)", RATIO_COLUMNS, ratios)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
