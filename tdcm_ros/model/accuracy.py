"""Accuracy against time for every method and accuracy knob (``tdcm bench accuracy``).

Each configuration (a registered method plus its knobs) solves every case (design x
tension); its tip error (m) is measured against a converged reference **of the model it
discretises**, and its median wall time per solve (s) in the same run:

- ``paper/closed``, ``free/closed``, ``paper/literal``: Algorithm 1 with ``REFERENCE``
  (adaptive grid, 64 cells per notch, 16 per tube, 12 Gauss points, tol 1e-13) in that
  routing/load form;
- ``constrained`` (the shooting baselines' Rucker tendon, on the offset curve everywhere):
  the moment is exactly ``R_c T``, so the reference is the exact integration of
  ``kappa = R_c T / (E I)`` on the same ``REFERENCE`` grid;
- ``constant-curvature`` and ``pseudo-rigid-body`` have no discretisation: their error is
  against the package model's (``paper/closed``) reference.

How converged each reference is: the largest tip difference to the previous refinement
(``COARSER``: 32/8 cells, 8 points). Model differences (routing, load form, constrained
tendon) are reported separately as tip differences between references, never mixed into a
configuration's error. Timings are wall-clock on a shared machine and noisy.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from time import perf_counter
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.baselines import OdeMethod, ShootingOptions, get_method, solve_with
from tdcm_ros.model.design import MM, PRESETS, Design, preset
from tdcm_ros.model.errors import ModelError
from tdcm_ros.model.grid import build_grid
from tdcm_ros.model.kinematics import integrate
from tdcm_ros.model.progress import Progress, report_progress
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS, solve
from tdcm_ros.plot_backend import load_pyplot

Array = NDArray[np.float64]

REFERENCE = SolverSettings(cells_per_notch=64, cells_per_tube=16, quad_order=12, tol=1e-13,
                           max_iter=2000)
COARSER = REFERENCE.with_overrides(cells_per_notch=32, cells_per_tube=8, quad_order=8)
#: The two grids :func:`converged_tip` extrapolates from (adaptive: 64 and 32 cells per notch).
RICHARDSON_FINE = SolverSettings(grid="adaptive", cells_per_notch=64, cells_per_tube=16,
                                 quad_order=8, tol=1e-14, max_iter=2000)
RICHARDSON_HALF = RICHARDSON_FINE.with_overrides(cells_per_notch=32, cells_per_tube=8)
PACKAGE_MODEL = "paper/closed"
SHOOTING_TENSIONS = (4.0, 20.0)
TIME_TIE = 0.9

_BASE = preset("paper-experiment")
HARD_DESIGNS: dict[str, Design] = {
    # I0 / I(notch centre) ~ 1080: very thin backbone.
    "hard-stiffness-ratio-1000": _BASE.with_overrides(w_d=0.75 * MM),
    # 0.2 mm rectangular notches between 5.8 mm tubes: narrower than a default cell.
    "hard-narrow-notch": _BASE.with_overrides(w_n=0.2 * MM, w_t=5.8 * MM, w_d=0.8 * MM,
                                              profile="rectangular"),
    # 40 notches, 50 um tubes between them.
    "hard-n40-short-tubes": _BASE.with_overrides(N=40, w_n=1.0 * MM, w_t=0.05 * MM,
                                                 w_d=1.5 * MM),
    # R_c * kappa = 0.95 at 20 N at the notch centres: close to the tendon singularity.
    "hard-near-singular": _BASE.with_overrides(w_d=0.6 * MM),
    # 64 notches (0.39 m): errors per notch and per chord add up along the body.
    "hard-n64": _BASE.with_overrides(N=64),
}


@dataclass(frozen=True)
class Config:
    """One method with its knobs; ``model`` names the model it discretises."""

    label: str
    method: str
    model: str
    settings: SolverSettings = DEFAULT_SETTINGS
    options: ShootingOptions | None = None
    max_step_per_notch: float | None = None
    default: bool = False
    tensions: tuple[float, ...] | None = None

    def knobs(self) -> dict[str, Any]:
        """The accuracy knobs that matter for this method (JSON-ready)."""
        if self.method == "algorithm1":
            s = self.settings
            return {"routing": s.routing, "loads": s.loads, "grid": s.grid,
                    "cells_per_notch": s.cells_per_notch,
                    "cells_per_tube": s.cells_per_tube, "quad_order": s.quad_order, "tol": s.tol}
        if self.options is not None:
            o = self.options
            knobs: dict[str, Any] = {"rtol": o.rtol, "ode_method": o.ode_method,
                                     "root_tol": o.root_tol}
            if self.max_step_per_notch is not None:
                knobs["max_step"] = f"{self.max_step_per_notch:g} w_n"
            return knobs
        return {}

    def run(self, design: Design, tension: float) -> tuple[Array, bool]:
        """Tip position (m) and the method's own convergence flag for one case."""
        if self.options is None:
            result = solve_with(self.method, design, tension, settings=self.settings,
                                strict=False) if self.method == "algorithm1" \
                else get_method(self.method)(design, tension, settings=self.settings)
        else:
            options = self.options
            if self.max_step_per_notch is not None:
                options = ShootingOptions(**{**asdict(options),
                                             "max_step": self.max_step_per_notch
                                             * float(np.min(design.per_notch("w_n")))})
            result = solve_with(self.method, design, tension, options=options, strict=False)
        return result.tip_position, result.converged


