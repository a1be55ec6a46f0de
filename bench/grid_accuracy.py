"""Tip error of the default grid against a converged reference, and its time per solve
against today's (``grid=uniform``) default, in the same run (issue 15, item 4).

Run: ``python bench/grid_accuracy.py [--quick] [--settings k=v,k=v ...] [--results FILE]``.

Cases: every preset with ``N`` in ``--notches`` (default 1, 8, 64; ``paper-experiment`` also
2, 4, 16, 32) and the accuracy bench's hard designs, at 4 and 20 N, both routings, both load
forms. The reference of each case is :func:`converged_tip` (Richardson extrapolation of two
fine adaptive grids; its own uncertainty is printed). Cases the model refuses at that load
(notch closure, the tendon singularity, eq. 7's 45 degree kink limit) are counted, not hidden.
The batch with ``partials="interpolated"`` (``solve_batch`` of each case alone, default grid)
is measured the same way: its grid takes the partial integrals by the interpolated rule (no
nested points), the single solve's by the nested one (:data:`tdcm_ros.model.grid.PARTIAL_RULES`); its largest difference
from the single solve is printed too. An independent check of the references' compliance
integration: the constrained tendon's tip from the reference grid against
``shooting-segmented`` at rtol 1e-11.
Single-threaded: BLAS threads are pinned to one before NumPy loads. ``--results FILE`` also
writes the printed figures as tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import PRESETS, SolverSettings, solve
from tdcm_ros.model.accuracy import (
    HARD_DESIGNS,
    REFERENCE,
    constrained_tip,
    converged_tip,
)
from tdcm_ros.model.baselines import ShootingOptions, solve_with
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.errors import ModelError, ModelLimitError
from tdcm_ros.model.grid import INTERPOLATED

TODAY = SolverSettings(grid="uniform", cells_per_notch=4, cells_per_tube=1, quad_order=4)
TENSIONS = (4.0, 20.0)
TARGET_M = 1e-7
MODELS = (("paper", "closed"), ("free", "closed"), ("paper", "literal"), ("free", "literal"))


def cases(notches: list[int], quick: bool) -> dict[str, object]:
    """Designs by name: presets at every ``N`` in ``notches``, and the hard designs."""
    names = ["paper-experiment", "fig3-wd-1.2"] if quick else list(PRESETS)
    out: dict[str, object] = {}
    for name in names:
        counts = sorted(set(notches) | ({2, 4, 16, 32} if name == "paper-experiment"
                                        and not quick else set()))
        for n in counts:
            out[f"{name} N={n}"] = PRESETS[name].with_overrides(N=n)
    if not quick:
        out.update(HARD_DESIGNS)
        out["fully-notched N=8"] = PRESETS["paper-experiment"].with_overrides(w_t=0.0)
    return out


def median_time(design: object, tension: float, settings: SolverSettings, repeats: int
                ) -> tuple[np.ndarray, float]:
    """Tip (m) and median wall time (s) of ``repeats`` solves (grid built beforehand)."""
    tip = solve(design, tension, settings=settings, strict=False).tip_position
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        solve(design, tension, settings=settings, strict=False)
        times.append(time.perf_counter() - start)
    return tip, float(np.median(times))


def batch_tip_of(design: object, tension: float, routing: str, loads: str) -> np.ndarray:
    """Tip (m) of ``solve_batch`` of ``design`` alone at ``tension`` (N), default grid."""
    settings = SolverSettings(routing=routing, loads=loads)
    result = solve_batch([design], np.array([tension]), settings=settings,
                         partials=INTERPOLATED)
    if not result.ok[0]:  # the single solve took it: a batch that refuses it is a failure
        raise RuntimeError(f"batch refused a case the single solve takes: {result.message[0]}")
    return result.tip_position[0]


def parse_settings(text: str) -> SolverSettings:
    """``k=v,k=v`` overrides of the default settings."""
    overrides: dict[str, object] = {}
    for item in filter(None, text.split(",")):
        key, value = item.split("=")
        overrides[key] = value if key in ("grid", "routing", "loads") else (
            float(value) if "." in value or "e" in value else int(value))
    return SolverSettings().with_overrides(**overrides)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two presets, closed loads")
    parser.add_argument("--notches", default="1,8,64")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--over", type=float, default=None,
                        help="also list the cases whose error exceeds this (m)")
    parser.add_argument("--settings", nargs="*", default=[""],
                        help="candidate grids as k=v,k=v overrides of the default ('' = it)")
    add_results_argument(parser, "grid_accuracy")
    args = parser.parse_args()
    results = BenchResults("grid_accuracy")
    candidates = {text or "default": parse_settings(text) for text in args.settings}
    designs = cases([int(n) for n in args.notches.split(",")], args.quick)
    models = MODELS[:2] if args.quick else MODELS
    print(f"today's default: {TODAY}\n")
    header = (f"{'model':<15}{'cases':>6}{'refused':>8}{'ref unc (m)':>12}"
              f"{'today err':>11}{'today ms':>9}")
    header += "".join(f"{(label[:14] + ' err'):>19}{'<=0.1um':>8}{'time/today':>11}"
                      for label in candidates)
    header += f"{'batch err':>11}{'<=0.1um':>8}{'batch-single':>13}"
    print(header)
    worst_case: dict[str, tuple[float, str]] = {label: (0.0, "") for label in candidates}
    rows: list[list[object]] = []
    over: list[list[object]] = []
    for routing, loads in models:
        unc = today_err = 0.0
        today_t: list[float] = []
        errs = {label: 0.0 for label in candidates}
        within = {label: 0 for label in candidates}
        ratios: dict[str, list[float]] = {label: [] for label in candidates}
        count = refused = batch_within = 0
        batch_err = batch_gap = 0.0
        for name, design in designs.items():
            for tension in TENSIONS:
                try:
                    reference, uncertainty = converged_tip(design, tension, routing, loads)
                    base = TODAY.with_overrides(routing=routing, loads=loads)
                    tip_today, t_today = median_time(design, tension, base, args.repeats)
                    runs = {label: median_time(design, tension, st.with_overrides(
                        routing=routing, loads=loads), args.repeats)
                        for label, st in candidates.items()}
                except ModelLimitError:
                    refused += 1
                    continue
                count += 1
                batch_tip = batch_tip_of(design, tension, routing, loads)
                batch_err = max(batch_err, float(np.linalg.norm(batch_tip - reference)))
                batch_within += float(np.linalg.norm(batch_tip - reference)) <= TARGET_M
                batch_gap = max(batch_gap, float(np.linalg.norm(
                    batch_tip - solve(design, tension, settings=SolverSettings(
                        routing=routing, loads=loads), strict=False).tip_position)))
                unc = max(unc, uncertainty)
                today_err = max(today_err, float(np.linalg.norm(tip_today - reference)))
                today_t.append(t_today)
                for label, (tip, elapsed) in runs.items():
                    err = float(np.linalg.norm(tip - reference))
                    errs[label] = max(errs[label], err)
                    within[label] += err <= TARGET_M
                    ratios[label].append(elapsed / t_today)
                    if args.over is not None and err > args.over:
                        print(f"  {label}: {err:.2e} m {routing}/{loads} {name} @ {tension:g} N")
                        over.append([label, f"{routing}/{loads}", name, tension, err])
                    if err > worst_case[label][0]:
                        worst_case[label] = (err, f"{routing}/{loads} {name} @ {tension:g} N")
        line = (f"{routing + '/' + loads:<15}{count:>6}{refused:>8}{unc:>12.1e}"
                f"{today_err:>11.2e}{np.median(today_t) * 1e3:>9.3f}")
        line += "".join(f"{errs[label]:>19.2e}{within[label]:>8}{np.median(ratios[label]):>11.2f}"
                        for label in candidates)
        line += f"{batch_err:>11.2e}{batch_within:>8}{batch_gap:>13.2e}"
        print(line, flush=True)
        rows.append([f"{routing}/{loads}", count, refused, unc, today_err,
                     float(np.median(today_t)) * 1e3,
                     *(cell for label in candidates for cell in (
                         errs[label], within[label], float(np.median(ratios[label])))),
                     batch_err, batch_within, batch_gap])
    results.table(
        "Tip error against the converged reference, and time against the uniform grid",
        [Column("model"), Column("cases"), Column("refused"),
         Column("reference uncertainty", "m", ".1e"), Column("uniform grid: worst", "m", ".2e"),
         Column("uniform grid: median time", "ms", ".3f"),
         *(column for label in candidates for column in (
             Column(f"{label}: worst", "m", ".2e"), Column(f"{label}: cases ≤ 0.1 µm"),
             Column(f"{label}: time / uniform", format=".2f"))),
         Column("batch: worst", "m", ".2e"), Column("batch: cases ≤ 0.1 µm"),
         Column("batch − single solve: largest", "m", ".2e")], rows,
        note=f"uniform grid: grid=uniform, 4 cells per notch, 1 per tube, quadrature order 4 "
             f"(the previous default); cases at {' and '.join(f'{t:g}' for t in TENSIONS)} N; "
             f"times: median of {args.repeats} solves per case, then the median over the cases; "
             "refused: cases the model refuses at that load (closure, the tendon singularity, "
             "eq. 7's kink limit); batch: solve_batch(partials='interpolated') of each case "
             "alone at the default settings (literal loads fall back to the single solve)")
    if over:
        results.table(f"Cases over {args.over:g} m",
                      [Column("grid"), Column("model"), Column("case"),
                       Column("tension", "N", "g"), Column("error", "m", ".2e")], over)
    for label, (err, where) in worst_case.items():
        print(f"\nworst case of {label}: {err:.2e} m, {where}")
    results.table("Worst case of each grid",
                  [Column("grid"), Column("error", "m", ".2e"), Column("case")],
                  [[label, err, where] for label, (err, where) in worst_case.items()])
    print("\nindependent check (constrained tendon, reference grid vs shooting-segmented "
          "rtol 1e-11):")
    options = ShootingOptions(rtol=1e-11, atol=1e-14)
    checks: list[list[object]] = []
    for name in ("paper-experiment N=8", "fig3-wd-1.2 N=8", "paper-experiment N=1"):
        if name not in designs:
            continue
        design = designs[name]
        try:
            shot = solve_with("shooting-segmented", design, 20.0, options=options,
                              strict=False).tip_position
        except ModelError as exc:
            print(f"  {name}: shooting failed ({exc})")
            checks.append([name, None, f"shooting failed ({exc})"])
            continue
        grid_tip = constrained_tip(design, 20.0, REFERENCE)
        print(f"  {name} @ 20 N: |grid - shooting| = {np.linalg.norm(grid_tip - shot):.2e} m")
        checks.append([name, float(np.linalg.norm(grid_tip - shot)), ""])
    results.table(
        "Independent check at 20 N: constrained tendon, reference grid against "
        "shooting-segmented at rtol 1e-11",
        [Column("design"), Column("|grid − shooting|", "m", ".2e"), Column("note")], checks)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
