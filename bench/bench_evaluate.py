"""Evaluation benchmark (issue 6): ``tdcm evaluate`` on a simulated 10-minute bag.

Run: ``python bench/bench_evaluate.py [--repeats 3] [--minutes 10] [--calibrate]``
(``--write BAG`` only writes the bag, for ``bench_evaluate_memory.py``). Simulates
the paper-experiment robot (E = 0.7 GPa) over repeated 0-20 N staircases (10 s holds) with
1 kHz tension and 100 Hz mocap (3 markers, 5 % occlusion, noise), writes it as a rosbag2 MCAP
bag with /tf_static (not timed), then times the whole evaluation (read the bag, detect steps,
average markers, re-run the model per step, Table I) and prints the figures. Target: <= 5 s.
Single-threaded BLAS.
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

from tdcm_ros.metrics.api import Topics, calibrate_paths, evaluate_sources, load_paths
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.synthetic import PAPER_LEVELS, simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset

TARGET_S = 5.0
HOLD_S = 10.0
BENCH_E = 0.7e9
"""Young's modulus (Pa) of the simulated robot; evaluate with ``--set E=0.7e9``."""


def write_bench_bag(minutes: float, path: Path) -> tuple[Path, str]:
    """Simulate about ``minutes`` of 0-20 N staircases (whole trials of 10 s holds, 1 kHz
    tension, 100 Hz mocap, 5 % occlusion) and write them as the bag folder ``path``; returns it
    and a one-line description."""
    trials = max(1, round(minutes * 60.0 / (HOLD_S * len(PAPER_LEVELS))))
    design = preset("paper-experiment").with_overrides(E=BENCH_E)
    rec = simulate(design, hold_s=HOLD_S, trials=trials, tension_hz=1000.0, mocap_hz=100.0,
                   occlusion=0.05, seed=0)
    span = rec.tension.stamps_s[-1] - rec.tension.stamps_s[0]
    bag = write_recording(rec, path)
    return bag, (f"{span / 60:.2f} min, {rec.tension.stamps_s.size} tension samples (1 kHz), "
                 f"{rec.markers.stamps_s.size} marker frames (100 Hz), {bag_bytes(bag) / 1e6:.1f} MB")


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
    args = parser.parse_args()
    if args.write:
        print(f"wrote {args.write}: {write_bench_bag(args.minutes, args.write)[1]}")
        return
    options = options_from_sets([f"E={BENCH_E:g}"])
    with tempfile.TemporaryDirectory() as tmp:
        bag, described = write_bench_bag(args.minutes, Path(tmp) / "bench")
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
        if args.calibrate:
            started = time.perf_counter()
            cal = calibrate_paths([bag], ["E"], options_from_sets([]))
            p = cal.parameters[0]
            print(f"calibrate E: {p.value:.4g} Pa ({p.ci_low:.4g} .. {p.ci_high:.4g}) in "
                  f"{time.perf_counter() - started:.2f} s")


if __name__ == "__main__":
    main()
