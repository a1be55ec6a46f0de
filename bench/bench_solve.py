"""Single-solve benchmark (issue 2): median time of one solve and iterations to converge.

Run: ``python bench/bench_solve.py [--repeats 2000] [--baseline /work/main] [--rounds 3]
[--results FILE]``.
Prints the median and p90 time per solve on ``paper-experiment`` at 20 N with the default
settings (compiled kernel, and the plain-Python build of the same kernel, ``TDCM_JIT=0``),
the tip error of that solve against a converged reference, and the iterations across presets
and hard designs. Issue 27: the same solve through the shipped body file, and a body whose 8
notches all differ (widths, backbones, tubes), the same body with one-sided cuts and the
paper's tube with 8 polygon (tee) notches, timed
interleaved in this process, as ratios to the preset. ``--baseline`` times another checkout of the package (e.g. main's NumPy
path) in the same run: baseline and this checkout alternate in fresh processes for
``--rounds`` rounds and the ratio of their medians is printed. Issue 34: the same solve's
compiled floor, ``bench/solve_reference.c`` (the kernel's fixed point in C, compiled here with
gcc into a shared library and called through ctypes on the solve's own grid arrays, each
solve timed inside C), interleaved with the package's solve; its tip must equal the
package's to the last bit. Without gcc that part is skipped.
Single-threaded: BLAS threads are pinned to one before NumPy loads. ``--results FILE`` also
writes the printed figures as tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import ctypes
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import PRESETS, SolverSettings, preset, read_body_file, solve
from tdcm_ros.model.design import Design
from tdcm_ros.model.grid import build_grid
from tdcm_ros.model.moment_model import DIVERGENCE_GROWTH
from tdcm_ros.model.solver import DEFAULT_SETTINGS, SLOW_CONTRACTION

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


def all_different() -> Design:
    """Eight notches, all different (issue 27's target: <= 1.2x the uniform body's solve);
    built on use, so that --baseline may time a checkout without per-notch designs."""
    return preset("paper-experiment").with_overrides(
        w_n=[2.0e-3, 2.5e-3, 1.5e-3, 2.1e-3, 2.2e-3, 3.0e-3, 1.9e-3, 1.8e-3],
        w_d=[1.6e-3, 1.5e-3, 1.4e-3, 1.3e-3, 1.2e-3, 1.1e-3, 1.0e-3, 0.9e-3],
        w_t=[4e-3, 3e-3, 5e-3, 4.5e-3, 3.5e-3, 4e-3, 2e-3])


def all_different_cuts() -> Design:
    """:func:`all_different` with one-sided cuts 5.0 to 6.4 mm deep instead of the bands (the
    off-axis centroid's mechanics in every notch cell)."""
    cuts = [5.0e-3, 5.2e-3, 5.4e-3, 5.6e-3, 5.8e-3, 6.0e-3, 6.2e-3, 6.4e-3]
    base = all_different()
    return base.with_overrides(w_d=[2 * base.R_outer - c for c in cuts], w_o=[-c / 2 for c in cuts])


BODIES = Path(__file__).resolve().parents[1] / "config" / "bodies"
BODY_FILE = BODIES / "paper_experiment.yaml"


def interleaved(designs: dict[str, Design], repeats: int, rounds: int = 5) -> dict[str, float]:
    """Median solve time (s) of each design at 20 N, ``rounds`` rounds of ``repeats // rounds``
    solves each, the designs taking turns (warm grid caches)."""
    times: dict[str, list[float]] = {name: [] for name in designs}
    for design in designs.values():
        solve(design, 20.0)
    for _ in range(rounds):
        for name, design in designs.items():
            for _ in range(max(repeats // rounds, 1)):
                start = time.perf_counter()
                solve(design, 20.0)
                times[name].append(time.perf_counter() - start)
    return {name: float(np.median(t)) for name, t in times.items()}


C_SOURCE = Path(__file__).resolve().with_name("solve_reference.c")
C_FLAGS = ("-O3", "-march=native", "-ffp-contract=off", "-shared", "-fPIC")
"""No fused multiply-adds, no fast math: the C solve rounds as numba's kernel does."""


class CReference:
    """``bench/solve_reference.c`` built into ``workdir`` and bound to one design's grid at
    one tension (N), with the default settings."""

    def __init__(self, workdir: Path, design: Design, tension: float) -> None:
        library = workdir / "solve_reference.so"
        subprocess.run(["gcc", *C_FLAGS, "-o", str(library), str(C_SOURCE), "-lm"], check=True)
        self.lib = ctypes.CDLL(str(library))
        grid = build_grid(design, DEFAULT_SETTINGS)
        cells = grid.cells
        n, budget = grid.n_cells, DEFAULT_SETTINGS.max_iter
        self.arrays = [np.ascontiguousarray(a[0]) for a in
                       (cells.fc, cells.fq, cells.ic, cells.notch, cells.scal)]
        self.x0 = np.full(2 * n, grid.r_c * tension)
        self.x, self.theta, self.info = np.empty(2 * n), np.empty(n + 1), np.empty(3 + budget)
        self.p, self.tangent = np.empty(n + 1, complex), np.empty(n + 1, complex)
        pointer = ctypes.c_void_p
        self.args = [ctypes.c_int(n), ctypes.c_int(cells.fq.shape[3]),
                     ctypes.c_int(cells.notch.shape[2]),
                     *(a.ctypes.data_as(pointer) for a in self.arrays), ctypes.c_double(tension),
                     self.x0.ctypes.data_as(pointer), ctypes.c_double(DEFAULT_SETTINGS.tol),
                     ctypes.c_double(SLOW_CONTRACTION), ctypes.c_double(DIVERGENCE_GROWTH),
                     ctypes.c_int(budget),
                     *(a.ctypes.data_as(pointer) for a in (self.x, self.p, self.theta,
                                                           self.tangent, self.info))]

    def tip(self) -> np.ndarray:
        """The C solve's tip ``(x, 0, z)`` (m)."""
        self.lib.tdcm_solve(*self.args)
        return np.array([self.p[-1].imag, 0.0, self.p[-1].real])

    def times(self, repeats: int) -> np.ndarray:
        """Wall time (s) of each of ``repeats`` C solves, timed inside C."""
        out = np.empty(repeats)
        self.lib.tdcm_time(ctypes.c_int(repeats), out.ctypes.data_as(ctypes.c_void_p), *self.args)
        return out


def against_c(repeats: int, results: BenchResults, rounds: int = 5) -> None:
    """The package's solve of paper-experiment at 20 N against the C floor, interleaved in
    ``rounds`` rounds; prints both medians, their ratio and the bit check of the tips."""
    if shutil.which("gcc") is None:
        print("C reference: skipped (no gcc)")
        return
    design = preset("paper-experiment")
    with tempfile.TemporaryDirectory() as workdir:
        reference = CReference(Path(workdir), design, 20.0)
        tip = reference.tip()
        package: list[np.ndarray] = []
        floor: list[np.ndarray] = []
        for _ in range(rounds):
            package.append(time_solves(max(repeats // rounds, 1)))
            floor.append(reference.times(max(repeats // rounds, 1)))
    mine = solve(design, 20.0).tip_position
    same = bool(np.array_equal(tip, mine))
    m, c = float(np.median(np.concatenate(package))), float(np.median(np.concatenate(floor)))
    print(f"C reference (bench/solve_reference.c), interleaved, {rounds} rounds")
    print(f"  package solve          {m * 1e6:8.2f} us")
    print(f"  C solve (timed in C)   {c * 1e6:8.2f} us")
    print(f"  ratio                  {m / c:8.2f}x   (target <= 1.5x, <= 5 us)")
    print(f"  tips bit-identical     {same}  (C {tip.tolist()}, package {mine.tolist()})")
    results.table(
        "Single solve against its compiled floor (C), interleaved",
        [Column("solve"), Column("median", "µs", ".2f"), Column("× the C floor", format=".2f")],
        [["package: solve(paper-experiment, 20 N)", m * 1e6, m / c],
         ["C: bench/solve_reference.c, timed in C", c * 1e6, 1.0]],
        note=f"{rounds} interleaved rounds of {max(repeats // rounds, 1)} solves each; "
             f"gcc {' '.join(C_FLAGS)}; tips bit-identical: {same}")
    if not same:
        raise SystemExit("C reference: the tip differs from the package's")


def median_in(checkout: Path, repeats: int, jit: str = "1") -> float:
    """Median solve time (s) measured in a fresh process importing ``tdcm_ros`` from
    ``checkout`` (``jit``: the ``TDCM_JIT`` switch, ignored by checkouts without it)."""
    env = {**os.environ, "PYTHONPATH": str(checkout), "TDCM_JIT": jit}
    out = subprocess.run([sys.executable, __file__, "--median-only", "--repeats", str(repeats)],
                         env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1])


def compare(baseline: Path, repeats: int, rounds: int, results: BenchResults) -> None:
    """Alternate baseline and this checkout; print medians and their ratio."""
    here = Path(__file__).resolve().parents[1]
    base, mine = [], []
    for _ in range(rounds):
        base.append(median_in(baseline, repeats))
        mine.append(median_in(here, repeats))
    b, m = float(np.median(base)), float(np.median(mine))
    print(f"same-run comparison, {rounds} alternating rounds of {repeats} solves")
    print(f"  baseline {baseline}: median {b * 1e6:8.1f} us  (rounds: "
          + ", ".join(f"{t * 1e6:.1f}" for t in base) + ")")
    print(f"  this checkout      : median {m * 1e6:8.1f} us  (rounds: "
          + ", ".join(f"{t * 1e6:.1f}" for t in mine) + ")")
    print(f"  speed-up           : {b / m:8.1f}x  (target >= 10x, <= 10 us)")
    results.table(
        f"Same-run comparison, {rounds} alternating rounds of {repeats} solves",
        [Column("checkout"), Column("median solve", "µs", ".1f"), Column("rounds", "µs")],
        [[f"baseline {baseline}", b * 1e6, ", ".join(f"{t * 1e6:.1f}" for t in base)],
         ["this checkout", m * 1e6, ", ".join(f"{t * 1e6:.1f}" for t in mine)]],
        note=f"speed-up (baseline median / this checkout's): {b / m:.1f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2000)
    parser.add_argument("--baseline", type=Path, help="checkout to compare with, e.g. /work/main")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--median-only", action="store_true", help=argparse.SUPPRESS)
    add_results_argument(parser, "bench_solve")
    args = parser.parse_args()
    if args.median_only:
        print(float(np.median(time_solves(args.repeats))))
        return
    results = BenchResults("bench_solve")
    if args.baseline is not None:
        compare(args.baseline, args.repeats, args.rounds, results)
    against_c(args.repeats, results)
    plain = median_in(Path(__file__).resolve().parents[1], max(args.repeats // 10, 20), "0")
    design = preset("paper-experiment")
    reference = solve(design, 20.0, settings=REFERENCE).tip_position
    finer = solve(design, 20.0, settings=FINER).tip_position
    default = solve(design, 20.0)
    times = time_solves(args.repeats)
    start = time.perf_counter()
    solve(design.with_overrides(E=1.8e9), 20.0)
    first = time.perf_counter() - start
    print("paper-experiment, T = 20 N, default settings")
    print(f"  median solve time      {np.median(times) * 1e6:8.1f} us   (target <= 10 us)")
    print(f"  p90 solve time         {np.percentile(times, 90) * 1e6:8.1f} us")
    print(f"  plain-Python build     {plain * 1e6:8.1f} us   (TDCM_JIT=0: no numba import)")
    print(f"  first solve of a new design (grid build) {first * 1e3:.2f} ms")
    print(f"  tip error vs reference {np.linalg.norm(default.tip_position - reference) * 1e9:8.2f}"
          " nm  (target <= 1000 nm)")
    print(f"  reference self-check   {np.linalg.norm(finer - reference) * 1e9:8.3f} nm "
          "(256 vs 512 cells/notch)")
    results.table(
        "Single solve: paper-experiment at 20 N, default settings",
        [Column("figure"), Column("measured"), Column("unit")],
        [["median solve time", np.median(times) * 1e6, "µs"],
         ["p90 solve time", np.percentile(times, 90) * 1e6, "µs"],
         ["plain-Python build (TDCM_JIT=0), median", plain * 1e6, "µs"],
         ["first solve of a new design (grid build)", first * 1e3, "ms"],
         ["tip error vs the converged reference",
          np.linalg.norm(default.tip_position - reference) * 1e9, "nm"],
         ["reference self-check (256 vs 512 cells per notch)",
          np.linalg.norm(finer - reference) * 1e9, "nm"]],
        note=f"{args.repeats} timed solves (the plain-Python build: "
             f"{max(args.repeats // 10, 20)}, in a fresh process)")
    bodies = interleaved({"preset": design, "body file": read_body_file(BODY_FILE).design(),
                          "8 notches all different": all_different(),
                          "8 one-sided cuts": all_different_cuts(),
                          "8 polygon notches": read_body_file(BODIES / "tee_notches.yaml").design()},
                         args.repeats)
    print("body path (issue 27), interleaved medians at 20 N")
    for name, median in bodies.items():
        print(f"  {name:24s} {median * 1e6:8.1f} us  {median / bodies['preset']:5.2f}x the preset"
              + ("   (target <= 1.2x)" if name.startswith("8 notches") else
                 "   (target: no slower)" if name == "body file" else ""))
    results.table(
        "Body path: interleaved median solve at 20 N",
        [Column("body"), Column("median solve", "µs", ".1f"), Column("× the preset", format=".2f")],
        [[name, median * 1e6, median / bodies["preset"]] for name, median in bodies.items()],
        note="preset: paper-experiment; body file: config/bodies/paper_experiment.yaml; "
             "8 polygon notches: config/bodies/tee_notches.yaml")
    print("iterations to converge (tol 1e-10 m), strategy")
    iterations = []
    for name in PRESETS:
        row = [solve(preset(name), t) for t in (4.0, 12.0, 20.0)]
        print(f"  {name:22s} " + "  ".join(f"{t:4.0f} N: {r.iterations:2d} ({r.strategy})"
                                           for t, r in zip((4, 12, 20), row, strict=True)))
        iterations.append([name, *(r.iterations for r in row),
                           ", ".join(dict.fromkeys(r.strategy for r in row))])
    results.table("Iterations to converge (tol 1e-10 m), presets",
                  ["preset", "at 4 N", "at 12 N", "at 20 N", "strategy"], iterations)
    hard_rows = []
    for name, hard in HARD.items():
        for routing in ("paper", "free"):
            r = solve(hard, HARD_TENSION[name], settings=SolverSettings(routing=routing))
            print(f"  {name:22s} {routing:5s} {HARD_TENSION[name]:4g} N: {r.iterations:3d} "
                  f"({r.strategy}), tip angle {np.degrees(r.tip_angle_rad):7.1f} deg")
            hard_rows.append([name, routing, HARD_TENSION[name], r.iterations, r.strategy,
                              np.degrees(r.tip_angle_rad)])
    results.table("Iterations to converge (tol 1e-10 m), hard designs",
                  [Column("design"), Column("routing"), Column("tension", "N", "g"),
                   Column("iterations"), Column("strategy"), Column("tip angle", "deg", ".1f")],
                  hard_rows)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