def _alg1(label: str, default: bool = False, **knobs: Any) -> Config:
    settings = DEFAULT_SETTINGS.with_overrides(**knobs)
    model = f"{settings.routing}/{settings.loads}"
    return Config(label=label, method="algorithm1", model=model, settings=settings,
                  default=default)


def _shoot(variant: str, rtol: float, method: OdeMethod = "RK45",
           max_step_per_notch: float | None = None) -> Config:
    label = f"shooting-{variant} rtol={rtol:g}"
    if method != "RK45":
        label += f" {method}"
    if max_step_per_notch is not None:
        label += f" max_step={max_step_per_notch:g}w_n"
    return Config(label=label, method=f"shooting-{variant}", model="constrained",
                  options=ShootingOptions(rtol=rtol, ode_method=method),
                  max_step_per_notch=max_step_per_notch, tensions=SHOOTING_TENSIONS)


def configs(quick: bool = False) -> list[Config]:
    """Every configuration of the bench (a subset with ``quick``)."""
    out = [_alg1("algorithm1 default (adaptive cpn=4 cpt=1 q=6 tol=1e-10)", default=True),
           _alg1("algorithm1 previous default (uniform cpn=4 cpt=1 q=4)", grid="uniform",
                 quad_order=4)]
    cells = (1, 2, 8) if quick else (1, 2, 8, 16, 32)
    out += [_alg1(f"algorithm1 cpn={c}", cells_per_notch=c) for c in cells]
    quads = (2,) if quick else (1, 2, 3, 4, 8)
    out += [_alg1(f"algorithm1 q={q}", quad_order=q) for q in quads]
    if not quick:
        out += [_alg1("algorithm1 cpn=2 q=4", cells_per_notch=2, quad_order=4),
                _alg1("algorithm1 cpn=8 q=8", cells_per_notch=8, quad_order=8),
                _alg1("algorithm1 cpn=16 cpt=4 q=8", cells_per_notch=16, cells_per_tube=4,
                      quad_order=8),
                _alg1("algorithm1 cpt=4", cells_per_tube=4),
                _alg1("algorithm1 uniform cpn=8 q=6", grid="uniform", cells_per_notch=8),
                _alg1("algorithm1 uniform cpn=16 cpt=4 q=8", grid="uniform",
                      cells_per_notch=16, cells_per_tube=4, quad_order=8)]
    tols = (1e-6,) if quick else (1e-4, 1e-6, 1e-8, 1e-12)
    out += [_alg1(f"algorithm1 tol={t:g}", tol=t) for t in tols]
    out += [_alg1("algorithm1 loads=literal", loads="literal"),
            _alg1("algorithm1 routing=free", routing="free")]
    if not quick:
        out += [_alg1("algorithm1 loads=literal cpn=16", loads="literal", cells_per_notch=16),
                _alg1("algorithm1 routing=free cpn=16", routing="free", cells_per_notch=16)]
    out += [Config(label="constant-curvature", method="constant-curvature",
                   model="constant-curvature"),
            Config(label="pseudo-rigid-body", method="pseudo-rigid-body",
                   model="pseudo-rigid-body")]
    rtols_seg = (1e-3, 1e-6) if quick else (1e-3, 1e-5, 1e-8)
    rtols_whole = (1e-3, 1e-6) if quick else (1e-3, 1e-6, 1e-9)
    out += [_shoot("segmented", r) for r in rtols_seg]
    out += [_shoot("whole", r) for r in rtols_whole]
    if not quick:
        out += [_shoot("whole", 1e-6, max_step_per_notch=0.5)]
    return out


