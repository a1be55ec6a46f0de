"""What ``tendon_states`` costs model_node per input (issue 28): one solve and the shape
messages (:func:`tdcm_ros.nodes.shape_messages.midline_messages`) against the same plus the
tendon's stroke and its ``sensor_msgs/JointState``, interleaved in one run.

Run: ``python bench/bench_tendon_states.py [--rounds 15] [--number 100] [--results FILE]``.
paper-experiment at 20 N, 50 midline samples, three markers; per round the best of three timings
of ``--number`` calls of each; prints the medians over rounds (us) and their difference.
Single-threaded. ``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import timeit

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import SolveResult, preset, solve, warm_up
from tdcm_ros.nodes.joint_messages import tendon_states
from tdcm_ros.nodes.shape_messages import midline_messages

DESIGN = preset("paper-experiment")
MARKERS = np.array([0.015, 0.033, 0.053])


def shape() -> SolveResult:
    """One solve and its shape messages, as model_node builds them for an input."""
    result = solve(DESIGN, 20.0)
    for _ in midline_messages(result, stamp_ns=1, frame_id="tdcm_base", samples=50,
                              marker_s=MARKERS, marker_radius=0.0045, marker_side_rad=0.0):
        pass
    return result


def with_tendon() -> None:
    """:func:`shape` and the tendon's JointState."""
    result = shape()
    tendon_states(1, result.tendons.names, result.tendon_strokes_m.tolist(), [result.tension_n])


def main() -> None:
    """Interleave both, print the medians and the difference."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--number", type=int, default=100)
    add_results_argument(parser, "bench_tendon_states")
    args = parser.parse_args()
    results = BenchResults("bench_tendon_states")
    warm_up()
    times: dict[str, list[float]] = {"shape": [], "tendon": []}
    for _ in range(args.rounds):
        for name, call in (("shape", shape), ("tendon", with_tendon)):
            best = min(timeit.repeat(call, number=args.number, repeat=3))
            times[name].append(best / args.number * 1e6)
    base, more = float(np.median(times["shape"])), float(np.median(times["tendon"]))
    print(f"solve + shape messages {base:.0f} us; with tendon_states {more:.0f} us: "
          f"+{more - base:.0f} us ({(more / base - 1.0) * 100:.0f} %) per input")
    results.table(
        "tendon_states: cost per input (paper-experiment at 20 N)",
        [Column("solve + shape messages", "µs", ".0f"), Column("with tendon_states", "µs", ".0f"),
         Column("extra", "µs", "+.0f"), Column("extra", "%", ".0f")],
        [[base, more, more - base, (more / base - 1.0) * 100]],
        note=f"medians over {args.rounds} interleaved rounds, each the best of three timings of "
             f"{args.number} calls; 50 midline samples, three markers")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
