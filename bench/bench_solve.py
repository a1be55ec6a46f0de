"""Single-solve benchmark (issue 2): median time of one solve and iterations to converge.

Run: ``python bench/bench_solve.py [--repeats 2000]``. Prints the median and p90 time per solve
on ``paper-experiment`` at 20 N with the default settings, the tip error of that solve
against a converged reference, and the iterations across presets and hard designs.
Single-threaded: BLAS threads are pinned to one before NumPy loads.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from tdcm_ros.model import PRESETS, SolverSettings, preset, solve

REFERENCE = SolverSettings(cells_per_notch=256, cells_per_tube=32, quad_order=16, tol=1e-14)
FINER = SolverSettings(cells_per_notch=512, cells_per_tube=64, quad_order=16, tol=1e-14)

HARD = {
    "stiffness-ratio-1000": preset("paper-experiment").with_overrides(w_d=0.25e-3),
    "narrow-notch": preset("paper-experiment").with_overrides(w_n=2e-5),
    "N60-past-360deg": preset("paper-experiment").with_overrides(N=60, w_n=1e-3, w_t=0.2e-3,
                                                                 w_d=0.6e-3, E=0.5e9),
    "soft-tube": preset("paper-experiment").with_overrides(w_d=7.8e-3, E=1e7),
}
HARD_TENSION = {"stiffness-ratio-1000": 0.5, "narrow-notch": 20.0, "N60-past-360deg": 4.0,
                "soft-tube": 20.0}


def time_solves(repeats: int) -> np.ndarray:
    """Wall time (s) of ``repeats`` solves of paper-experiment at 20 N (warm grid cache)."""
    design = preset("paper-experiment")
    solve(design, 20.0)
    times = np.empty(repeats)
    for k in range(repeats):
        start = time.perf_counter()
        solve(design, 20.0)
        times[k] = time.perf_counter() - start
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2000)
    args = parser.parse_args()
    design = preset("paper-experiment")
    reference = solve(design, 20.0, settings=REFERENCE).tip_position
    finer = solve(design, 20.0, settings=FINER).tip_position
    default = solve(design, 20.0)
    times = time_solves(args.repeats)
    start = time.perf_counter()
    solve(design.with_overrides(E=1.8e9), 20.0)
    first = time.perf_counter() - start
    print("paper-experiment, T = 20 N, default settings")
    print(f"  median solve time      {np.median(times) * 1e6:8.1f} us   (target <= 200 us)")
    print(f"  p90 solve time         {np.percentile(times, 90) * 1e6:8.1f} us")
    print(f"  first solve of a new design (grid build) {first * 1e3:.2f} ms")
    print(f"  tip error vs reference {np.linalg.norm(default.tip_position - reference) * 1e9:8.2f}"
          " nm  (target <= 1000 nm)")
    print(f"  reference self-check   {np.linalg.norm(finer - reference) * 1e9:8.3f} nm "
          "(256 vs 512 cells/notch)")
    print("iterations to converge (tol 1e-10 m), strategy")
    for name in PRESETS:
        row = [solve(preset(name), t) for t in (4.0, 12.0, 20.0)]
        print(f"  {name:22s} " + "  ".join(f"{t:4.0f} N: {r.iterations:2d} ({r.strategy})"
                                           for t, r in zip((4, 12, 20), row, strict=True)))
    for name, hard in HARD.items():
        for routing in ("paper", "free"):
            r = solve(hard, HARD_TENSION[name], settings=SolverSettings(routing=routing))
            print(f"  {name:22s} {routing:5s} {HARD_TENSION[name]:4g} N: {r.iterations:3d} "
                  f"({r.strategy}), tip angle {np.degrees(r.tip_angle_rad):7.1f} deg")


if __name__ == "__main__":
    main()
