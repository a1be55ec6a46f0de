"""Batch solver throughput on one core for paper-like designs, and its tip error.

Run: ``python bench/bench_batch.py [--designs 40] [--tensions 250] [--repeat 5]
[--baseline /work/main] [--rounds 3]``.

Workloads (default solver settings, whose tip error against a converged reference is printed):

- design space: ``designs`` paper-like designs (w_n x w_d around the paper's, fixed pitch,
  L = 53 mm) x ``tensions`` tensions in 0-20 N, grids already built (what a sweep costs once
  the design grid exists) and cold (grid building included);
- many designs: one tension per design, grid building included (the worst case).

The design-space case is also timed with two worker threads (``workers=2``; the ratio to one
is printed). ``--baseline`` times another checkout (e.g. main's NumPy batch) on the warm
design-space case in the same run: it and this checkout alternate in fresh processes for
``--rounds`` rounds and the ratio of their median throughputs is printed.

Tip error: the batch against single solves at the same settings (should be ~1e-17 m), and
against converged single solves (128 cells per notch, 16 per tube, 12-point quadrature,
tol 1e-14 m) on a sample of points. Timings are best-of-``repeat`` wall times.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from time import perf_counter
from typing import Any

THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")
MM = 1e-3


def paper_like(count: int, rng: Any) -> list[Any]:
    """Designs of the paper's family: w_n in 1-2.5 mm, w_d in 1.2-2 mm, pitch 6 mm."""
    from tdcm_ros.model import preset
    from tdcm_ros.model.design_space import couple

    base = preset("fig2-wn-1.9")
    return [couple(base.with_overrides(w_n=rng.uniform(1.0, 2.5) * MM,
                                       w_d=rng.uniform(1.2, 2.0) * MM), "fixed-pitch", 6 * MM)
            for _ in range(count)]


def best_time(run: Callable[[], object], repeat: int, cold: bool) -> float:
    """Best wall time (s) of ``run()`` over ``repeat`` calls; ``cold`` clears the grid cache."""
    from tdcm_ros.model.grid import _build_grid

    times = []
    for _ in range(repeat):
        if cold:
            _build_grid.cache_clear()
        started = perf_counter()
        run()
        times.append(perf_counter() - started)
    return min(times)