def designs(quick: bool = False) -> dict[str, Design]:
    """Every preset plus the hard designs (two presets and one hard design with ``quick``)."""
    if quick:
        return {"paper-experiment": PRESETS["paper-experiment"],
                "fig2-wn-1": PRESETS["fig2-wn-1"],
                "hard-narrow-notch": HARD_DESIGNS["hard-narrow-notch"]}
    return {**PRESETS, **HARD_DESIGNS}


def tensions(quick: bool = False) -> tuple[float, ...]:
    """Tensions (N) of the bench."""
    return (4.0, 20.0) if quick else (4.0, 8.0, 12.0, 16.0, 20.0)


def constrained_tip(design: Design, tension: float, settings: SolverSettings) -> Array:
    """Exact tip (m) for the constrained tendon: ``m = R_c T`` everywhere, integrated on the grid."""
    grid = build_grid(design, settings)
    moment = np.full(grid.n_cells, design.R_c * tension)
    tip = integrate(grid, moment, moment).p[-1]
    return np.array([tip.imag, 0.0, tip.real])


def converged_tip(design: Design, tension: float, routing: str, loads: str
                  ) -> tuple[Array, float]:
    """Tip (m) of Algorithm 1 converged in the grid, and its uncertainty (m).

    Richardson extrapolation of ``RICHARDSON_FINE`` and ``RICHARDSON_HALF`` (half the cells)
    for a second-order error, ``fine + (fine - half)/3``; the uncertainty is
    ``|fine - half| / 3``, the fine grid's own estimated error. With the grid's chord terms the
    tip converges faster than second order (the moment's bow on chords is carried, not
    resolved by cells), so the correction is itself within that uncertainty.
    """
    fine, half = (solve(design, tension, settings=st.with_overrides(routing=routing, loads=loads),
                        strict=False).tip_position for st in (RICHARDSON_FINE, RICHARDSON_HALF))
    return fine + (fine - half) / 3.0, float(np.linalg.norm(fine - half)) / 3.0


def _reference_tip(model: str, design: Design, tension: float, settings: SolverSettings
                   ) -> Array:
    if model == "constrained":
        return constrained_tip(design, tension, settings)
    routing, loads = model.split("/")
    result = solve(design, tension, settings=settings.with_overrides(routing=routing, loads=loads),
                   strict=False)
    return result.tip_position


@dataclass
class Row:
    """One configuration's result over all cases: errors (m), times (s)."""

    label: str
    method: str
    model: str
    knobs: dict[str, Any]
    max_error_m: float
    median_error_m: float
    median_time_s: float
    solves: int
    not_converged: int
    failed: int
    default: bool
    on_front: bool = False
    errors_by_case: dict[str, float] = field(default_factory=dict)


