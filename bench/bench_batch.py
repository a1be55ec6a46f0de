"""Batch solver throughput on one core for paper-like designs, and its tip error.

Run: ``python bench/bench_batch.py [--designs 40] [--tensions 250] [--repeat 5]``.

Workloads (default solver settings, whose tip error against a converged reference is printed):

- design space: ``designs`` paper-like designs (w_n x w_d around the paper's, fixed pitch,
  L = 53 mm) x ``tensions`` tensions in 0-20 N, grids already built (what a sweep costs once
  the design grid exists) and cold (grid building included);
- many designs: one tension per design, grid building included (the worst case).

Tip error: the batch against single solves at the same settings (should be ~1e-17 m), and
against converged single solves (128 cells per notch, 16 per tube, 12-point quadrature,
tol 1e-14 m) on a sample of points. Timings are best-of-``repeat`` wall times.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
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
    print(f"  incl. grids  : {count / cold:10.0f} solves/s  ({cold * 1e3:.1f} ms)")
    print(f"many designs {args.many} x 1 tension, incl. grids: {args.many / many_time:10.0f} "
          f"solves/s ({many_time * 1e3:.1f} ms)")
    print(f"single solve() loop          : {single_n / single_time:10.0f} solves/s")
    print(f"tip error vs single solve, same settings ({len(picks)} points): {same:.2e} m")
    print(f"tip error vs converged reference: max {max(converged) * 1e6:.3f} um, "
          f"median {np.median(converged) * 1e6:.3f} um (target <= 1 um)")


def main() -> None:
    """Pin every thread pool to one thread, then benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=40)
    parser.add_argument("--tensions", type=int, default=250)
    parser.add_argument("--many", type=int, default=2000, help="designs, one tension each")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sample", type=int, default=24, help="points checked at the reference")
    args = parser.parse_args()
    os.environ.update({name: "1" for name in THREAD_VARIABLES})
    run(args)


if __name__ == "__main__":
    main()
