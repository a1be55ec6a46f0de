"""Batch solver throughput on one core for paper-like designs, and its tip error.

Run: ``python bench/bench_batch.py [--designs 40] [--tensions 250] [--many 2000]
[--repeat 5] [--baseline /work/main] [--rounds 3] [--results FILE]``.

Workloads (default solver settings, whose tip error against a converged reference is printed):

- design space: ``designs`` paper-like designs (w_n x w_d around the paper's, fixed pitch,
  L = 53 mm) x ``tensions`` tensions in 0-20 N, grids already built (what a sweep costs once
  the design grid exists) and cold (grid building included);
- many designs: one tension per design, grid building included (the worst case); also with
  the grids' partial integrals by the interpolated rule (``partials="interpolated"``: 25
  compliance evaluations per notch cell instead of 61, tips within the grid's accuracy of the
  single solve's; ``bench/grid_accuracy.py``).

Both are also timed with two worker threads (``workers=2``). Every workload is timed in
``--rounds`` interleaved rounds (best of ``--repeat`` each): medians, spreads and the
per-round ratio of two workers to one are printed; one-worker workloads also per CPU second
of the process (``time.process_time``), which other jobs on shared cores disturb less.
``--baseline`` times another checkout (e.g. main) on the warm design-space and the
many-design cases in the same run: it and this checkout alternate in fresh processes for
``--rounds`` rounds and the per-round ratios are printed. ``--breakdown`` prints only the CPU
time of the many-design case's steps.

Tip error: the batch against single solves at the same settings (should be ~1e-17 m; with
interpolated partial integrals ~1e-10 m), and against converged single solves (128 cells per notch, 16 per tube, 12-point quadrature,
tol 1e-14 m) on a sample of points. Timings are best of ``repeat``. ``--results FILE`` also
writes the printed figures as tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from time import perf_counter, process_time
from typing import Any

from results import BenchResults, Column, add_results_argument

THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "NUMEXPR_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")
MM = 1e-3
#: ``tdcm_ros.model.grid.INTERPOLATED``, spelled here: a baseline checkout may predate it.
INTERPOLATED = "interpolated"


def paper_like(count: int, rng: Any) -> list[Any]:
    """Designs of the paper's family: w_n in 1-2.5 mm, w_d in 1.2-2 mm, pitch 6 mm."""
    from tdcm_ros.model import preset
    from tdcm_ros.model.design_space import couple

    base = preset("fig2-wn-1.9")
    return [couple(base.with_overrides(w_n=rng.uniform(1.0, 2.5) * MM,
                                       w_d=rng.uniform(1.2, 2.0) * MM), "fixed-pitch", 6 * MM)
            for _ in range(count)]


def best_time(run: Callable[[], object], repeat: int, cold: bool, clock: Callable[[], float]
              = perf_counter) -> float:
    """Best time (s, wall unless ``clock`` says otherwise) of ``run()`` over ``repeat`` calls;
    ``cold`` clears the grid cache."""
    from tdcm_ros.model.grid import clear_grid_cache

    times = []
    for _ in range(repeat):
        if cold:
            clear_grid_cache()
        started = clock()
        run()
        times.append(clock() - started)
    return min(times)