@dataclass
class Report:
    """The whole bench: rows, references, model differences and the findings."""

    designs: list[str]
    tensions: list[float]
    reference: dict[str, Any]
    rows: list[Row]
    model_differences: dict[str, float]
    default_label: str
    default_reason: str
    speedup: dict[str, Any]
    shooting_findings: list[str]
    timing_note: str = ("wall-clock, perf_counter, median over all cases of the median of "
                        "`repeats` solves; 2 shared cores, expect +-30% noise")

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (SI units)."""
        return asdict(self)


def _case_key(name: str, tension: float) -> str:
    return f"{name}@{tension:g}N"


def _time_one(config: Config, design: Design, tension: float, repeats: int
              ) -> tuple[Array, bool, float]:
    times: list[float] = []
    tip, converged = np.zeros(3), False
    build_grid(design, config.settings)  # grids are cached: build outside the timing
    if repeats > 1:
        config.run(design, tension)  # warm-up
    for _ in range(repeats):
        started = perf_counter()
        tip, converged = config.run(design, tension)
        times.append(perf_counter() - started)
    return tip, converged, float(np.median(times))


def run_bench(*, quick: bool = False, progress: Progress | None = None) -> Report:
    """Run every configuration on every case; see the module docstring. ``progress``: stages
    ``reference solutions`` (one unit per model and case) and ``methods and settings`` (one
    per configuration)."""
    cases = [(name, d, t) for name, d in designs(quick).items() for t in tensions(quick)]
    models = {"paper/closed", "free/closed", "paper/literal", "constrained"}
    refs: dict[tuple[str, str], Array] = {}
    ref_spread: dict[str, float] = {}
    references = len(models) * len(cases)
    for index, model in enumerate(sorted(models)):
        spread = 0.0
        report_progress(progress, "reference solutions", index * len(cases), references)
        for name, design, t in cases:
            fine = _reference_tip(model, design, t, REFERENCE)
            coarse = _reference_tip(model, design, t, COARSER)
            refs[(model, _case_key(name, t))] = fine
            spread = max(spread, float(np.linalg.norm(fine - coarse)))
        ref_spread[model] = spread
    model_diff = {
        f"{model} vs {PACKAGE_MODEL}": max(
            float(np.linalg.norm(refs[(model, _case_key(n, t))]
                                 - refs[(PACKAGE_MODEL, _case_key(n, t))]))
            for n, _, t in cases)
        for model in sorted(models - {PACKAGE_MODEL})}

    report_progress(progress, "reference solutions", references, references)
    rows = []
    chosen = configs(quick)
    for index, config in enumerate(chosen):
        report_progress(progress, "methods and settings", index, len(chosen))
        ref_model = config.model if config.model in models else PACKAGE_MODEL
        repeats = 1 if config.options is not None else 5
        errors: dict[str, float] = {}
        times: list[float] = []
        not_converged = failed = 0
        for name, design, t in cases:
            if config.tensions is not None and t not in config.tensions:
                continue
            key = _case_key(name, t)
            try:
                tip, converged, elapsed = _time_one(config, design, t, repeats)
            except ModelError:
                failed += 1
                continue
            not_converged += not converged
            errors[key] = float(np.linalg.norm(tip - refs[(ref_model, key)]))
            times.append(elapsed)
        values = list(errors.values())
        rows.append(Row(label=config.label, method=config.method, model=config.model,
                        knobs=config.knobs(),
                        max_error_m=max(values) if values else math.inf,
                        median_error_m=float(np.median(values)) if values else math.inf,
                        median_time_s=float(np.median(times)) if times else math.inf,
                        solves=len(values), not_converged=not_converged, failed=failed,
                        default=config.default, errors_by_case=errors))
    report_progress(progress, "methods and settings", len(chosen), len(chosen))
    _mark_front(rows)
    default = next(r for r in rows if r.default)
    return Report(designs=[n for n in designs(quick)], tensions=list(tensions(quick)),
                  reference={"settings": REFERENCE.to_dict(), "coarser": COARSER.to_dict(),
                             "max_tip_change_to_coarser_m": ref_spread},
                  rows=rows, model_differences=model_diff, default_label=default.label,
                  default_reason=_default_reason(rows, default),
                  speedup=_speedup(rows, default), shooting_findings=_shooting_findings(rows))


def _dominates(other: Row, row: Row) -> bool:
    """``other`` is strictly more accurate and no slower, or as accurate and clearly faster
    (by more than the timing noise: ``TIME_TIE``)."""
    if other is row or other.failed:
        return False
    if other.max_error_m < row.max_error_m and other.median_time_s <= row.median_time_s:
        return True
    return other.max_error_m <= row.max_error_m and \
        other.median_time_s < TIME_TIE * row.median_time_s


def _mark_front(rows: Sequence[Row]) -> None:
    """Pareto front on (median time, worst error); a failing configuration is never on it."""
    for row in rows:
        row.on_front = row.failed == 0 and not any(_dominates(o, row) for o in rows)


def _default_reason(rows: Sequence[Row], default: Row) -> str:
    faster = [r for r in rows if r.median_time_s < default.median_time_s and r.failed == 0]
    better = [r for r in rows if r.max_error_m < default.max_error_m and r.failed == 0]
    best_faster = min(faster, key=lambda r: r.max_error_m, default=None)
    fastest_better = min(better, key=lambda r: r.median_time_s, default=None)
    parts = [f"default: worst tip error {default.max_error_m:.2e} m at "
             f"{default.median_time_s * 1e3:.2f} ms per solve; "
             + ("on the measured Pareto front" if default.on_front else
                "NOT on the measured front in this run (timing noise or a better setting)")]
    if best_faster is not None:
        parts.append(f"the best faster setting ({best_faster.label}) errs "
                     f"{best_faster.max_error_m:.2e} m")
    if fastest_better is not None:
        parts.append(f"the fastest more accurate one ({fastest_better.label}) costs "
                     f"{fastest_better.median_time_s / default.median_time_s:.1f}x the time "
                     f"for {fastest_better.max_error_m:.2e} m")
    parts.append("1 um is well below the 0.5 mm RMSE of the paper's experiment")
    return "; ".join(parts)


def _speedup(rows: Sequence[Row], default: Row) -> dict[str, Any]:
    shooting = [r for r in rows if r.method.startswith("shooting") and r.failed == 0]
    good = [r for r in shooting if r.max_error_m <= default.max_error_m]
    if good:
        match = min(good, key=lambda r: r.median_time_s)
        return {"shooting": match.label, "shooting_error_m": match.max_error_m,
                "shooting_time_s": match.median_time_s, "default_time_s": default.median_time_s,
                "speedup": match.median_time_s / default.median_time_s}
    best = min(shooting, key=lambda r: r.max_error_m, default=None)
    return {"shooting": None, "note": "no shooting configuration reached the default's accuracy",
            "most_accurate_shooting": best.label if best else None,
            "its_error_m": best.max_error_m if best else None,
            "its_time_s": best.median_time_s if best else None,
            "default_time_s": default.median_time_s}


def _shooting_findings(rows: Sequence[Row]) -> list[str]:
    """Where shooting fails or silently returns a wrong shape, with numbers."""
    out = []
    whole = sorted((r for r in rows if r.method == "shooting-whole"
                    and "rtol" in r.knobs and "max_step" not in r.knobs),
                   key=lambda r: -r.knobs["rtol"])
    if whole:
        trend = ", ".join(f"rtol {r.knobs['rtol']:g}: {r.max_error_m * 1e3:.3g} mm" for r in whole)
        out.append(f"shooting-whole worst tip error vs rtol ({trend}): it does not shrink as "
                   "rtol tightens, because adaptive steps (growing up to 10x per step in the "
                   "smooth tubes) step across whole notches and the error estimate misses it")
        for r in whole:
            silent = [k for k, e in r.errors_by_case.items() if e > 1e-4]
            if silent:
                out.append(f"shooting-whole rtol {r.knobs['rtol']:g}: {len(silent)} of "
                           f"{r.solves} solves off by > 0.1 mm while the root finder reported "
                           f"{r.solves - r.not_converged} converged (silently wrong shapes), "
                           f"e.g. {silent[0]} {r.errors_by_case[silent[0]] * 1e3:.3g} mm")
    seg = sorted((r for r in rows if r.method == "shooting-segmented"
                  and r.knobs.get("ode_method") == "RK45"), key=lambda r: -r.knobs["rtol"])
    if seg:
        trend = ", ".join(f"rtol {r.knobs['rtol']:g}: {r.max_error_m:.2e} m" for r in seg)
        out.append(f"shooting-segmented (restarts at every l_i, r_i) converges with rtol: {trend}")
    return out


def format_table(report: Report) -> str:
    """The report as plain text (errors in m, times in ms)."""
    lines = [f"designs: {', '.join(report.designs)}",
             f"tensions (N): {', '.join(f'{t:g}' for t in report.tensions)}",
             "reference: Algorithm 1, adaptive grid, cells_per_notch=64, cells_per_tube=16, "
             "quad_order=12, tol=1e-13; max tip change vs 32/8 cells, q=8: "
             + ", ".join(f"{k} {v:.1e} m"
                         for k, v in report.reference["max_tip_change_to_coarser_m"].items()),
             "",
             "shooting runs at " + ", ".join(f"{t:g}" for t in SHOOTING_TENSIONS)
             + " N only (time budget); '!conv': the method's own flag said not converged",
             "",
             (f"{'configuration':<48} {'model':<18} {'max err (m)':>11} {'med err (m)':>11} "
              f"{'med ms':>9} {'solves':>6} {'!conv':>5} {'fail':>4} front")]
    for r in sorted(report.rows, key=lambda r: r.median_time_s):
        mark = ("*" if r.on_front else "") + (" default" if r.default else "")
        lines.append(f"{r.label:<48} {r.model:<18} {r.max_error_m:>11.2e} "
                     f"{r.median_error_m:>11.2e} {r.median_time_s * 1e3:>9.3f} {r.solves:>6} "
                     f"{r.not_converged:>5} {r.failed:>4} {mark}")
    lines += ["", ("model differences (tip, between converged references; not discretisation "
                   "error):")]
    lines += [f"  {k}: {v:.2e} m" for k, v in report.model_differences.items()]
    lines += ["", report.default_reason, "", "speed-up of the default over shooting at equal "
              "or better accuracy: " + _speedup_text(report.speedup), "",
              "where shooting fails:"]
    lines += [f"  - {f}" for f in report.shooting_findings]
    lines += ["", f"timing: {report.timing_note}"]
    return "\n".join(lines)


def format_markdown(report: Report) -> str:
    """The configurations as a Markdown table (errors in m, times in ms), fastest first."""
    header = ("| configuration | model | worst tip error (m) | median error (m) | median ms | "
              "Pareto front |")
    lines = [header, "|---|---|---|---|---|---|"]
    for r in sorted(report.rows, key=lambda r: r.median_time_s):
        label = f"**{r.label}**" if r.default else r.label
        lines.append(f"| {label} | {r.model} | {r.max_error_m:.2e} | {r.median_error_m:.2e} | "
                     f"{r.median_time_s * 1e3:.3f} | {'yes' if r.on_front else ''} |")
    return "\n".join(lines)


def _speedup_text(speedup: dict[str, Any]) -> str:
    if speedup.get("shooting"):
        return (f"{speedup['speedup']:.0f}x ({speedup['shooting']}: "
                f"{speedup['shooting_error_m']:.2e} m in {speedup['shooting_time_s'] * 1e3:.1f} "
                f"ms vs {speedup['default_time_s'] * 1e3:.2f} ms)")
    return str(speedup.get("note"))


def plot_pareto(report: Report, path: str) -> None:
    """Error vs time (log-log) of every configuration to a PNG; the front is joined."""
    plt = load_pyplot("--plot", path)
    fig, ax = plt.subplots(figsize=(9, 6))
    styles = {"algorithm1": ("o", "C0"), "constant-curvature": ("s", "C2"),
              "pseudo-rigid-body": ("D", "C4"), "shooting-segmented": ("^", "C1"),
              "shooting-whole": ("v", "C3")}
    floor = 1e-12
    for method, (marker, color) in styles.items():
        rows = [r for r in report.rows if r.method == method and r.solves]
        if rows:
            ax.scatter([r.median_time_s for r in rows],
                       [max(r.max_error_m, floor) for r in rows], marker=marker, color=color,
                       label=method, s=40, zorder=3)
    front = sorted((r for r in report.rows if r.on_front), key=lambda r: r.median_time_s)
    ax.step([r.median_time_s for r in front], [max(r.max_error_m, floor) for r in front],
            where="post", color="k", lw=1, alpha=0.6, label="Pareto front")
    for r in report.rows:
        if r.default:
            ax.annotate("default", (r.median_time_s, max(r.max_error_m, floor)),
                        xytext=(8, 8), textcoords="offset points", fontsize=9)
            ax.scatter([r.median_time_s], [max(r.max_error_m, floor)], s=160,
                       facecolors="none", edgecolors="k", zorder=4,
                       label="the package's default setting")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("median time per solve (s)")
    ax.set_ylabel("worst tip error vs converged reference (m)")
    ax.set_title(f"Accuracy vs time: {len(report.designs)} designs x "
                 f"{len(report.tensions)} tensions")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
