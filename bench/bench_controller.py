"""Shape-controller core benchmark (issue 18, item 3): tracking error with feed-forward only and
with feedback, against worlds whose modulus is not the model's, and the cost of the core's calls.

Run: ``python bench/bench_controller.py [--hold 4] [--seed 0] [--results FILE]``.
Eight tip targets on paper-experiment (the model's tip at 5-12 N, rolled -1 to 1 rad) are held
``--hold`` s each in :func:`tdcm_ros.control.simulate_tracking` (50 Hz control and markers,
driver limits 20 N, 40 N/s, +-pi/2 rad, 1 rad/s; noise 0.02 N on the tension and 0.1 mm per
marker coordinate). Printed per ``E_model / E_world`` (the true g): the largest and the RMS
settled tip error over the last second of every hold (mm), for feed-forward (g frozen at 1) and
feedback, the final gain +- std, and the time from which the gain stays within 5 % of the truth. Then the
median time per ``observe`` (one measurement: two warm solves and the update) and per
``resolve`` (one target: the inverse model), against one warm solve in the same run.
``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.control import (
    DriverLimits,
    PlaneTarget,
    ShapeController,
    rotate_z,
    simulate_tracking,
)
from tdcm_ros.model import MarkerLayout, preset, solve, warm_up

DESIGN = preset("paper-experiment")
LIMITS = DriverLimits(tension_max=20.0, setpoint_rate=40.0, roll_max=np.pi / 2, roll_rate=1.0)
RATIOS = (0.7, 0.8, 1.0, 1.3, 1.5)


def targets() -> list[tuple[float, float, float]]:
    out = []
    for tension, roll in zip(np.linspace(5.0, 12.0, 8), np.linspace(-1.0, 1.0, 8), strict=True):
        x, _, z = solve(DESIGN, float(tension)).tip_position
        out.append(rotate_z((float(x), 0.0, float(z)), float(roll)))
    return out


def median_us(call, repeats: int) -> float:
    times = []
    for i in range(repeats):
        start = time.perf_counter()
        call(i)
        times.append(time.perf_counter() - start)
    return float(np.median(times)) * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hold", type=float, default=4.0, help="s per target")
    parser.add_argument("--seed", type=int, default=0)
    add_results_argument(parser, "bench_controller")
    args = parser.parse_args()
    results = BenchResults("bench_controller")
    warm_up()
    points = targets()
    print(f"{len(points)} targets held {args.hold:g} s each; settled = last 1 s of each hold")
    print("| E_model/E_world | feed-forward max / RMS (mm) | feedback max / RMS (mm) "
          "| gain +- std | gain within 5 % from |")
    print("|---|---|---|---|---|")
    tracking = []
    for ratio in RATIOS:
        runs = {mode: simulate_tracking(DESIGN, points, modulus_ratio=ratio, mode=mode,
                                        limits=LIMITS, hold_s=args.hold, seed=args.seed)
                for mode in ("feedforward", "feedback")}
        cells, figures = [], []
        for run in runs.values():
            settled = run.settled_error_m(1.0)
            cells.append(f"{settled.max() * 1e3:.3f} / {np.sqrt(np.mean(settled ** 2)) * 1e3:.3f}")
            figures += [settled.max() * 1e3, np.sqrt(np.mean(settled ** 2)) * 1e3]
        fb = runs["feedback"]
        outside = np.flatnonzero(np.abs(fb.gain - ratio) >= 0.05 * ratio)
        within = ("from the start" if not outside.size else "never" if outside[-1] ==
                  fb.gain.size - 1 else f"{fb.time_s[outside[-1] + 1]:.2f} s")
        print(f"| {ratio:g} | {cells[0]} | {cells[1]} | {fb.gain[-1]:.4f} +- "
              f"{fb.gain_std[-1]:.4f} | {within} |")
        tracking.append([ratio, *figures, fb.gain[-1], fb.gain_std[-1], within])
    results.table(
        f"Tracking: {len(points)} targets held {args.hold:g} s each",
        [Column("E_model/E_world", format="g"), Column("feed-forward max", "mm", ".3f"),
         Column("feed-forward RMS", "mm", ".3f"), Column("feedback max", "mm", ".3f"),
         Column("feedback RMS", "mm", ".3f"), Column("gain", format=".4f"),
         Column("gain std", format=".4f"), Column("gain within 5 % from")], tracking,
        note="settled tip error: the last 1 s of each hold; gain: feedback's final gain and "
             f"its std; seed {args.seed}")

    controller = ShapeController(DESIGN, MarkerLayout())
    rng = np.random.default_rng(args.seed)
    tensions = rng.uniform(2.0, 18.0, 400)
    markers = np.zeros((3, 3))
    solve_us = median_us(lambda i: solve(DESIGN, float(tensions[i])), 400)
    observe_us = median_us(lambda i: controller.observe(float(tensions[i]), 0.0, markers, 0.02,
                                                        adapt=True), 400)
    tips = [solve(DESIGN, float(t)).tip_position for t in tensions[:100]]
    resolve_us = median_us(lambda i: controller.resolve(
        PlaneTarget(0.0, tip_point=(float(tips[i][0]), float(tips[i][2]))), LIMITS), 100)
    print(f"\nmedian time: one solve {solve_us:.1f} us; observe {observe_us:.1f} us "
          f"({observe_us / solve_us:.1f} x); resolve {resolve_us:.1f} us "
          f"({resolve_us / solve_us:.1f} x)")
    results.table(
        "Median time per call",
        [Column("call"), Column("median", "µs", ".1f"), Column("× one solve", format=".1f")],
        [["one solve", solve_us, 1.0], ["observe", observe_us, observe_us / solve_us],
         ["resolve", resolve_us, resolve_us / solve_us]],
        note="observe: one measurement (two warm solves and the update), 400 calls; resolve: one "
             "tip-point target (the inverse model), 100 calls; one solve: 400 warm solves")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
