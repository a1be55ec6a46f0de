"""What the uncertainty band costs model_node (issue 33, item 4): the tip covariance and the band
of one solve against the solve itself, without and with friction, in one run.

Run: ``python bench/bench_band.py [--repeats 1000] [--results FILE]``.
For paper-experiment at 12 N (E = 0.7 GPa) the bench times, interleaved so machine noise hits
all alike: the solve model_node does per message (warm started; with friction mu = 0.3 the
stick-slip solve after a 0 -> 20 -> 12 N history), the band's extra work (one solve per fitted
parameter: ``E`` without friction, ``E`` and ``mu`` with it, and the covariances) and building
the two messages. Prints the medians and the band's cost in plain solves; model_node computes the
band only on the solves it draws (``output.visual_rate_hz``, 30 Hz by default), so at 1 kHz of
inputs it adds that cost to 3 % of them. Single-threaded. ``--results FILE`` also writes the
printed figures as tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import (
    Design,
    FrictionTrack,
    ParameterCovariance,
    SolveResult,
    preset,
    warm_up,
)
from tdcm_ros.nodes.band_messages import shape_spread, uncertainty_messages

TENSION_N = 12.0
SAMPLES = 54  # model_node's output.samples default
VISUAL_SHARE = 30.0 / 1000.0  # drawn solves at 1 kHz of inputs, output.visual_rate_hz 30


def case(mu: float, names: tuple[str, ...]) -> tuple[FrictionTrack, Design, SolveResult,
                                                      ParameterCovariance]:
    """A track after 0 -> 20 N (with friction), its solve at 12 N and a covariance of ``names``."""
    design = preset("paper-experiment").with_overrides(E=7.0e8)
    track = FrictionTrack(mu)
    for tension in (0.0, 20.0):
        track.solve(design, tension)
    result = track.solve_at(design, TENSION_N)
    values = {"E": 7.0e8, "mu": mu}
    std = {"E": 7e6, "mu": 0.03}
    covariance = np.diag([std[n] ** 2 for n in names])
    return track, design, result, ParameterCovariance(
        names, np.array([values[n] for n in names]), covariance, 1.2e-4)


def timed(run: Callable[[], object]) -> float:
    """Seconds ``run()`` takes."""
    started = time.perf_counter()
    run()
    return time.perf_counter() - started


def measure(mu: float, names: tuple[str, ...], repeats: int) -> tuple[float, float, float]:
    """Median seconds of the solve, the spread (covariances) and the two messages."""
    track, design, result, uncertainty = case(mu, names)
    s = np.linspace(0.0, design.length, SAMPLES)

    def solve_once() -> SolveResult:
        return track.solve_at(design, TENSION_N, warm_start=result)

    def resolve(moved: Design, moved_mu: float) -> SolveResult:
        return track.solve_at(moved, TENSION_N, mu=moved_mu, warm_start=result)

    spread = shape_spread(result, mu, uncertainty, s, resolve)
    solves, spreads, messages = [], [], []
    for _ in range(repeats):
        solves.append(timed(solve_once))
        spreads.append(timed(lambda: shape_spread(result, mu, uncertainty, s, resolve)))
        messages.append(timed(lambda: list(uncertainty_messages(
            spread, result, stamp_ns=1, frame_id="tdcm_base", roll=0.3, confidence=0.95))))
    return float(np.median(solves)), float(np.median(spreads)), float(np.median(messages))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1000)
    add_results_argument(parser, "bench_band")
    args = parser.parse_args()
    results = BenchResults("bench_band")
    warm_up()
    rows = []
    for label, mu, names in (("no friction, fit E", 0.0, ("E",)),
                             ("friction mu 0.3, fit E and mu", 0.3, ("E", "mu"))):
        solve_s, spread_s, messages_s = measure(mu, names, args.repeats)
        band = spread_s + messages_s
        per_message = (solve_s + VISUAL_SHARE * band) / solve_s
        print(f"{label}: solve {solve_s * 1e6:.1f} us, covariances {spread_s * 1e6:.1f} us, "
              f"messages {messages_s * 1e6:.1f} us; band = {band / solve_s:.2f} solves; at 1 kHz "
              f"drawn at 30 Hz a message costs {per_message:.2f} solves on average")
        rows.append([label, solve_s * 1e6, spread_s * 1e6, messages_s * 1e6, band / solve_s,
                     per_message])
    results.table(
        f"The band of one solve at {TENSION_N:g} N ({SAMPLES} samples), median of {args.repeats}",
        [Column("case"), Column("solve", "µs", ".1f"), Column("covariances", "µs", ".1f"),
         Column("messages", "µs", ".1f"), Column("band / solve", "", ".2f"),
         Column("solve + band at 30 of 1000 messages / solve", "", ".2f")], rows,
        note="solve: model_node's per message (warm; with friction after 0 -> 20 N); band: the "
             "covariances (one solve per fitted parameter) and the two messages; all "
             "interleaved")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
