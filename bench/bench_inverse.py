"""Inverse-model benchmark (issue 18, item 1): round trip to ``solve``, forward solves and time
per call against one solve in the same run, and the sensitivity's error.

Run: ``python bench/bench_inverse.py [--targets 20] [--seed 1] [--results FILE]``.
For every preset, ``--targets`` tensions drawn uniformly from ``[0.5, 49.5]`` N give a tip
deflection, a tip angle and a tip point (the tip of ``solve`` there); ``solve_inverse`` finds
each (default bounds ``[0, 50]`` N). Printed per target kind, on ``paper-experiment`` (the
issue's target row) and over all presets:

- round trip: the largest ``|solve(design, T*).tip - achieved tip|`` (m), ``solve`` cold;
- the largest distance from the achieved tip to the target (m or rad) and ``|T* - T|`` (N);
- forward solves per call (mean, max) and the median time per call, with the median time of
  one solve of the same design in the same run and their ratio;
- the sensitivity's relative error against a reference: Richardson-extrapolated central
  differences of solves at ``tol = 1e-14`` with steps 0.02 and 0.01 N;
- off the path: tip points 1 mm across the tip's path from the tip at each tension (the
  closest tip is still that one): forward solves, time, ``|T* - T|`` and the residual's error;
- why Brent: the solves (bounds included, sensitivity not) that ``brentq``, ``toms748`` and
  ``ridder`` need for the deflection and angle targets, under the tolerances the model uses.

Warm means after :func:`warm_up` and a first call (compiled kernels, cached grid). Single-threaded.
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

from tdcm_ros.model import (
    PRESETS,
    SolverSettings,
    preset,
    solve,
    solve_inverse,
    warm_up,
)

KINDS = ("tip_deflection", "tip_angle", "tip_point")
TIGHT = SolverSettings(tol=1e-14)


def target_of(kind: str, result) -> object:
    """The target of ``kind`` that ``result`` reaches."""
    if kind == "tip_point":
        return (float(result.tip_position[0]), float(result.tip_position[2]))
    return result.tip_deflection_m if kind == "tip_deflection" else result.tip_angle_rad


def reference_slope(design, tension: float) -> np.ndarray:
    """d(tip x, z)/dT (m/N) by Richardson extrapolation of tight central differences."""
    def central(step: float) -> np.ndarray:
        high = solve(design, tension + step, settings=TIGHT).tip_position
        low = solve(design, tension - step, settings=TIGHT).tip_position
        return (high - low)[[0, 2]] / (2.0 * step)
    return (4.0 * central(0.01) - central(0.02)) / 3.0


def median_solve_s(design, tensions: np.ndarray, repeats: int = 20) -> float:
    """Median wall time (s) of one (cold-started) solve of ``design`` at ``tensions``."""
    times = []
    for _ in range(repeats):
        for tension in tensions:
            start = time.perf_counter()
            solve(design, float(tension))
            times.append(time.perf_counter() - start)
    return float(np.median(times))


def measure(name: str, kind: str, tensions: np.ndarray) -> dict[str, float]:
    """Figures of the inverse of ``kind`` targets of preset ``name`` at ``tensions`` (N)."""
    design = preset(name)
    solve_inverse(design, **{kind: target_of(kind, solve(design, 20.0))})  # warm grid cache
    rows = []
    for tension in tensions:
        target = target_of(kind, solve(design, float(tension)))
        start = time.perf_counter()
        found = solve_inverse(design, **{kind: target})
        elapsed = time.perf_counter() - start
        cold = solve(design, found.tension_n)
        achieved = target_of(kind, found.result)
        slope = reference_slope(design, found.tension_n) if name == "paper-experiment" else None
        sens_err = (np.nan if slope is None else float(
            np.linalg.norm(np.subtract(found.sensitivity.tip_point_m_per_n, slope))
            / np.linalg.norm(slope)))
        rows.append((float(np.max(np.abs(cold.tip_position - found.result.tip_position))),
                     float(np.max(np.abs(np.subtract(achieved, target)))),
                     abs(found.tension_n - tension), found.forward_solves, elapsed, sens_err))
    table = np.array(rows)
    return {"round_trip_m": table[:, 0].max(), "target_err": table[:, 1].max(),
            "tension_err_n": table[:, 2].max(), "solves_mean": table[:, 3].mean(),
            "solves_max": table[:, 3].max(), "call_s": float(np.median(table[:, 4])),
            "sens_rel_err": float(np.nanmax(table[:, 5])) if name == "paper-experiment"
            else np.nan}


def measure_off_path(name: str, tensions: np.ndarray, offset: float = 1e-3) -> dict[str, float]:
    """Figures of point targets ``offset`` (m) across the tip's path at ``tensions`` (N)."""
    design = preset(name)
    rows = []
    for tension in tensions:
        tip = solve(design, float(tension)).tip_position[[0, 2]]
        along = (solve(design, float(tension) + 1e-3).tip_position
                 - solve(design, float(tension) - 1e-3).tip_position)[[0, 2]]
        aim = tip + offset * np.array([along[1], -along[0]]) / np.hypot(*along)
        start = time.perf_counter()
        found = solve_inverse(design, tip_point=(float(aim[0]), float(aim[1])))
        elapsed = time.perf_counter() - start
        rows.append((abs(found.tension_n - tension), abs(found.residual - offset),
                     found.forward_solves, elapsed))
    table = np.array(rows)
    return {"tension_err_n": table[:, 0].max(), "residual_err_m": table[:, 1].max(),
            "solves_mean": table[:, 2].mean(), "solves_max": table[:, 2].max(),
            "call_s": float(np.median(table[:, 3]))}


