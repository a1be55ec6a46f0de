"""``tdcm evaluate``: Table I metrics of recorded bags against the model re-run at each step."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING, Any

from tdcm_ros.errors import TdcmError

if TYPE_CHECKING:
    from tdcm_ros.metrics.evaluation import Evaluation
    from tdcm_ros.metrics.options import EvaluateOptions

SET_HELP = ("override in SI units: a design field (E=1.2e9, w_d=0.0014) or design.preset=NAME, "
            "steps.tolerance_n, steps.min_hold_s, steps.settle_s, steps.zero_n, "
            "markers.arc_lengths=0.015,0.033,0.053, markers.labels=m1,m2,m3, "
            "markers.ball_radius, markers.side_deg, align.tolerance_s, mape_threshold_m, "
            "stations, deflection_axis=marker|body, solver.<setting>")


def add_input_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments shared by ``evaluate`` and ``calibrate``."""
    parser.add_argument("bags", nargs="+", metavar="BAG",
                        help="rosbag2 folder or .mcap file (several: trials numbered on)")
    parser.add_argument("--tension-topic", default="tension",
                        help="geometry_msgs/msg/WrenchStamped topic (default: tension)")
    parser.add_argument("--markers-topic", default="markers",
                        help="mocap4r2_msgs/msg/Markers topic (default: markers)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help=SET_HELP)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def register(subparsers: Any) -> None:
    """Add the ``evaluate`` subcommand."""
    parser = subparsers.add_parser(
        "evaluate", help="Table I metrics of bags against the model",
        description="Detect tension steps in the bags, average the markers per step and compare "
                    "them with the model at each step's mean tension (MAPE, RMSE, MAE, shape "
                    "error, deflection mean).")
    add_input_arguments(parser)
    parser.add_argument("--plots", metavar="DIR",
                        help="write shapes.png and error_vs_tension.png into DIR (created if "
                             "missing; its parent must exist; needs matplotlib)")
    parser.set_defaults(handler=run)


def _mm(value: float | None, digits: int = 3) -> str:
    return "-" if value is None else f"{value * 1e3:.{digits}f}"


def format_report(ev: Evaluation) -> str:
    """The text report: setup, per-step table, Table I and warnings."""
    opts: EvaluateOptions = ev.options
    d = opts.design
    lines = [(f"design: L = {d.length * 1e3:.3f} mm, w_d = {d.w_d * 1e3:.3f} mm, "
             f"E = {d.E:.4g} Pa; deflection from the {opts.deflection_axis} axis")]
    for source, reg in zip(ev.sources, ev.registrations, strict=True):
        how = {"tf_static": "from /tf_static in the bag", "given": "given",
               "estimated": f"estimated from the markers (axis-fit residual "
                            f"{reg.residual_m * 1e3:.3f} mm)"}.get(reg.method, reg.method)
        lines.append(f"registration mocap -> tdcm_base of {source}: {how}")
    lines.append("")
    lines.append(f"{'trial':>5} {'tension N':>9} {'frames':>6} {'meas mm':>8} {'pred mm':>8} "
                 f"{'err mm':>7} {'shape mm':>8}  note")
    for r in ev.records:
        measured, predicted = r.measured_deflection_m, r.predicted_deflection_m
        err = predicted - measured if predicted is not None and measured is not None else None
        lines.append(f"{r.trial:>5} {r.tension_n:>9.3f} {r.frames:>6} "
                     f"{_mm(r.measured_deflection_m):>8} {_mm(r.predicted_deflection_m):>8} "
                     f"{_mm(err):>7} {_mm(r.shape_error_m):>8}  {r.note}")
    m = ev.metrics
    lines += ["", (f"Table I over {m.n_trials} trials, {m.n_steps} steps"
                  f"{f' ({m.n_flagged} flagged steps left out)' if m.n_flagged else ''}:"),
              (f"  MAPE            {'-' if m.mape_pct is None else f'{m.mape_pct:.2f} %'}"
              f"  ({m.mape_excluded} steps below {m.mape_threshold_m * 1e3:g} mm left out)"),
              f"  RMSE            {_mm(m.rmse_m)} mm",
              f"  MAE             {_mm(m.mae_m)} mm",
              f"  Shape error     {_mm(m.shape_error_m)} mm",
              (f"  Deflection mean {_mm(m.deflection_mean_m, 2)} mm "
              f"(model {_mm(m.predicted_deflection_mean_m, 2)} mm)")]
    if any(ev.occluded.values()):
        lines.append("occluded marker positions left out (NaN or exactly 0): " + ", ".join(
            f"{label} {count}" for label, count in ev.occluded.items()))
    lines += [f"warning: {w}" for w in ev.warnings]
    return "\n".join(lines)


def fail(command: str, error: TdcmError, as_json: bool) -> int:
    """Report a known error in one line (and as JSON on stdout with ``--json``)."""
    if as_json:
        print(json.dumps({"error": {"kind": error.kind, "message": str(error)}}))
    print(f"tdcm {command}: {error}", file=sys.stderr)
    return error.exit_code


def run(args: argparse.Namespace) -> int:
    """Evaluate; known errors become one line and a non-zero exit status."""
    from tdcm_ros.metrics.api import Topics, evaluate_paths
    from tdcm_ros.metrics.options import options_from_sets

    try:
        options = options_from_sets(args.set)
        ev = evaluate_paths(args.bags, options,
                            topics=Topics(args.tension_topic, args.markers_topic))
        plots = []
        if args.plots:
            from tdcm_ros.metrics.plots import write_plots

            plots = write_plots(ev, args.plots)
    except TdcmError as error:
        return fail("evaluate", error, args.json)
    if args.json:
        print(json.dumps(ev.to_json()))
    else:
        print(format_report(ev))
        for path in plots:
            print(f"plot written to {path}")
    return 0
