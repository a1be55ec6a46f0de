"""What ``SolveResult.pose_at`` costs: a station set seen for the first time (its partial
integrals from the grid kernel, :meth:`tdcm_ros.model.grid.Grid.query`) and one the grid has
cached, against one warm solve of the same design for scale.

Run: ``python bench/bench_pose.py [--stations 400] [--repeats 50] [--results FILE]``.
paper-experiment at 6 N; each first-time set is the ``--stations`` evenly spaced arc lengths
shifted by a different fraction of a nanometre, so no cache helps. Prints medians (ms). Compare
checkouts by running it with ``PYTHONPATH`` set to each, in the same minute. Single-threaded.
``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import preset, solve, warm_up


def main() -> None:
    """Time first-time and cached station sets and a warm solve; print the medians."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stations", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=50)
    add_results_argument(parser, "bench_pose")
    args = parser.parse_args()
    results = BenchResults("bench_pose")
    warm_up()
    design = preset("paper-experiment")
    result = solve(design, 6.0)
    base = np.linspace(0.0, design.length, args.stations)

    def median_ms(call: object) -> float:
        times = []
        for k in range(args.repeats):
            start = time.perf_counter()
            call(k)  # type: ignore[operator]
            times.append(time.perf_counter() - start)
        return 1e3 * float(np.median(times))

    first = median_ms(lambda k: result.pose_at(base * (1.0 - 1e-9 * (k + 1))))
    result.pose_at(base)
    cached = median_ms(lambda k: result.pose_at(base))
    solved = median_ms(lambda k: solve(design, 6.0 + 1e-6 * k))
    print(f"pose_at, {args.stations} stations: first time {first:.2f} ms, cached {cached:.3f} ms;"
          f" one warm solve {solved:.2f} ms")
    results.table(
        f"pose_at, {args.stations} stations: paper-experiment at 6 N",
        [Column("call"), Column("median", "ms", ".3f")],
        [["pose_at, station set seen for the first time", first],
         ["pose_at, station set cached", cached],
         ["one warm solve (for scale)", solved]],
        note=f"medians of {args.repeats} calls each")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
