"""Evaluation benchmark (issue 6): ``tdcm evaluate`` on a simulated 10-minute bag.

Run: ``python bench/bench_evaluate.py [--repeats 3] [--minutes 10] [--calibrate]
[--results FILE]``
(``--write BAG`` only writes the bag, for ``bench_evaluate_memory.py``). Simulates
the paper-experiment robot (E = 0.7 GPa) over repeated 0-20 N staircases (10 s holds) with
1 kHz tension and 100 Hz mocap (3 markers, 5 % occlusion, noise), writes it as a rosbag2 MCAP
bag with /tf_static (not timed), then times the whole evaluation (read the bag, detect steps,
average markers, re-run the model per step, Table I) and prints the figures. Target: <= 5 s.
Single-threaded BLAS. ``--results FILE`` also writes the printed figures as tables to a results
file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.metrics.api import Topics, calibrate_paths, evaluate_sources, load_paths
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.synthetic import PAPER_LEVELS, simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset

TARGET_S = 5.0
HOLD_S = 10.0
BENCH_E = 0.7e9
"""Young's modulus (Pa) of the simulated robot; evaluate with ``--set E=0.7e9``."""


def write_bench_bag(minutes: float, path: Path) -> tuple[Path, str, list[list[object]]]:
    """Simulate about ``minutes`` of 0-20 N staircases (whole trials of 10 s holds, 1 kHz
    tension, 100 Hz mocap, 5 % occlusion) and write them as the bag folder ``path``; returns it,
    a one-line description and the described figures as ``[figure, value, unit]`` rows."""
    trials = max(1, round(minutes * 60.0 / (HOLD_S * len(PAPER_LEVELS))))
    design = preset("paper-experiment").with_overrides(E=BENCH_E)
    rec = simulate(design, hold_s=HOLD_S, trials=trials, tension_hz=1000.0, mocap_hz=100.0,
                   occlusion=0.05, seed=0)
    span = rec.tension.stamps_s[-1] - rec.tension.stamps_s[0]
    bag = write_recording(rec, path)
    figures: list[list[object]] = [
        ["bag length", span / 60, "min"],
        ["tension samples (1 kHz)", rec.tension.stamps_s.size, ""],
        ["marker frames (100 Hz)", rec.markers.stamps_s.size, ""],
        ["bag size", bag_bytes(bag) / 1e6, "MB"]]
    return bag, (f"{span / 60:.2f} min, {rec.tension.stamps_s.size} tension samples (1 kHz), "
                 f"{rec.markers.stamps_s.size} marker frames (100 Hz), {bag_bytes(bag) / 1e6:.1f} MB"
                 ), figures


def bag_bytes(bag: Path) -> int:
    """Size of a bag folder's files (bytes)."""
    return sum(f.stat().st_size for f in bag.iterdir() if f.is_file())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--calibrate", action="store_true", help="also time tdcm calibrate")
    parser.add_argument("--write", type=Path, metavar="BAG",
                        help="only write the bench bag (--minutes long) to the new folder BAG")
    add_results_argument(parser, "bench_evaluate")
    args = parser.parse_args()
    if args.write:
        print(f"wrote {args.write}: {write_bench_bag(args.minutes, args.write)[1]}")
        return
    results = BenchResults("bench_evaluate")
    options = options_from_sets([f"E={BENCH_E:g}"])
    with tempfile.TemporaryDirectory() as tmp:
        bag, described, figures = write_bench_bag(args.minutes, Path(tmp) / "bench")
        print(f"bag: {described}")
        loads, evals = [], []
        for _ in range(args.repeats):
            started = time.perf_counter()
            sources = load_paths([bag], options, Topics())
            loaded = time.perf_counter()
            ev = evaluate_sources(sources, options)
            loads.append(loaded - started)
            evals.append(time.perf_counter() - loaded)
        total = np.array(loads) + np.array(evals)
        m = ev.metrics
        print(f"steps {m.n_steps} in {m.n_trials} trials; RMSE {m.rmse_m * 1e3:.4f} mm, "
              f"shape error {m.shape_error_m * 1e3:.4f} mm")
        print(f"read bag   median {np.median(loads):.2f} s")
        print(f"evaluate   median {np.median(evals):.2f} s")
        print(f"total      median {np.median(total):.2f} s, min {total.min():.2f} s "
              f"over {args.repeats} runs (target <= {TARGET_S:g} s: "
              f"{'met' if np.median(total) <= TARGET_S else 'NOT met'})")
        figure = [Column("figure"), Column("measured"), Column("unit")]
        results.table(
            "The simulated bag and its evaluation", figure,
            [*figures, ["steps", m.n_steps, ""], ["trials", m.n_trials, ""],
             ["RMSE", m.rmse_m * 1e3, "mm"], ["shape error", m.shape_error_m * 1e3, "mm"]],
            note=f"paper-experiment with E = {BENCH_E:g} Pa, 0-20 N staircases of "
                 f"{HOLD_S:g} s holds, 5 % marker occlusion; evaluated with --set "
                 f"E={BENCH_E:g}")
        timing = [["read the bag, median", float(np.median(loads)), "s"],
                  ["evaluate (steps, model, Table I), median", float(np.median(evals)), "s"],
                  ["total, median", float(np.median(total)), "s"],
                  ["total, fastest run", float(total.min()), "s"]]
        if args.calibrate:
            started = time.perf_counter()
            cal = calibrate_paths([bag], ["E"], options_from_sets([]))
            p = cal.parameters[0]
            elapsed = time.perf_counter() - started
            print(f"calibrate E: {p.value:.4g} Pa ({p.ci_low:.4g} .. {p.ci_high:.4g}) in "
                  f"{elapsed:.2f} s")
            timing.append(["calibrate E (one run)", elapsed, "s"])
            results.table("Calibrating E on the same bag",
                          [Column("parameter"), Column("value", "Pa", ".4g"),
                           Column("interval low", "Pa", ".4g"),
                           Column("interval high", "Pa", ".4g"), Column("time", "s", ".2f")],
                          [["E", p.value, p.ci_low, p.ci_high, elapsed]])
        results.table(f"Time, {args.repeats} runs in this process", figure, timing,
                      note=f"target: total <= {TARGET_S:g} s")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