def finder_solves(finder: str, design, kind: str, target: float) -> int:
    """Distinct warm-started solves ``scipy.optimize.<finder>`` needs for a scalar target on
    ``[0, 50]`` N with the model's tolerances (xtol = 0.01 tol / mean slope, tol = 1e-9)."""
    import scipy.optimize

    solved: dict[float, object] = {}

    def miss(tension: float) -> float:
        if tension not in solved:
            warm = solved[max(solved, key=lambda t: -abs(t - tension))] if solved else None
            solved[tension] = solve(design, tension, warm_start=warm)
        return target_of(kind, solved[tension]) - target

    low, high = miss(0.0), miss(50.0)
    getattr(scipy.optimize, finder)(miss, 0.0, 50.0, xtol=0.01 * 1e-9 / (abs(high - low) / 50.0),
                                    rtol=4.0 * np.finfo(float).eps, maxiter=100)
    return len(solved)


def compare_finders(tensions: dict[str, np.ndarray]) -> list[list[object]]:
    """Print the mean and max solves of each scalar root finder over the targets; returns the
    rows printed."""
    rows: list[list[object]] = []
    for finder in ("brentq", "toms748", "ridder"):
        counts = [finder_solves(finder, preset(name), kind, target_of(kind, solve(preset(name), t)))
                  for name in PRESETS for t in tensions[name] for kind in KINDS[:2]]
        print(f"root finder {finder:8s}: {np.mean(counts):.2f} solves mean, {max(counts)} max "
              f"(deflection and angle targets, bounds included, sensitivity not)")
        rows.append([finder, float(np.mean(counts)), max(counts)])
    return rows


UNITS = {"tip_deflection": "m", "tip_angle": "rad", "tip_point": "m"}
ROW_COLUMNS = [Column("kind"), Column("designs"), Column("round trip to solve", "m", ".1e"),
               Column("target error", format=".1e"), Column("target unit"),
               Column("|T*−T|", "N", ".1e"), Column("forward solves, mean", format=".2f"),
               Column("max"), Column("time per call", "µs", ".0f"),
               Column("× one solve", format=".1f"), Column("sensitivity rel. error", format=".1e")]
"""The columns of :func:`_cells`: what :func:`_row` prints."""


