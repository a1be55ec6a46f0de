"""Several tendons (issue 28): what a tendon list costs per solve, and the antagonistic target.

Run: ``python bench/bench_tendons.py [--repeats 1000] [--results FILE]``. Prints interleaved
medians (warm grid caches, one process) of: the paper preset at 20 N (the compiled
single-tendon iteration), the same tendon given as a one-entry tendon list, the antagonistic
pair of ``config/bodies/antagonistic_pair.yaml`` at 25/5 N (and the same pair under ``free``
routing; the NumPy iteration of :class:`~tdcm_ros.model.tendon_model.TendonSet`) and the
disk-routed body at 0.3/0 N, as ratios to the preset; then the pair's tip against one tendon at
the difference (target: 0.02 um under ``paper`` routing) for three preloads. Single-threaded:
BLAS threads are pinned before NumPy. ``--results FILE`` also writes the printed figures as
tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time
from collections.abc import Sequence
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import SolverSettings, preset, read_body_file, solve
from tdcm_ros.model.design import Design
from tdcm_ros.model.tendons import Tendon

BODIES = Path(__file__).resolve().parents[1] / "config" / "bodies"
FREE = SolverSettings(routing="free")


def interleaved(cases: dict[str, tuple[Design, float | Sequence[float], SolverSettings]],
                repeats: int, rounds: int = 5) -> dict[str, float]:
    """Median solve time (s) of each case, ``rounds`` rounds of ``repeats // rounds`` solves,
    the cases taking turns."""
    times: dict[str, list[float]] = {name: [] for name in cases}
    for design, tension, settings in cases.values():
        solve(design, tension, settings=settings)
    for _ in range(rounds):
        for name, (design, tension, settings) in cases.items():
            for _ in range(max(repeats // rounds, 1)):
                start = time.perf_counter()
                solve(design, tension, settings=settings)
                times[name].append(time.perf_counter() - start)
    return {name: float(np.median(t)) for name, t in times.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1000)
    add_results_argument(parser, "bench_tendons")
    args = parser.parse_args()
    results = BenchResults("bench_tendons")
    paper = preset("paper-experiment")
    listed = dataclasses.replace(paper, tendons=(Tendon(paper.R_c),))
    pair = read_body_file(BODIES / "antagonistic_pair.yaml").design()  # routing: paper each
    either = dataclasses.replace(paper, tendons=(Tendon(paper.R_c), Tendon(-paper.R_c)))
    disks = read_body_file(BODIES / "disk_routed.yaml").design()
    default = SolverSettings()
    medians = interleaved({
        "preset, 20 N": (paper, 20.0, default),
        "one-tendon list, 20 N": (listed, [20.0], default),
        "pair 25/5 N, paper": (pair, [25.0, 5.0], default),
        "pair 25/5 N, free": (either, [25.0, 5.0], FREE),
        "disk-routed 0.3/0 N": (disks, [0.3, 0.0], default),
    }, args.repeats)
    print("solve time, interleaved medians (one process)")
    for name, median in medians.items():
        print(f"  {name:24s} {median * 1e6:8.1f} us  {median / medians['preset, 20 N']:5.2f}x "
              "the preset")
    results.table(
        "Solve time, interleaved medians (one process)",
        [Column("case"), Column("median solve", "µs", ".1f"),
         Column("× the preset", format=".2f")],
        [[name, median * 1e6, median / medians["preset, 20 N"]]
         for name, median in medians.items()],
        note=f"{args.repeats} solves per case, warm grid caches; preset: paper-experiment; pair: "
             "config/bodies/antagonistic_pair.yaml (free: the same pair on the preset under "
             "free routing); disk-routed: config/bodies/disk_routed.yaml")
    print("antagonistic pair vs one tendon at the difference (tip, max |dx|, |dz|)")
    pairs = []
    for pull, preload in ((20.0, 5.0), (10.0, 10.0), (3.0, 17.0)):
        for settings in (default, FREE):
            one = solve(paper, pull, settings=settings).tip_position
            both = solve(either, [pull + preload, preload], settings=settings).tip_position
            target = "   (target <= 20 nm)" if settings.routing == "paper" else ""
            print(f"  T = {pull:4g} N, preload {preload:4g} N, {settings.routing:5s}: "
                  f"{np.max(np.abs(both - one)) * 1e9:10.3f} nm{target}")
            pairs.append([pull, preload, settings.routing, np.max(np.abs(both - one)) * 1e9,
                          "<= 20 nm" if settings.routing == "paper" else None])
    results.table(
        "Antagonistic pair against one tendon at the difference",
        [Column("tension", "N", "g"), Column("preload", "N", "g"), Column("routing"),
         Column("tip difference", "nm", ".3f"), Column("target")], pairs,
        note="tip difference: the larger of |dx| and |dz| between the tips of the pair at "
             "(tension + preload, preload) and of one tendon at the tension")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
