"""What a progress hook costs a design sweep: ``sweep(..., progress=hook)`` (solved in up to
``PROGRESS_UPDATES`` chunks, the hook called after each) against ``sweep(...)`` in one batch,
interleaved rounds in the same run (issue 16, item 7).

Run: ``python bench/bench_progress.py [--points 41] [--rounds 7] [--results FILE]``. The sweep
is the feasibility figure's ``w_n x w_d`` grid (``points**2`` designs at 20 N) and Fig. 2's
``w_n x T`` one (``points`` designs x ``points`` tensions). Single-threaded; prints medians and
the ratio. ``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import preset, sweep
from tdcm_ros.model.design import MM


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=41)
    parser.add_argument("--rounds", type=int, default=7)
    add_results_argument(parser, "bench_progress")
    args = parser.parse_args()
    results = BenchResults("bench_progress")
    n = args.points
    cases = {
        f"w_n x w_d, {n * n} designs x 1 tension": (
            preset("fig2-wn-1.9"), {"w_n": np.geomspace(0.02 * MM, 5.5 * MM, n),
                                    "w_d": np.linspace(0.3 * MM, 2.5 * MM, n)}, [20.0]),
        f"w_n x T, {n} designs x {n} tensions": (
            preset("fig2-wn-1.9"), {"w_n": np.linspace(0.5 * MM, 3.0 * MM, n)},
            np.linspace(0.0, 20.0, n)),
    }
    calls = 0
    rows = []

    def hook(stage: str, done: int, total: int | None) -> None:
        nonlocal calls
        calls += 1

    for label, (base, axes, tensions) in cases.items():
        sweep(base, axes, tensions, coupling="fixed-pitch")  # compile / warm the caches
        plain, hooked = [], []
        for _ in range(args.rounds):
            started = time.perf_counter()
            sweep(base, axes, tensions, coupling="fixed-pitch")
            plain.append(time.perf_counter() - started)
            calls = 0
            started = time.perf_counter()
            sweep(base, axes, tensions, coupling="fixed-pitch", progress=hook)
            hooked.append(time.perf_counter() - started)
        a, b = statistics.median(plain), statistics.median(hooked)
        print(f"{label}: one batch {a * 1e3:.1f} ms, with a hook {b * 1e3:.1f} ms "
              f"({calls} calls): ratio {b / a:.3f}")
        rows.append([label, a * 1e3, b * 1e3, calls, b / a])
    results.table(
        "A progress hook's cost to a sweep",
        [Column("sweep"), Column("one batch", "ms", ".1f"), Column("with a hook", "ms", ".1f"),
         Column("hook calls"), Column("ratio", format=".3f")], rows,
        note=f"medians of {args.rounds} interleaved rounds; fig2-wn-1.9, fixed-pitch coupling")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
