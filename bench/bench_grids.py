"""Grid building for many different designs: ``build_grids`` (one compiled kernel call over
every design's prototype cells) against one ``build_grid`` per design, in the same run
(issue 15, item 3).

Run: ``python bench/bench_grids.py [--designs 2000] [--repeat 3] [--baseline CHECKOUT]
[--rounds 3] [--results FILE]``. Designs are paper-like (``w_n``, ``w_d`` drawn around the paper's), every one
different, so no cache helps; the grid cache is cleared before each single-design pass.
Single-threaded; times are CPU time of the process (``time.process_time``), which other jobs
on shared cores disturb far less than wall time. ``--baseline`` times ``build_grids`` of another checkout (e.g. main) in the
same run: it and this checkout alternate in fresh processes for ``--rounds`` rounds and the
per-round ratios are printed (median and range). The two rules for the cells' partial integrals
(:data:`tdcm_ros.model.grid.PARTIAL_RULES`: ``nested``, the default and the single solve's, and
``interpolated``, no compliance evaluation beyond each cell's Gauss points and probes) are
timed against each other in the same process, interleaved. ``--results FILE`` also writes the
printed figures as tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import SolverSettings, preset
from tdcm_ros.model.design import MM
from tdcm_ros.model.grid import build_grid, build_grids, clear_grid_cache
from tdcm_ros.model.grid_layout import PEAK_SAMPLES

CASES = (("default (adaptive), paper", SolverSettings()),
         ("default (adaptive), free", SolverSettings(routing="free")),
         ("uniform cpn=4 cpt=1 q=4", SolverSettings(grid="uniform", cells_per_notch=4,
                                                    cells_per_tube=1, quad_order=4)))


def stacked_rates(designs: list, repeat: int) -> list[float]:
    """``build_grids`` grids/s of every case (best of ``repeat``; the first call warms up)."""
    rates = []
    for _, settings in CASES:
        build_grids(designs, settings)
        times = []
        for _ in range(repeat):
            start = time.process_time()
            build_grids(designs, settings)
            times.append(time.process_time() - start)
        rates.append(len(designs) / min(times))
    return rates


def compare(args: argparse.Namespace, results: BenchResults) -> None:
    """Alternate the baseline checkout and this one in fresh processes; print the ratios."""
    here = Path(__file__).resolve().parents[1]
    runs: dict[Path, list[list[float]]] = {args.baseline: [], here: []}
    for _ in range(args.rounds):
        for checkout, rates in runs.items():
            out = subprocess.run(
                [sys.executable, __file__, "--rates-only", "--designs", str(args.designs),
                 "--repeat", str(args.repeat)], env={**os.environ, "PYTHONPATH": str(checkout)},
                capture_output=True, text=True, check=True)
            rates.append([float(v) for v in out.stdout.split()[-len(CASES):]])
    print(f"build_grids, grids per CPU second, {args.rounds} alternating rounds (fresh processes), "
          f"median (min-max); baseline {args.baseline}")
    rows: list[list[object]] = []
    for k, (label, _) in enumerate(CASES):
        base = [r[k] for r in runs[args.baseline]]
        mine = [r[k] for r in runs[here]]
        ratios = sorted(m / b for m, b in zip(mine, base, strict=True))
        print(f"  {label:<28} baseline {np.median(base):8.0f} ({min(base):.0f}-{max(base):.0f})"
              f"  this {np.median(mine):8.0f} ({min(mine):.0f}-{max(mine):.0f})  ratio "
              f"{ratios[len(ratios) // 2]:.2f}x ({ratios[0]:.2f}-{ratios[-1]:.2f})")
        rows.append([label, float(np.median(base)), min(base), max(base), float(np.median(mine)),
                     min(mine), max(mine), ratios[len(ratios) // 2], ratios[0], ratios[-1]])
    rate = ",.0f"
    results.table(
        f"build_grids, grids per CPU second, {args.rounds} alternating rounds (fresh processes) "
        f"against {args.baseline}",
        [Column("grid"), Column("baseline", format=rate), Column("min", format=rate),
         Column("max", format=rate), Column("this checkout", format=rate),
         Column("min", format=rate), Column("max", format=rate),
         Column("ratio", format=".2f"), Column("min", format=".2f"),
         Column("max", format=".2f")], rows)


def rules(designs: list, repeat: int, results: BenchResults) -> None:
    """``build_grids`` grids per CPU second of every case under each partial-integral rule,
    interleaved (best of ``repeat``), and their ratio (this checkout only: a ``--baseline``
    one may predate the rules)."""
    from tdcm_ros.model.grid import INTERPOLATED, NESTED, PARTIAL_RULES

    rows: list[list[object]] = []
    for label, settings in CASES:
        times: dict[str, list[float]] = {rule: [] for rule in PARTIAL_RULES}
        for rule in PARTIAL_RULES:
            build_grids(designs, settings, partials=rule)
        for _ in range(repeat):
            for rule in PARTIAL_RULES:
                start = time.process_time()
                build_grids(designs, settings, partials=rule)
                times[rule].append(time.process_time() - start)
        nested, interpolated = (len(designs) / min(times[r]) for r in (NESTED, INTERPOLATED))
        q = settings.quad_order
        print(f"{label:<28} nested {nested:8.0f}  interpolated {interpolated:8.0f} grids per CPU s"
              f"  ratio {interpolated / nested:.2f}x  (points per notch cell "
              f"{q + q * q + PEAK_SAMPLES + 2} -> {q + PEAK_SAMPLES + 2})")
        rows.append([label, q + q * q + PEAK_SAMPLES + 2, nested, q + PEAK_SAMPLES + 2,
                     interpolated, interpolated / nested])
    rate = ",.0f"
    results.table(
        f"build_grids of {len(designs):,} designs by partial-integral rule, in one process",
        [Column("grid"), Column("nested: points per notch cell"),
         Column("nested: grids per CPU s", format=rate),
         Column("interpolated: points per notch cell"),
         Column("interpolated: grids per CPU s", format=rate),
         Column("ratio", format=".2f")], rows,
        note=f"CPU time of the process (process_time), best of {repeat}, the two rules "
             "interleaved; nested is the default (the single solve's grid), interpolated is "
             "solve_batch(..., partials='interpolated')")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--baseline", type=Path, help="checkout to compare with, e.g. main")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--rates-only", action="store_true", help=argparse.SUPPRESS)
    add_results_argument(parser, "bench_grids")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    base = preset("paper-experiment")
    designs = [base.with_overrides(w_n=float(rng.uniform(1.0, 2.5)) * MM,
                                   w_d=float(rng.uniform(1.2, 2.0)) * MM)
               for _ in range(args.designs)]
    if args.rates_only:
        print(*stacked_rates(designs, args.repeat))
        return
    results = BenchResults("bench_grids")
    if args.baseline is not None:
        compare(args, results)
    rows: list[list[object]] = []
    for label, settings in CASES:
        stacked, single = [], []
        stack = build_grids(designs, settings)
        for _ in range(args.repeat):
            start = time.process_time()
            stack = build_grids(designs, settings)
            stacked.append(time.process_time() - start)
            clear_grid_cache()
            start = time.process_time()
            for design in designs:
                build_grid(design, settings)
            single.append(time.process_time() - start)
        fast, slow = min(stacked), min(single)
        print(f"{label:<28} cells/design {stack.n_cells.mean():6.1f}  build_grids "
              f"{args.designs / fast:9.0f} grids per CPU s ({fast / args.designs * 1e6:6.1f} us)  "
              f"build_grid loop {args.designs / slow:7.0f} grids/s  ratio {slow / fast:5.1f}x")
        rows.append([label, float(stack.n_cells.mean()), args.designs / fast,
                     fast / args.designs * 1e6, args.designs / slow, slow / fast])
    rate = ",.0f"
    results.table(
        f"Grid building for {args.designs:,} different paper-like designs, in one process",
        [Column("grid"), Column("cells per design", format=".1f"),
         Column("build_grids, grids per CPU s", format=rate),
         Column("per design", "µs", ".1f"),
         Column("one build_grid per design, grids per CPU s", format=rate),
         Column("ratio", format=".1f")], rows,
        note=f"CPU time of the process (process_time), best of {args.repeat}; the grid cache is "
             "cleared before each single-design pass")
    rules(designs, args.repeat, results)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