def _cells(kind: str, designs: str, f: dict[str, float], ratio: float, *, sens: bool = True
           ) -> list[object]:
    return [kind, designs, f["round_trip_m"], f["target_err"], UNITS[kind], f["tension_err_n"],
            f["solves_mean"], int(f["solves_max"]), f["call_s"] * 1e6, ratio,
            f["sens_rel_err"] if sens else None]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=20, help="tensions per preset")
    parser.add_argument("--seed", type=int, default=1)
    add_results_argument(parser, "bench_inverse")
    args = parser.parse_args()
    results = BenchResults("bench_inverse")
    warm_up()
    rng = np.random.default_rng(args.seed)
    tensions = {name: rng.uniform(0.5, 49.5, args.targets) for name in PRESETS}
    solve_s = {name: median_solve_s(preset(name), tensions[name]) for name in PRESETS}
    print(f"{args.targets} targets per kind and preset, tensions U(0.5, 49.5) N, seed "
          f"{args.seed}; bounds [0, 50] N; one solve {solve_s['paper-experiment'] * 1e6:.1f} us "
          "median on paper-experiment")
    print(f"{'kind':15s} {'designs':17s} {'round trip m':>12s} {'target err':>10s} "
          f"{'|T*-T| N':>9s} {'solves':>11s} {'call us':>8s} {'x solve':>7s} "
          f"{'sens rel err':>12s}")
    rows: list[list[object]] = []
    for kind in KINDS:
        figures = {name: measure(name, kind, tensions[name]) for name in PRESETS}
        paper = figures["paper-experiment"]
        _row(kind, "paper-experiment", paper, paper["call_s"] / solve_s["paper-experiment"])
        rows.append(_cells(kind, "paper-experiment", paper,
                           paper["call_s"] / solve_s["paper-experiment"]))
        ratios = [figures[n]["call_s"] / solve_s[n] for n in PRESETS]
        every = {key: max(f[key] for f in figures.values()) for key in paper}
        every["solves_mean"] = float(np.mean([f["solves_mean"] for f in figures.values()]))
        every["call_s"] = float(np.median([f["call_s"] for f in figures.values()]))
        every["sens_rel_err"] = paper["sens_rel_err"]
        _row(kind, f"all {len(PRESETS)} presets", every, float(np.median(ratios)), sens=False)
        rows.append(_cells(kind, f"all {len(PRESETS)} presets", every, float(np.median(ratios)),
                           sens=False))
    results.table(
        "Inverse model per target kind", ROW_COLUMNS, rows,
        note=f"{args.targets} targets per kind and preset, tensions U(0.5, 49.5) N, seed "
             f"{args.seed}; bounds [0, 50] N; one solve "
             f"{solve_s['paper-experiment'] * 1e6:.1f} µs median on paper-experiment in this "
             f"run. Over all presets: the largest of each figure, the mean of the mean solves, "
             f"the median of the times and of the ratios to one solve")
    off_rows: list[list[object]] = []
    for name in ("paper-experiment", *(n for n in PRESETS if n != "paper-experiment")):
        f = measure_off_path(name, tensions[name])
        print(f"tip_point 1 mm off the path, {name:16s}: |T*-T| {f['tension_err_n']:.2e} N, "
              f"|residual - 1 mm| {f['residual_err_m']:.2e} m, solves {f['solves_mean']:.2f} / "
              f"{int(f['solves_max'])}, {f['call_s'] * 1e6:.1f} us per call "
              f"({f['call_s'] / solve_s[name]:.1f} x solve)")
        off_rows.append([name, f["tension_err_n"], f["residual_err_m"], f["solves_mean"],
                         int(f["solves_max"]), f["call_s"] * 1e6, f["call_s"] / solve_s[name]])
    results.table(
        "tip_point 1 mm off the path",
        [Column("design"), Column("|T*−T|", "N", ".1e"), Column("|residual − 1 mm|", "m", ".1e"),
         Column("forward solves, mean", format=".2f"), Column("max"),
         Column("time per call", "µs", ".0f"), Column("× one solve", format=".1f")], off_rows)
    results.table(
        "Scalar root finders on the deflection and angle targets",
        [Column("finder"), Column("solves, mean", format=".2f"), Column("max")],
        compare_finders(tensions), note="bounds included, sensitivity not")
    if args.results:
        results.write(args.results)


def _row(kind: str, designs: str, f: dict[str, float], ratio: float, *, sens: bool = True) -> None:
    sens_text = f"{f['sens_rel_err']:12.2e}" if sens else f"{'':>12s}"
    print(f"{kind:15s} {designs:17s} {f['round_trip_m']:12.2e} {f['target_err']:10.2e} "
          f"{f['tension_err_n']:9.2e} {f['solves_mean']:5.2f} / {int(f['solves_max']):2d} "
          f"{f['call_s'] * 1e6:8.1f} {ratio:7.1f} {sens_text}")


if __name__ == "__main__":
    main()
