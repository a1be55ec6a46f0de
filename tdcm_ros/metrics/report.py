"""Text reports of an evaluation and a calibration (lengths printed in mm, the rest SI)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from tdcm_ros.metrics.calibration import Calibration
    from tdcm_ros.metrics.evaluation import Evaluation
    from tdcm_ros.metrics.options import EvaluateOptions


def _mm(value: float | None, digits: int = 3) -> str:
    return "-" if value is None else f"{value * 1e3:.{digits}f}"


def format_evaluation(ev: Evaluation) -> str:
    """The text report: setup, per-step table, Table I and warnings."""
    opts: EvaluateOptions = ev.options
    d = opts.design
    w_d = ", ".join(f"{w * 1e3:.3f}" for w in dict.fromkeys(d.per_notch("w_d").tolist()))
    lines = [(f"design: L = {d.length * 1e3:.3f} mm, w_d = {w_d} mm, "
             f"E = {d.E:.4g} Pa; deflection from the {opts.deflection_axis} axis")]
    for source, reg in zip(ev.sources, ev.registrations, strict=True):
        how = {"tf_static": "from /tf_static in the bag", "given": "given",
               "estimated": f"estimated from the markers (axis-fit residual "
                            f"{reg.residual_m * 1e3:.3f} mm)"}.get(reg.method, reg.method)
        lines.append(f"registration mocap -> tdcm_base of {source}: {how}")
    lines.append("")
    tendons = [t.name for t in d.tendon_list()]
    # one tension column per tendon, headed by its name where the body has several
    heads = ["tension N"] if len(tendons) == 1 else [f"{name} N" for name in tendons]
    widths = [max(9, len(head)) for head in heads]
    lines.append(f"{'trial':>5} {'phase':>9} "
                 + "".join(f"{head:>{w}} " for head, w in zip(heads, widths, strict=True))
                 + f"{'frames':>6} {'meas mm':>8} {'pred mm':>8} {'err mm':>7} {'shape mm':>8}"
                 "  note")
    for r in ev.records:
        measured, predicted = r.measured_deflection_m, r.predicted_deflection_m
        err = predicted - measured if predicted is not None and measured is not None else None
        tensions = "".join(f"{value:>{w}.3f} " for value, w in zip(
            r.tensions_n.values(), widths, strict=True))
        lines.append(f"{r.trial:>5} {r.phase:>9} {tensions}{r.frames:>6} "
                     f"{_mm(r.measured_deflection_m):>8} {_mm(r.predicted_deflection_m):>8} "
                     f"{_mm(err):>7} {_mm(r.shape_error_m):>8}  {r.note}")
    m, unloading = ev.metrics, ev.unloading
    lines += ["", (f"Table I over {m.n_trials} trials, {m.n_steps} loading steps"
                  f"{f' ({m.n_flagged} flagged steps left out)' if m.n_flagged else ''}:"),
              (f"  MAPE            {'-' if m.mape_pct is None else f'{m.mape_pct:.2f} %'}"
              f"  ({m.mape_excluded} steps below {m.mape_threshold_m * 1e3:g} mm left out)"),
              f"  RMSE            {_mm(m.rmse_m)} mm",
              f"  MAE             {_mm(m.mae_m)} mm",
              f"  Shape error     {_mm(m.shape_error_m)} mm",
              (f"  Deflection mean {_mm(m.deflection_mean_m, 2)} mm "
              f"(model {_mm(m.predicted_deflection_mean_m, 2)} mm)")]
    if unloading is not None:
        lines += [(f"Unloading steps (not in Table I; hysteresis): {unloading.n_steps} steps, "
                   f"MAE {_mm(unloading.mae_m)} mm, RMSE {_mm(unloading.rmse_m)} mm")]
        paired = [h for h in ev.hysteresis_m() if h is not None]
        if paired:
            lines.append(f"  measured unloading - loading deflection at the same level: mean "
                         f"{_mm(sum(paired) / len(paired))} mm, largest "
                         f"{_mm(max(paired, key=abs))} mm over {len(paired)} steps")
    if any(ev.occluded.values()):
        lines.append("occluded marker positions left out (NaN or exactly 0): " + ", ".join(
            f"{label} {count}" for label, count in ev.occluded.items()))
    if (band := ev.band) is not None:
        lines.append(band_line(*band))
    lines += [f"warning: {w}" for w in ev.warnings]
    return "\n".join(lines)


def band_line(inside: int, markers: int) -> str:
    """How many measured markers fall in their predicted 95 % band."""
    share = f"{inside / markers:.1%}" if markers else "-"
    return (f"95 % band (the fit's covariance and residual): {inside} of {markers} measured "
            f"markers inside ({share})")


def _metric(value: float | None, scale: float, unit: str) -> str:
    return "-" if value is None else f"{value * scale:.3f} {unit}"


def format_calibration(cal: Calibration) -> str:
    """Warnings first (not identifiable, not converged, then the evaluation's), then fitted
    values with intervals, residuals and Table I before/after."""
    steps = len(cal.before.records)  # loading and unloading steps are fitted alike
    lines = [f"warning: {w}" for w in (*cal.warnings, *cal.after.warnings)]
    lines += [f"note: {n}" for n in cal.notes]
    lines += [(f"least squares over {steps} steps ({cal.n_residuals} marker coordinates), "
             f"residual RMS {cal.residual_rms_m * 1e3:.4f} mm")]
    level = f"{cal.confidence:.0%}"
    for p in cal.parameters:
        lines.append(f"  {p.name} = {p.value:.5g} {p.unit}  ({level} interval "
                     f"{p.ci_low:.5g} .. {p.ci_high:.5g}; start {p.initial:.5g})")
    b, a = cal.before.metrics, cal.after.metrics
    rows = [("MAPE", b.mape_pct, a.mape_pct, 1.0, "%"), ("RMSE", b.rmse_m, a.rmse_m, 1e3, "mm"),
            ("MAE", b.mae_m, a.mae_m, 1e3, "mm"),
            ("Shape error", b.shape_error_m, a.shape_error_m, 1e3, "mm"),
            ("Deflection mean", b.deflection_mean_m, a.deflection_mean_m, 1e3, "mm"),
            ("  model", b.predicted_deflection_mean_m, a.predicted_deflection_mean_m, 1e3, "mm")]
    lines += ["", f"{'Table I':<16} {'before':>12} {'after':>12}"]
    lines += [f"{name:<16} {_metric(x, k, u):>12} {_metric(y, k, u):>12}"
              for name, x, y, k, u in rows]
    if (band := cal.after.band) is not None:
        lines += ["", f"fitted steps: {band_line(*band)}"]
    if (held := cal.held_out) is not None:
        h = held.metrics
        trials = f"{h.n_trials} trial{'' if h.n_trials == 1 else 's'}"
        lines += ["", (f"held out ({trials}, {len(held.records)} steps, not "
                       f"fitted): MAPE {_metric(h.mape_pct, 1.0, '%')}, RMSE "
                       f"{_metric(h.rmse_m, 1e3, 'mm')}, shape error "
                       f"{_metric(h.shape_error_m, 1e3, 'mm')}")]
        if (band := held.band) is not None:
            lines.append(f"held out: {band_line(*band)}")
    return "\n".join(lines)
