"""``tdcm calibrate``: fit Young's modulus (and other design fields) to recorded bags."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING, Any

from tdcm_ros.cli.evaluate import add_input_arguments, fail
from tdcm_ros.errors import PhysicsError, TdcmError

if TYPE_CHECKING:
    from tdcm_ros.metrics.calibration import Calibration

UNUSABLE_FIT_EXIT = PhysicsError.exit_code
"""Exit status when the fit did not converge or a parameter is not identifiable (numerics)."""


def register(subparsers: Any) -> None:
    """Add the ``calibrate`` subcommand."""
    parser = subparsers.add_parser(
        "calibrate", help="fit E (and other design fields) to bags by least squares",
        description="Least squares on the marker position residuals of every step; reports "
                    "each value with a confidence interval, Table I before and after, and warns "
                    "when a parameter is not identifiable from the data.")
    add_input_arguments(parser)
    parser.add_argument("--fit", default="E", metavar="NAME[,NAME]",
                        help="real-valued design fields to fit (default: E); start values from "
                             "--set / the preset")
    parser.add_argument("--confidence", type=float, default=0.95,
                        help="confidence level of the intervals, in (0, 1) (default: 0.95)")
    parser.set_defaults(handler=run)


def _metric(value: float | None, scale: float, unit: str) -> str:
    return "-" if value is None else f"{value * scale:.3f} {unit}"


def format_report(cal: Calibration) -> str:
    """Warnings (not identifiable, not converged) first, then fitted values with intervals,
    residuals, Table I before/after and the evaluation's warnings."""
    steps = cal.before.metrics.n_steps + cal.before.metrics.n_flagged
    lines = [f"warning: {w}" for w in cal.warnings]
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
    lines += [f"warning: {w}" for w in cal.after.warnings]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Calibrate; known errors become one line and a non-zero exit status."""
    from tdcm_ros.metrics.api import Topics, calibrate_paths
    from tdcm_ros.metrics.calibration import parse_fit
    from tdcm_ros.metrics.options import options_from_sets

    try:
        names = parse_fit(args.fit)
        options = options_from_sets(args.set)
        cal = calibrate_paths(args.bags, names, options, confidence=args.confidence,
                              topics=Topics(args.tension_topic, args.markers_topic))
    except TdcmError as error:
        return fail("calibrate", error, args.json)
    print(json.dumps(cal.to_json()) if args.json else format_report(cal))
    if cal.warnings:
        print(f"tdcm calibrate: the fit is not usable: {'; '.join(cal.warnings)}",
              file=sys.stderr)
        return UNUSABLE_FIT_EXIT
    return 0
