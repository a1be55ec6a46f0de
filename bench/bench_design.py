"""Inverse-design benchmark (issue 18, item 5): ``search_designs`` over 100,000 candidates, 0-20 N.

Run: ``python bench/bench_design.py [--samples 100000] [--rounds 3] [--ladders 2,4,8]
[--check 20] [--profile] [--results FILE]``.

The search: ``paper-experiment`` with ``w_n`` in [0.5, 3] mm, ``w_d`` in [0.6, 2.2] mm, ``N`` in
3..12 and ``w_t`` in [1, 6] mm freed, Sobol' samples, budget 0-20 N, allowable strain 6 %,
targets a tip angle of 0.45 rad and a tip deflection of 12 mm. Printed per target and ladder:
CPU seconds of the process (``process_time``, steadier than wall on the shared 2-core machine)
and wall seconds per run (median and range of ``--rounds``), against the target of 10 s on one
core, with candidates per CPU second, solves per candidate, refinement rounds and counts.

``--check K``: ``K`` Pareto and other ``meets`` designs of the default ladder's run, their
tension against ``solve_inverse`` (same target, bounds 0-20 N, default ``tol``), relative
difference (largest), and a re-solve with ``solve`` at the reported tension (tip within ``tol``
of the target). ``--profile``: where one run's time goes (cProfile, cumulative, top entries;
profiling inflates the Python-heavy parts). Warm: kernels compiled and loaded before timing.
Single-threaded. ``--results FILE`` also writes the printed figures (all but the profile) as
tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import preset, solve, solve_inverse, warm_up
from tdcm_ros.model.inverse_design import (
    DEFAULT_DESIGN_LADDER,
    OUTCOMES,
    search_designs,
)

MM = 1e-3
FREE = {"w_n": (0.5 * MM, 3.0 * MM), "w_d": (0.6 * MM, 2.2 * MM), "N": (3, 12),
        "w_t": (1.0 * MM, 6.0 * MM)}
TARGETS = {"tip_angle": 0.45, "tip_deflection": 0.012}
TARGET_SECONDS = 10.0


def run(kind: str, samples: int, ladder: int):
    """One search; (search, CPU s, wall s)."""
    cpu, wall = time.process_time(), time.perf_counter()
    found = search_designs(preset("paper-experiment"), FREE, samples=samples, ladder=ladder,
                           tension_max=20.0, **{kind: TARGETS[kind]})
    return found, time.process_time() - cpu, time.perf_counter() - wall


def check(found, kind: str, count: int) -> list[object]:
    """Tensions of ``count`` designs against ``solve_inverse``, and a re-solve at each; returns
    the figures printed."""
    meets = np.flatnonzero(found.outcome == "meets")
    picks = list(found.pareto[:count])
    picks += [int(i) for i in meets[:: max(1, meets.size // max(1, count - len(picks)))]]
    worst_rel, worst_miss = 0.0, 0.0
    for i in picks[:count]:
        design = found.design(int(i))
        reference = solve_inverse(design, tension_max=20.0, **{kind: found.target})
        worst_rel = max(worst_rel, abs(found.tension_n[i] - reference.tension_n)
                        / reference.tension_n)
        again = solve(design, float(found.tension_n[i]))
        tip = again.tip_deflection_m if kind == "tip_deflection" else again.tip_angle_rad
        worst_miss = max(worst_miss, abs(tip - found.target))
        assert tip == found.tip_value[i], (i, tip, found.tip_value[i])
    print(f"  check of {min(count, len(picks))} designs: tension vs solve_inverse, largest "
          f"relative difference {worst_rel:.2e}; re-solve at the reported tension: tip "
          f"bit-identical, largest |tip - target| {worst_miss:.2e} {found.unit} "
          f"(tol {found.tol:g})")
    return [min(count, len(picks)), worst_rel, worst_miss, found.unit, found.tol]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--ladders", default=f"{DEFAULT_DESIGN_LADDER}",
                        help="comma-separated ladder sizes to time (default: the default's)")
    parser.add_argument("--check", type=int, default=20)
    parser.add_argument("--profile", action="store_true")
    add_results_argument(parser, "bench_design")
    args = parser.parse_args()
    results = BenchResults("bench_design")
    warm_up()
    search_designs(preset("paper-experiment"), FREE, tip_angle=0.3, samples=300)  # warm
    print(f"{args.samples} candidates, free {', '.join(FREE)}, budget 0-20 N, one core; "
          f"target {TARGET_SECONDS:g} CPU s")
    rows: list[list[object]] = []
    checks: list[list[object]] = []
    for kind, value in TARGETS.items():
        for ladder in (int(x) for x in args.ladders.split(",")):
            cpu, wall = [], []
            for _ in range(args.rounds):
                found, c, w = run(kind, args.samples, ladder)
                cpu.append(c)
                wall.append(w)
            mid = statistics.median(cpu)
            print(f"{kind} = {value:g} {found.unit}, ladder {ladder}: CPU "
                  f"{mid:.2f} s (runs {min(cpu):.2f}-{max(cpu):.2f}), wall "
                  f"{statistics.median(wall):.2f} s ({min(wall):.2f}-{max(wall):.2f}); "
                  f"{args.samples / mid:,.0f} candidates per CPU s; {mid / TARGET_SECONDS:.2f}x"
                  f" the target; {found.solves / args.samples:.2f} solves per candidate, "
                  f"{found.rounds} rounds; {found.counts()}; Pareto {found.pareto.size}")
            counts = found.counts()
            rows.append([f"{kind} = {value:g} {found.unit}", ladder, mid, min(cpu), max(cpu),
                         statistics.median(wall), min(wall), max(wall), args.samples / mid,
                         mid / TARGET_SECONDS, found.solves / args.samples, found.rounds,
                         *(counts[name] for name in OUTCOMES), found.pareto.size])
            if ladder == DEFAULT_DESIGN_LADDER and args.check:
                checks.append([f"{kind} = {value:g} {found.unit}",
                               *check(found, kind, args.check)])
    results.table(
        f"search_designs over {args.samples:,} candidates, {args.rounds} runs each",
        [Column("target"), Column("ladder"), Column("CPU", "s", ".2f"), Column("min", "s", ".2f"),
         Column("max", "s", ".2f"), Column("wall", "s", ".2f"), Column("min", "s", ".2f"),
         Column("max", "s", ".2f"), Column("candidates per CPU s", format=",.0f"),
         Column("× the target", format=".2f"), Column("solves per candidate", format=".2f"),
         Column("rounds"), *(Column(name) for name in OUTCOMES), Column("Pareto")], rows,
        note=f"paper-experiment with {', '.join(FREE)} free (w_n 0.5-3 mm, w_d 0.6-2.2 mm, N "
             f"3-12, w_t 1-6 mm), Sobol' samples, budget 0-20 N, allowable strain 6 %, one core; "
             f"CPU and wall: median of the runs; target {TARGET_SECONDS:g} CPU s; default ladder "
             f"{DEFAULT_DESIGN_LADDER}")
    if checks:
        results.table(
            "Check against solve_inverse, default ladder",
            [Column("target"), Column("designs"),
             Column("largest relative tension difference", format=".1e"),
             Column("largest |tip − target|", format=".1e"), Column("unit"),
             Column("tol", format="g")], checks,
            note="Pareto and other meets designs; tension against solve_inverse (same target, "
                 "bounds 0-20 N), and a re-solve with solve at the reported tension (the tip is "
                 "bit-identical)")
    if args.profile:
        profiler = cProfile.Profile()
        profiler.enable()
        run("tip_angle", args.samples, DEFAULT_DESIGN_LADDER)
        profiler.disable()
        pstats.Stats(profiler).sort_stats("cumulative").print_stats(25)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
