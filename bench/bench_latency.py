"""Tension -> ``midline`` end-to-end latency of ``model_node`` across processes (issue 4).

Run: ``python bench/bench_latency.py [--rates 100 500 1000] [--duration 10]`` or
``python bench/bench_latency.py --soak [--soak-duration 60] [--soak-rate 1000]``.

Starts a private zenoh router (``tdcm_ros.runtime.router``), ``model_node`` and, per rate, a
tension publisher, each its own process, as ``tdcm up`` does. The publisher sends
``geometry_msgs/WrenchStamped`` on ``tension`` with the send time (``time.time_ns``) in the
header stamp; model_node stamps its outputs with the input's stamp, so this process measures
latency = receive time of a ``midline`` (taken first thing in the zenoh callback) minus its
stamp. Per rate it prints p50, p99 and max latency (ms), delivered/sent (inputs that produced a
midline; the rest were coalesced by the keep-latest node or lost) and the coalesced inputs the
node reports on ``/diagnostics``, with the 1-min load average (the figures are only as good as
an idle machine). ``--soak`` also samples model_node's RSS (``VmRSS``) once a second and prints
start, end and max RSS and the least-squares slope.
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict, type_hash

MODEL = "tdcm_ros.nodes.model_node:ModelNode"
TENSION_N = 12.0
_STAMP = struct.Struct("<iI")  # header.stamp (sec, nanosec) right after the 4-byte CDR header


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


# -- publisher process ------------------------------------------------------------------------

def publish(rate: float, duration: float, wait: float) -> None:
    """Publish ``tension`` at ``rate`` Hz for ``duration`` s; print a JSON summary on stdout."""
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext

    context = ZenohContext()
    try:
        publisher = context.create_port("bench_tension").create_publisher(
            "tension", "geometry_msgs/msg/WrenchStamped")
        deadline = time.monotonic() + wait
        while not publisher.matched():
            if time.monotonic() > deadline:
                raise SystemExit("bench publisher: no subscriber on `tension`")
            time.sleep(0.01)
        time.sleep(0.3)  # let the route settle
        message = from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": {"frame_id": "tdcm_tendon"}, "wrench": {"force": {"z": TENSION_N}}})
        stamp = message.header.stamp
        period_ns = int(1e9 / rate)
        count = round(rate * duration)
        start = time.monotonic_ns()
        first_ns = last_ns = 0
        for k in range(count):
            due = start + k * period_ns
            while (left := due - time.monotonic_ns()) > 0:
                time.sleep(left / 1e9)
            now = time.time_ns()
            stamp.sec, stamp.nanosec = divmod(now, 1_000_000_000)
            publisher.publish(message)
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

    rate: float
    sent: int
    latencies_ms: np.ndarray
    hop_ms: np.ndarray
    coalesced: int
    solved: int
    load: tuple[float, float]
    cpu_node: float
    elapsed_s: float
    rss_kib: list[tuple[float, int]] = field(default_factory=list)


class Bench:
    """Router + model_node children and the receiving side in this process."""

    def __init__(self, params: Path | None) -> None:
        self.port = free_port()
        self.env = {**os.environ, "TDCM_ZENOH_ENDPOINT": f"tcp/127.0.0.1:{self.port}",
                    "TDCM_RUNTIME": "zenoh", "ROS_DOMAIN_ID": "0"}
        self.env.pop("TDCM_ZENOH_CONFIG", None)
        os.environ.update({k: self.env[k] for k in ("TDCM_ZENOH_ENDPOINT", "ROS_DOMAIN_ID")})
        os.environ.pop("TDCM_ZENOH_CONFIG", None)
        self.children: list[subprocess.Popen[bytes]] = []
        self.router = self._spawn("-m", "tdcm_ros.runtime.router", "--listen",
                                  self.env["TDCM_ZENOH_ENDPOINT"])
        self._wait(lambda: self._listening(), 15.0, "the router")
        extra = ["--params", str(params)] if params else []
        self.node = self._spawn("-m", "tdcm_ros.runtime.run_node", MODEL, "--runtime", "zenoh",
                                *extra)
        self.lock = threading.Lock()
        self.received: list[tuple[int, int]] = []   # (receive ns, stamp ns) of each midline
        self.inputs: list[tuple[int, int]] = []     # the same for each `tension` (one hop)
        self.counters: dict[str, int] = {}
        self.diag_ns = 0
        from tdcm_ros.runtime import wire
        from tdcm_ros.runtime.zenoh_runtime import ZenohContext

        self.context = ZenohContext()
        port = self.context.create_port("bench_latency")
        self.subscribers = [
            self.context.session.declare_subscriber(
                wire.topic_key(0, topic, type_name, type_hash(type_name)),
                lambda sample, into=into: self._on_stamped(sample, into))
            for topic, type_name, into in (("midline", "nav_msgs/msg/Path", self.received),
                                           ("tension", "geometry_msgs/msg/WrenchStamped",
                                            self.inputs))]
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
                raise SystemExit(f"bench: timed out after {timeout} s waiting for {what}")
            if spin:
                self.context.spin_for(0.05)
            else:
                time.sleep(0.05)

    def node_exited(self) -> bool:
        return len(self.children) > 1 and self.children[1].poll() is not None

    def _on_stamped(self, sample: Any, into: list[tuple[int, int]]) -> None:
        now = time.time_ns()
        sec, nanosec = _STAMP.unpack_from(sample.payload.to_bytes(), 4)
        with self.lock:
            into.append((now, sec * 1_000_000_000 + nanosec))

    def _on_diagnostics(self, message: Any) -> None:
        for status in message.status:
            if status.name.startswith("model_node"):
                self.counters = {v.key: int(v.value) for v in status.values if v.value.isdigit()}
                self.diag_ns = message.header.stamp.sec * 1_000_000_000 + \
                    message.header.stamp.nanosec

    def fresh_counters(self, after_ns: int) -> dict[str, int]:
        """Counters from a ``/diagnostics`` published after ``after_ns``."""
        self._wait(lambda: self.diag_ns > after_ns, 10.0, "fresh /diagnostics", spin=True)
        return dict(self.counters)

    def run(self, rate: float, duration: float, sample_rss: bool = False) -> Phase:
        """Publish at ``rate`` Hz for ``duration`` s from a child process; collect figures."""
        before = self.fresh_counters(time.time_ns())
        with self.lock:
            self.received.clear()
            self.inputs.clear()
        load0 = os.getloadavg()[0]
        cpu0 = cpu_s(self.node.pid)
        publisher = self._spawn(__file__, "--publish", str(rate), str(duration), output=True)
        rss: list[tuple[float, int]] = []
        t0 = time.monotonic()
        next_rss = t0
        while publisher.poll() is None:
            if sample_rss and time.monotonic() >= next_rss:
                rss.append((time.monotonic() - t0, rss_kib(self.node.pid)))
                next_rss += 1.0
            self.context.spin_for(0.05)
            if self.node_exited():
                raise SystemExit("bench: model_node exited")
        out = publisher.stdout.read() if publisher.stdout else b""
        if publisher.returncode != 0:
            raise SystemExit(f"bench: publisher failed ({publisher.returncode})")
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
        return Phase(rate, summary["sent"], latencies, hop,
                     after.get("coalesced", 0) - before.get("coalesced", 0),
                     after.get("solved", 0) - before.get("solved", 0),
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


@contextmanager
def bench(period: float | None) -> Iterator[Bench]:
    """A running :class:`Bench`, with ``process_period_s`` overridden when given."""
    with tempfile.TemporaryDirectory() as tmp:
        params = None
        if period is not None:
            params = Path(tmp) / "model_node.yaml"
            params.write_text(f"model_node:\n  ros__parameters:\n    process_period_s: {period}\n")
        runner = Bench(params)
        try:
            yield runner
        finally:
            runner.close()


def row(phase: Phase) -> str:
    lat = phase.latencies_ms
    delivered = len(lat)
    figures = (f"{np.percentile(lat, 50):7.2f} {np.percentile(lat, 99):7.2f} {lat.max():8.2f}"
               if delivered else f"{'-':>7} {'-':>7} {'-':>8}")
    hop = (f"{np.percentile(phase.hop_ms, 50):5.2f} {np.percentile(phase.hop_ms, 99):5.2f}"
           if len(phase.hop_ms) else f"{'-':>5} {'-':>5}")
    return (f"{phase.rate:7.0f} {figures} {delivered:7d}/{phase.sent:<7d} "
            f"{phase.coalesced:9d} {hop} {phase.cpu_node / phase.elapsed_s * 100:7.0f}% "
            f"{phase.load[0]:5.2f}->{phase.load[1]:.2f}")


HEADER = (f"{'rate Hz':>7} {'p50 ms':>7} {'p99 ms':>7} {'max ms':>8} {'delivered/sent':>15} "
          f"{'coalesced':>9} {'hop p50':>5} {'p99':>5} {'node CPU':>8} load1")


def soak_report(phase: Phase) -> None:
    times = np.array([t for t, _ in phase.rss_kib])
    kib = np.array([k for _, k in phase.rss_kib], dtype=float)
    slope = np.polyfit(times, kib, 1)[0] if len(times) > 1 else 0.0
    half = times >= times[-1] / 2
    late = np.polyfit(times[half], kib[half], 1)[0] if half.sum() > 1 else 0.0
    print(f"model_node RSS: start {kib[0] / 1024:.1f} MiB, end {kib[-1] / 1024:.1f} MiB, "
          f"max {kib.max() / 1024:.1f} MiB, slope {slope:+.2f} KiB/s over the run "
          f"({late:+.2f} KiB/s over the second half), {len(kib)} samples")
    every = max(1, len(kib) // 12)
    series = " ".join(f"{k / 1024:.1f}" for k in kib[::every])
    print(f"RSS (MiB) every ~{every} s: {series}")
    print(f"coalesced inputs (from /diagnostics): {phase.coalesced} of {phase.sent} sent; "
          f"solved {phase.solved}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rates", type=float, nargs="+", default=[100.0, 500.0, 1000.0],
                        help="input rates (Hz)")
    parser.add_argument("--duration", type=float, default=10.0, help="seconds per rate")
    parser.add_argument("--warmup", type=float, default=2.0,
                        help="seconds at 100 Hz before measuring (not reported)")
    parser.add_argument("--soak", action="store_true", help="memory soak instead of the rates")
    parser.add_argument("--soak-rate", type=float, default=1000.0, help="soak input rate (Hz)")
    parser.add_argument("--soak-duration", type=float, default=60.0, help="soak length (s)")
    parser.add_argument("--period", type=float, default=None,
                        help="override model_node's process_period_s (s)")
    parser.add_argument("--publish", nargs=2, type=float, metavar=("RATE", "DURATION"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.publish:
        publish(*args.publish, wait=20.0)
        return
    if min([*args.rates, args.soak_rate]) <= 0 or min(args.duration, args.soak_duration) <= 0:
        parser.error("rates and durations must be > 0")
    print(f"{os.cpu_count()} CPUs, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}; "
          f"tension {TENSION_N} N, paper-experiment, default model_node parameters"
          + (f", process_period_s {args.period}" if args.period else ""), flush=True)
    with bench(args.period) as runner:
        if args.warmup > 0:
            runner.run(100.0, args.warmup)
        if args.soak:
            phase = runner.run(args.soak_rate, args.soak_duration, sample_rss=True)
            print(f"soak: {args.soak_rate:g} Hz for {args.soak_duration:g} s")
            print(HEADER)
            print(row(phase))
            soak_report(phase)
            return
        print(HEADER)
        for rate in args.rates:
            print(row(runner.run(rate, args.duration)), flush=True)


if __name__ == "__main__":
    main()