def stats(values: list[float]) -> list[float]:
    """``[median, min, max]`` of ``values`` (the median as :func:`spread` takes it)."""
    ordered = sorted(values)
    return [ordered[len(ordered) // 2], ordered[0], ordered[-1]]


def spread(values: list[float]) -> str:
    """``median (min-max)`` of ``values``."""
    ordered = sorted(values)
    return f"{ordered[len(ordered) // 2]:.0f} ({ordered[0]:.0f}-{ordered[-1]:.0f})"


def ratio_spread(values: list[float]) -> str:
    """``median (min-max)`` of ratios."""
    ordered = sorted(values)
    return f"{ordered[len(ordered) // 2]:.2f}x ({ordered[0]:.2f}-{ordered[-1]:.2f})"


def workloads(args: argparse.Namespace) -> dict[str, tuple[int, Callable[[], object], bool]]:
    """Name -> (solves, run, cold) of every timed workload (imports NumPy)."""
    import numpy as np

    from tdcm_ros.model import SolverSettings
    from tdcm_ros.model.batch import solve_batch

    settings = SolverSettings()
    rng = np.random.default_rng(2024)
    designs = paper_like(args.designs, rng)
    tensions = np.broadcast_to(np.linspace(0.0, 20.0, args.tensions),
                               (args.designs, args.tensions))
    many = paper_like(args.many, rng)
    many_t = rng.uniform(0.0, 20.0, args.many)
    return {
        "space": (tensions.size, lambda: solve_batch(designs, tensions, settings=settings),
                  False),
        "space2": (tensions.size,
                   lambda: solve_batch(designs, tensions, settings=settings, workers=2), False),
        "cold": (tensions.size, lambda: solve_batch(designs, tensions, settings=settings),
                 True),
        "many": (args.many, lambda: solve_batch(many, many_t, settings=settings), True),
        "many2": (args.many, lambda: solve_batch(many, many_t, settings=settings, workers=2),
                  True),
        "manyi": (args.many, lambda: solve_batch(many, many_t, settings=settings,
                                                 partials=INTERPOLATED), True),  # this checkout
    }


def throughputs(args: argparse.Namespace, names: list[str], rounds: int
                ) -> dict[str, list[float]]:
    """Solves/s of workloads ``names`` (best of ``repeat`` each), interleaved for ``rounds``."""
    work = workloads(args)
    for name in names:
        work[name][1]()  # compile and warm up
    out: dict[str, list[float]] = {name: [] for name in names}
    for _ in range(rounds):
        for name in names:
            count, call, cold = work[name]
            out[name].append(count / best_time(call, args.repeat, cold))
            if "2" not in name:  # CPU time of one thread: less sensitive to the other jobs
                out.setdefault(f"{name} cpu", []).append(
                    count / best_time(call, args.repeat, cold, process_time))
    return out


def run(args: argparse.Namespace, results: BenchResults | None = None) -> None:
    """Measure and print (NumPy is imported here, after the thread variables are set); the
    figures also go to ``results``."""
    import numpy as np

    from tdcm_ros.model import SolverSettings, solve
    from tdcm_ros.model.batch import solve_batch

    if args.throughput_only:  # also in a baseline checkout: its API only
        measured = throughputs(args, ["space", "many"], 1)
        print(measured["space cpu"][0], measured["many cpu"][0])
        print(measured["space"][0], measured["many"][0])
        return
    reference = SolverSettings(cells_per_notch=128, cells_per_tube=16, quad_order=12, tol=1e-14)
    settings = SolverSettings()
    rng = np.random.default_rng(2024)
    designs = paper_like(args.designs, rng)
    tensions = np.broadcast_to(np.linspace(0.0, 20.0, args.tensions),
                               (args.designs, args.tensions))
    count = tensions.size
    result = solve_batch(designs, tensions, settings=settings)
    interpolated = solve_batch(designs, tensions, settings=settings, partials=INTERPOLATED)
    names = ["space", "space2", "cold", "many", "many2", "manyi"]
    measured = throughputs(args, names, args.rounds)
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
    fine = {(i, k): solve(designs[i], tensions[i, k], settings=reference).tip_position
            for i, k in picks}
    converged = [float(np.linalg.norm(fine[i, k] - result.tip_position[i, k])) for i, k in picks]
    same_i = max(float(np.max(np.abs(solve(designs[i], tensions[i, k], settings=settings)
                                     .tip_position - interpolated.tip_position[i, k])))
                 for i, k in picks)
    converged_i = [float(np.linalg.norm(fine[i, k] - interpolated.tip_position[i, k]))
                   for i, k in picks]

    def per_round(two: str, one: str) -> list[float]:
        return [b / a for a, b in zip(measured[one], measured[two], strict=True)]

    print(f"settings: cells_per_notch={settings.cells_per_notch}, quad_order="
          f"{settings.quad_order}, tol={settings.tol:g} m; "
          f"{', '.join(THREAD_VARIABLES)} = {os.environ['OMP_NUM_THREADS']}")
    print(f"statuses: {dict(zip(*np.unique(result.status, return_counts=True)))}; "
          f"fallback to single solve: {int(result.fallback.sum())}")
    print(f"solves/s, median (min-max) of {args.rounds} interleaved rounds, each best of "
          f"{args.repeat}")
    print(f"design space {args.designs} designs x {args.tensions} tensions = {count} solves")
    print(f"  grids built  : {spread(measured['space'])} (per CPU second: "
          f"{spread(measured['space cpu'])})")
    print(f"  two workers  : {spread(measured['space2'])}; per round "
          f"{ratio_spread(per_round('space2', 'space'))} one worker (target >= 1.8x)")
    print(f"  incl. grids  : {spread(measured['cold'])} (per CPU second: "
          f"{spread(measured['cold cpu'])})")
    print(f"many designs {args.many} x 1 tension, incl. grids: {spread(measured['many'])} "
          f"(per CPU second: {spread(measured['many cpu'])})")
    print(f"  two workers  : {spread(measured['many2'])}; per round "
          f"{ratio_spread(per_round('many2', 'many'))} one worker")
    print(f"  interpolated partial integrals: {spread(measured['manyi'])} (per CPU second: "
          f"{spread(measured['manyi cpu'])}); per round "
          f"{ratio_spread(per_round('manyi', 'many'))} nested")
    print(f"single solve() loop          : {single_n / single_time:10.0f} solves/s")
    print(f"tip error vs single solve, same settings ({len(picks)} points): {same:.2e} m")
    print(f"tip error vs converged reference: max {max(converged) * 1e6:.3f} um, "
          f"median {np.median(converged) * 1e6:.3f} um (target <= 1 um)")
    print(f"interpolated partial integrals: tip error vs single solve {same_i:.2e} m, vs "
          f"converged reference max {max(converged_i) * 1e6:.3f} um, median "
          f"{np.median(converged_i) * 1e6:.3f} um")
    if results is None:
        return
    space = f"design space {args.designs} designs × {args.tensions} tensions"
    many = f"many designs {args.many} × 1 tension"
    rate = ",.0f"
    results.table(
        f"Batch throughput: median (min–max) of {args.rounds} interleaved rounds, each best of "
        f"{args.repeat}",
        [Column("workload"), Column("workers"), Column("solves/s", format=rate),
         Column("min", format=rate), Column("max", format=rate),
         Column("per CPU second", format=rate), Column("min", format=rate),
         Column("max", format=rate)],
        [[f"{space}, grids built", 1, *stats(measured["space"]), *stats(measured["space cpu"])],
         [f"{space}, grids built", 2, *stats(measured["space2"]), None, None, None],
         [f"{space}, incl. grids", 1, *stats(measured["cold"]), *stats(measured["cold cpu"])],
         [f"{many}, incl. grids", 1, *stats(measured["many"]), *stats(measured["many cpu"])],
         [f"{many}, incl. grids", 2, *stats(measured["many2"]), None, None, None],
         [f"{many}, incl. grids, interpolated partial integrals", 1, *stats(measured["manyi"]),
          *stats(measured["manyi cpu"])],
         [f"single solve() loop, {single_n} solves", 1, single_n / single_time, None, None, None,
          None, None]],
        note=f"settings: cells_per_notch={settings.cells_per_notch}, quad_order="
             f"{settings.quad_order}, tol={settings.tol:g} m; thread pools pinned to 1; "
             "statuses " + ", ".join(f"{k} {int(v)}" for k, v in zip(
                 *np.unique(result.status, return_counts=True), strict=True)) + "; "
             f"fallback to single solve: {int(result.fallback.sum())}. Per CPU second: solves "
             "per second of the process's CPU time (process_time), steadier on shared cores. "
             "The single solve() loop is best of 2.")
    results.table(
        "Two workers against one, per round (wall)",
        [Column("workload"), Column("two workers / one", format=".2f"),
         Column("min", format=".2f"), Column("max", format=".2f")],
        [[space, *stats(per_round("space2", "space"))],
         [many, *stats(per_round("many2", "many"))]])
    results.table(
        "Interpolated partial integrals against nested, per round (wall)",
        [Column("workload"), Column("interpolated / nested", format=".2f"),
         Column("min", format=".2f"), Column("max", format=".2f")],
        [[many, *stats(per_round("manyi", "many"))]])
    results.table(
        "Tip error of the batch",
        [Column("against"), Column("points"), Column("max", "m", ".2e"),
         Column("median", "m", ".2e")],
        [["single solves, same settings", len(picks), same, None],
         [("converged single solves (128 cells per notch, 16 per tube, quadrature order 12, "
           "tol 1e-14 m)"), len(picks), max(converged), float(np.median(converged))],
         ["interpolated partial integrals: single solves, same settings", len(picks), same_i,
          None],
         ["interpolated partial integrals: converged single solves", len(picks),
          max(converged_i), float(np.median(converged_i))]])


def throughput_in(checkout: Path, args: argparse.Namespace
                  ) -> tuple[float, float, float, float]:
    """Design-space (grids built) and many-design throughputs (solves/s), then the same per
    CPU second, in a fresh process importing ``tdcm_ros`` from ``checkout``."""
    env = {**os.environ, "PYTHONPATH": str(checkout)}
    command = [sys.executable, __file__, "--throughput-only", "--designs", str(args.designs),
               "--tensions", str(args.tensions), "--many", str(args.many), "--repeat",
               str(args.repeat)]
    out = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    space_cpu, many_cpu, space, many = (float(v) for v in out.stdout.split()[-4:])
    return space, many, space_cpu, many_cpu


def breakdown(args: argparse.Namespace, results: BenchResults) -> None:
    """CPU time (best of ``repeat``) of the steps of the many-design case, and of the grid
    kernel per compliance evaluation point."""
    import numpy as np

    from tdcm_ros.model import SolverSettings
    from tdcm_ros.model.batch import _Stack, prepare_batch, solve_batch
    from tdcm_ros.model.grid import NESTED, _prototype_integrals, grid_parts
    from tdcm_ros.model.grid_layout import PEAK_SAMPLES, Members, cell_table, prototypes

    settings = SolverSettings()

    rng = np.random.default_rng(2024)
    paper_like(args.designs, rng)
    many = paper_like(args.many, rng)
    many_t = rng.uniform(0.0, 20.0, args.many)
    members = Members.of(many)
    layout = (settings.routing, settings.grid, settings.cells_per_notch,
              settings.cells_per_tube)
    proto = prototypes(members, *layout)
    parts = grid_parts(many, settings)
    prepared = prepare_batch(many, settings=settings)
    steps: list[tuple[str, Callable[[], object]]] = [
        ("solve_batch, all of it", lambda: solve_batch(many, many_t, settings=settings)),
        ("Members.of (collect, check rigidity)", lambda: Members.of(many)),
        ("prototypes + cell_table (layout)",
         lambda: cell_table(prototypes(members, *layout), settings.routing)),
        ("grid kernel (cell_integrals)",
         lambda: _prototype_integrals(proto, settings.quad_order, NESTED)),
        ("grid kernel, interpolated partial integrals",
         lambda: _prototype_integrals(proto, settings.quad_order, INTERPOLATED)),
        ("stacks' index tables (kernel_indices)", lambda: _Stack.split(parts, settings)),
        ("iteration (BatchGrids.solve, grids built)", lambda: prepared.solve(many_t))]
    print(f"many designs {args.many} x 1: CPU time (process_time), best of {args.repeat}")
    kernel_ms: dict[str, float] = {}
    rows = []
    for label, call in steps:
        call()
        ms = best_time(call, args.repeat, False, process_time) * 1e3
        if label.startswith("grid kernel"):
            kernel_ms[NESTED if "(" in label else INTERPOLATED] = ms
        print(f"  {label:<44} {ms:7.1f} ms")
        rows.append([label, ms])
    q = settings.quad_order
    cells = int(np.sum(proto.is_notch))
    kernel_rows = []
    for rule, per_cell in ((NESTED, q + q * q + PEAK_SAMPLES + 2),
                           (INTERPOLATED, q + PEAK_SAMPLES + 2)):
        points, ms = cells * per_cell, kernel_ms[rule]
        print(f"  grid kernel, {rule}: {points / args.many:.0f} notch compliance points per "
              f"design, {ms * 1e6 / points:.1f} ns each (tube cells included in the time), "
              f"{ms * 1e3 / args.many:.1f} us per design")
        kernel_rows.append([rule, points / args.many, ms * 1e6 / points, ms * 1e3 / args.many])
    results.table(f"Many designs ({args.many} × 1 tension): CPU time per step, best of "
                  f"{args.repeat}", [Column("step"), Column("CPU time", "ms", ".1f")], rows)
    results.table("Grid kernel per design, by partial-integral rule",
                  [Column("rule"), Column("notch compliance points per design", format=".0f"),
                   Column("per point", "ns", ".1f"), Column("per design", "µs", ".1f")],
                  kernel_rows,
                  note="tube cells included in the time")


def compare(args: argparse.Namespace, results: BenchResults) -> None:
    """Alternate the baseline checkout and this one; print throughputs and their ratios."""
    here = Path(__file__).resolve().parents[1]
    base: list[tuple[float, float, float, float]] = []
    mine: list[tuple[float, float, float, float]] = []
    for _ in range(args.rounds):
        base.append(throughput_in(args.baseline, args))
        mine.append(throughput_in(here, args))
    print(f"same-run comparison, one core, {args.rounds} alternating rounds (fresh processes), "
          "solves/s median (min-max)")
    rows = []
    for k, (label, target) in enumerate(
            ((f"design space {args.designs} x {args.tensions}, grids built", "250,000"),
             (f"many designs {args.many} x 1, grids included", "100,000"))):
        b, m = [r[k] for r in base], [r[k] for r in mine]
        b_cpu, m_cpu = [r[k + 2] for r in base], [r[k + 2] for r in mine]
        print(f"  {label} (target >= {target} solves/s)")
        print(f"    baseline {args.baseline}: {spread(b)}; per CPU second {spread(b_cpu)}")
        print(f"    this checkout: {spread(m)}; per CPU second {spread(m_cpu)}")
        print(f"    speed-up per round: {ratio_spread([y / x for x, y in zip(b, m, strict=True)])}"
              f"; per CPU second "
              f"{ratio_spread([y / x for x, y in zip(b_cpu, m_cpu, strict=True)])}")
        rows.append([label, stats(b)[0], stats(b_cpu)[0], stats(m)[0], stats(m_cpu)[0],
                     *stats([y / x for x, y in zip(b, m, strict=True)]),
                     stats([y / x for x, y in zip(b_cpu, m_cpu, strict=True)])[0]])
    rate = ",.0f"
    results.table(
        f"Same-run comparison with {args.baseline}, one core, {args.rounds} alternating rounds "
        "(fresh processes), medians",
        [Column("workload"), Column("baseline solves/s", format=rate),
         Column("per CPU s", format=rate), Column("this checkout solves/s", format=rate),
         Column("per CPU s", format=rate), Column("speed-up per round", format=".2f"),
         Column("min", format=".2f"), Column("max", format=".2f"),
         Column("speed-up per CPU s", format=".2f")], rows)


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
    parser.add_argument("--breakdown", action="store_true",
                        help="only the CPU-time breakdown of the many-design case")
    parser.add_argument("--throughput-only", action="store_true", help=argparse.SUPPRESS)
    add_results_argument(parser, "bench_batch")
    args = parser.parse_args()
    os.environ.update({name: "1" for name in THREAD_VARIABLES})
    if args.throughput_only:
        run(args)
        return
    results = BenchResults("bench_batch")
    if args.breakdown:
        breakdown(args, results)
    else:
        if args.baseline is not None:
            compare(args, results)
        run(args, results)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
