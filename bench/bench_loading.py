"""Loading benchmark (issue 7): cost per solve of each loading kind and its iterations.

Run: ``python bench/bench_loading.py [--repeats 1000] [--results FILE]``. Solves
``paper-experiment`` at 20 N with default settings under: no loading, a capstan tension
profile, a tip force, gravity (body force) and notch contact, then all together; prints the
time per solve (median and minimum over batches of 20 solves; the minimum is the figure least
disturbed by other load on the machine), the iterations, the strategy and the tip's move against
no loading. A last row solves a softer rectangular-notch design where contact is active (its
notches close at 40 N). Single-threaded: BLAS threads are pinned to one before NumPy loads.
``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import Capstan, Loading, NotchContact, preset, solve

GRAVITY = (-1010.0 * 9.81, 0.0)  # N/m^3: Nylon 12 with gravity along -x (base frame)
KINDS: dict[str, Loading | None] = {
    "none": None,
    "tension profile": Loading(tension_profile=Capstan(0.1)),
    "tip force": Loading(tip_force=(0.2, 0.0)),
    "body force": Loading(body_force_density=GRAVITY),
    "contact": Loading(notch_contact=NotchContact()),
    "all": Loading(tension_profile=Capstan(0.1), tip_force=(0.2, 0.0),
                   body_force_density=GRAVITY, notch_contact=NotchContact()),
}


BATCH = 20


def time_solves(design, tension: float, loading: Loading | None, repeats: int) -> np.ndarray:
    """Mean wall time (s) per solve of each batch of ``BATCH`` solves, ``repeats`` solves in all
    (warm grid and closure-angle caches)."""
    solve(design, tension, loading=loading)
    times = np.empty(max(repeats // BATCH, 1))
    for k in range(times.size):
        start = time.perf_counter()
        for _ in range(BATCH):
            solve(design, tension, loading=loading)
        times[k] = (time.perf_counter() - start) / BATCH
    return times


COLUMNS = [Column("loading"), Column("median", "µs", ".1f"), Column("min", "µs", ".1f"),
           Column("iterations"), Column("strategy"), Column("tip move", "µm", ".2f"),
           Column("closed notches")]


def row(label: str, design, tension: float, loading: Loading | None, repeats: int,
        base_tip: np.ndarray) -> list[object]:
    """Print the row of one loading; returns its cells (:data:`COLUMNS`)."""
    result = solve(design, tension, loading=loading)
    times = time_solves(design, tension, loading, repeats)
    move = np.linalg.norm(result.tip_position - base_tip) * 1e6
    print(f"  {label:24s} {np.median(times) * 1e6:8.1f} {np.min(times) * 1e6:8.1f}"
          f" {result.iterations:5d}  {result.strategy:13s} {move:10.2f}"
          f"  {len(result.closed_notches)}")
    return [label, np.median(times) * 1e6, np.min(times) * 1e6, result.iterations,
            result.strategy, move, len(result.closed_notches)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1000)
    add_results_argument(parser, "bench_loading")
    args = parser.parse_args()
    results = BenchResults("bench_loading")
    design = preset("paper-experiment")
    base_tip = solve(design, 20.0).tip_position
    print("paper-experiment, T = 20 N, default settings")
    print(f"  {'loading':24s} {'median':>8s} {'min':>8s} {'iter':>5s}  {'strategy':13s} "
          f"{'tip move':>10s}  closed")
    print(f"  {'':24s} {'us':>8s} {'us':>8s} {'':5s}  {'':13s} {'um':>10s}")
    rows = [row(name, design, 20.0, loading, args.repeats, base_tip)
            for name, loading in KINDS.items()]
    note = (f"time per solve over batches of {BATCH} solves, {args.repeats} solves in all "
            "(min: the batch least disturbed by other load); tip move against no loading")
    results.table("paper-experiment, T = 20 N, default settings", COLUMNS, rows, note=note)
    soft = design.with_overrides(profile="rectangular", E=0.3e9)
    soft_tip = solve(soft, 20.0).tip_position
    print("rectangular notches, E = 0.3 GPa (closure at ~34 N without contact)")
    rows = [row("none, 20 N", soft, 20.0, None, args.repeats, soft_tip),
            row("contact, 40 N (closed)", soft, 40.0, Loading(notch_contact=NotchContact()),
                args.repeats, soft_tip)]
    results.table("Rectangular notches, E = 0.3 GPa (closure at ~34 N without contact)", COLUMNS,
                  rows, note=note)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