def run(args: argparse.Namespace) -> None:
    """Measure and print (NumPy is imported here, after the thread variables are set)."""
    import numpy as np

    from tdcm_ros.model import SolverSettings, solve
    from tdcm_ros.model.batch import solve_batch

    reference = SolverSettings(cells_per_notch=128, cells_per_tube=16, quad_order=12, tol=1e-14)
    settings = SolverSettings()
    rng = np.random.default_rng(2024)
    designs = paper_like(args.designs, rng)
    tensions = np.broadcast_to(np.linspace(0.0, 20.0, args.tensions),
                               (args.designs, args.tensions))
    count = tensions.size
    result = solve_batch(designs, tensions, settings=settings)
    warm = best_time(lambda: solve_batch(designs, tensions, settings=settings), args.repeat,
                     cold=False)
    if args.throughput_only:
        print(count / warm)
        return
    solve_batch(designs, tensions, settings=settings, workers=2)
    two = best_time(lambda: solve_batch(designs, tensions, settings=settings, workers=2),
                    args.repeat, cold=False)
    cold = best_time(lambda: solve_batch(designs, tensions, settings=settings), args.repeat,
                     cold=True)
    many = paper_like(args.many, rng)
    many_t = rng.uniform(0.0, 20.0, args.many)
    many_time = best_time(lambda: solve_batch(many, many_t, settings=settings), 2, cold=True)
    single_n = 200
    pairs = [(designs[i % args.designs], float(tensions[0, (7 * i) % args.tensions]))
             for i in range(single_n)]
    single_time = best_time(lambda: [solve(d, t, settings=settings) for d, t in pairs], 2,
                            cold=False)

    flat = [(i, k) for i in range(args.designs) for k in range(args.tensions)]
    picks = [flat[j] for j in rng.choice(len(flat), args.sample, replace=False)]
    picks += [(i, args.tensions - 1) for i in range(min(4, args.designs))]
    same = max(float(np.max(np.abs(solve(designs[i], tensions[i, k], settings=settings)
                                   .tip_position - result.tip_position[i, k]))) for i, k in picks)
    converged = [float(np.linalg.norm(solve(designs[i], tensions[i, k], settings=reference)
                                      .tip_position - result.tip_position[i, k]))
                 for i, k in picks]

    print(f"settings: cells_per_notch={settings.cells_per_notch}, quad_order="
          f"{settings.quad_order}, tol={settings.tol:g} m; "
          f"{', '.join(THREAD_VARIABLES)} = {os.environ['OMP_NUM_THREADS']}")
    print(f"statuses: {dict(zip(*np.unique(result.status, return_counts=True)))}; "
          f"fallback to single solve: {int(result.fallback.sum())}")
    print(f"design space {args.designs} designs x {args.tensions} tensions = {count} solves")
    print(f"  grids built  : {count / warm:10.0f} solves/s  ({warm * 1e3:.1f} ms)")
    print(f"  two workers  : {count / two:10.0f} solves/s  ({two * 1e3:.1f} ms), "
          f"{warm / two:.2f}x one worker (target >= 1.8x)")
    print(f"  incl. grids  : {count / cold:10.0f} solves/s  ({cold * 1e3:.1f} ms)")
    print(f"many designs {args.many} x 1 tension, incl. grids: {args.many / many_time:10.0f} "
          f"solves/s ({many_time * 1e3:.1f} ms)")
    print(f"single solve() loop          : {single_n / single_time:10.0f} solves/s")
    print(f"tip error vs single solve, same settings ({len(picks)} points): {same:.2e} m")
    print(f"tip error vs converged reference: max {max(converged) * 1e6:.3f} um, "
          f"median {np.median(converged) * 1e6:.3f} um (target <= 1 um)")


def throughput_in(checkout: Path, args: argparse.Namespace) -> float:
    """Warm design-space throughput (solves/s) in a fresh process importing ``tdcm_ros`` from
    ``checkout``."""
    env = {**os.environ, "PYTHONPATH": str(checkout)}
    command = [sys.executable, __file__, "--throughput-only", "--designs", str(args.designs),
               "--tensions", str(args.tensions), "--repeat", str(args.repeat)]
    out = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1])


def compare(args: argparse.Namespace) -> None:
    """Alternate the baseline checkout and this one; print throughputs and their ratio."""
    here = Path(__file__).resolve().parents[1]
    base, mine = [], []
    for _ in range(args.rounds):
        base.append(throughput_in(args.baseline, args))
        mine.append(throughput_in(here, args))
    b, m = sorted(base)[len(base) // 2], sorted(mine)[len(mine) // 2]
    print(f"same-run comparison, {args.designs} x {args.tensions}, grids built, one core, "
          f"{args.rounds} alternating rounds")
    print(f"  baseline {args.baseline}: {b:10.0f} solves/s (rounds: "
          + ", ".join(f"{t:.0f}" for t in base) + ")")
    print(f"  this checkout      : {m:10.0f} solves/s (rounds: "
          + ", ".join(f"{t:.0f}" for t in mine) + ")")
    print(f"  speed-up           : {m / b:10.1f}x  (target >= 250,000 solves/s)")


def main() -> None:
    """Pin every thread pool to one thread, then benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=40)
    parser.add_argument("--tensions", type=int, default=250)
    parser.add_argument("--many", type=int, default=2000, help="designs, one tension each")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sample", type=int, default=24, help="points checked at the reference")
    parser.add_argument("--baseline", type=Path, help="checkout to compare with, e.g. /work/main")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--throughput-only", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    os.environ.update({name: "1" for name in THREAD_VARIABLES})
    if args.baseline is not None:
        compare(args)
    run(args)


if __name__ == "__main__":
    main()
