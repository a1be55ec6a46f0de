"""What the roll costs model_node per solve (issue 18, item 2): building its outputs (the five
shape messages and the ``/tf`` message) at a roll against at roll 0, in one run.

Run: ``python bench/bench_roll.py [--repeats 2000] [--stations 0] [--roll 0.7] [--results FILE]``.
One solve of paper-experiment at 12 N, then ``--repeats`` builds of every output at roll 0 and at
``--roll`` rad, interleaved (so machine noise hits both alike); prints the median time per build
of each and their ratio, and the median time of one solve of the same design (warm) for scale.
Single-threaded. ``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import math
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import SolveResult, preset, solve, warm_up
from tdcm_ros.nodes.shape_messages import midline_messages
from tdcm_ros.nodes.tf_messages import body_tf

ARCS = np.array([0.015, 0.033, 0.053])


def build(result: SolveResult, roll: float, stations: int) -> float:
    """Seconds to build model_node's outputs for ``result`` at ``roll`` (rad)."""
    started = time.perf_counter()
    for _ in midline_messages(result, stamp_ns=1, frame_id="tdcm_base", samples=54,
                              marker_s=ARCS, marker_radius=result.design.R_outer + 0.001,
                              marker_side_rad=math.pi, roll=roll):
        pass
    body_tf(result, stamp_ns=1, parent="tdcm_base", tip="tdcm_tip",
            station_prefix="tdcm_station_", stations=stations, roll=roll)
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2000)
    parser.add_argument("--stations", type=int, default=0)
    parser.add_argument("--roll", type=float, default=0.7)
    add_results_argument(parser, "bench_roll")
    args = parser.parse_args()
    results = BenchResults("bench_roll")
    warm_up()
    design = preset("paper-experiment")
    result = solve(design, 12.0)
    solves = []
    for _ in range(200):
        started = time.perf_counter()
        solve(design, 12.0)
        solves.append(time.perf_counter() - started)
    flat, rolled = [], []
    for _ in range(args.repeats):
        flat.append(build(result, 0.0, args.stations))
        rolled.append(build(result, args.roll, args.stations))
    p_flat, p_rolled = np.median(flat) * 1e6, np.median(rolled) * 1e6
    print(f"outputs of one solve ({args.stations} stations), median of {args.repeats}:")
    print(f"  roll 0        {p_flat:8.1f} us")
    print(f"  roll {args.roll:<8g} {p_rolled:8.1f} us")
    print(f"  ratio rolled / roll 0: {p_rolled / p_flat:.3f}  "
          f"(extra {p_rolled - p_flat:.1f} us per solve)")
    print(f"one solve of paper-experiment at 12 N, warm (median of 200): "
          f"{np.median(solves) * 1e6:.1f} us")
    results.table(
        f"Outputs of one solve ({args.stations} stations), median of {args.repeats}",
        [Column("figure"), Column("measured"), Column("unit")],
        [["outputs at roll 0", p_flat, "µs"],
         [f"outputs at roll {args.roll:g} rad", p_rolled, "µs"],
         ["ratio rolled / roll 0", p_rolled / p_flat, ""],
         ["extra per solve", p_rolled - p_flat, "µs"],
         ["one solve of paper-experiment at 12 N, warm (median of 200)",
          np.median(solves) * 1e6, "µs"]],
        note="outputs: the five shape messages and the /tf message of one solve of "
             "paper-experiment at 12 N; both rolls interleaved")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
