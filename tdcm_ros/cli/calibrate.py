"""``tdcm calibrate``: fit Young's modulus (other design fields, the tendon's friction) to
recorded bags."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from tdcm_ros.cli.evaluate import add_input_arguments, design_sets, fail, input_topics
from tdcm_ros.cli.progress import ProgressBars
from tdcm_ros.errors import InputError, PhysicsError, TdcmError

UNUSABLE_FIT_EXIT = PhysicsError.exit_code
"""Exit status when the fit did not converge or a parameter is not identifiable (numerics)."""
EXIT_MEANINGS = {"calibrate": {UNUSABLE_FIT_EXIT: "the fit did not converge or a parameter is "
                                                  "not identifiable; the table is still printed"}}
"""What ``calibrate`` means by an exit status (its ``--help`` epilog)."""


def register(subparsers: Any) -> None:
    """Add the ``calibrate`` subcommand."""
    parser = subparsers.add_parser(
        "calibrate", help="fit E (other design fields, friction mu) to bags by least squares",
        description="Least squares on the marker position residuals of every step (the model "
                    "at the step's mean tension, one per tendon; with friction the steps in "
                    "the order they happened); reports each value with a confidence interval, "
                    "Table I before and after, and warns when a parameter is not identifiable "
                    "from the data. --out writes the fitted model (body file with friction and "
                    "the parameters' covariance) for model_node, evaluate and solve.",
        epilog="examples:\n"
               "  tdcm calibrate bags/paper_experiment\n"
               "  tdcm calibrate run.mcap --fit E --confidence 0.9 --json\n"
               "  tdcm calibrate friction_demo/bag --fit E,mu --hold-out 1 --out model.yaml\n"
               "  tdcm calibrate pair_run --design config/bodies/antagonistic_pair.yaml")
    add_input_arguments(parser)
    parser.add_argument("--fit", default="E", metavar="NAME[,NAME]",
                        help="real-valued design fields and mu (the tendon's capstan friction) "
                             "to fit (default: E); start values from --design / --set (mu: "
                             "friction.mu, default 0)")
    parser.add_argument("--confidence", type=float, default=0.95,
                        help="confidence level of the intervals, in (0, 1) (default: 0.95)")
    parser.add_argument("--hold-out", type=int, default=0, metavar="TRIALS",
                        help="leave each bag's last TRIALS trials out of the fit and report them "
                             "with the fitted model: Table I and how many markers fall in the "
                             "95%% band (default: 0)")
    parser.add_argument("--out", default=None, metavar="MODEL.yaml",
                        help="write the fitted model: the body file with friction and the "
                             "parameters' covariance (design.file of model_node, --design of "
                             "evaluate)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Calibrate; known errors become one line and a non-zero exit status."""
    from tdcm_ros.metrics import format_calibration, options_from_sets
    from tdcm_ros.metrics.api import calibrate_paths
    from tdcm_ros.metrics.calibration import parse_fit

    try:
        names = parse_fit(args.fit)
        options = options_from_sets(design_sets(args))
        with ProgressBars.of(args) as bars:
            cal = calibrate_paths(args.bags, names, options, confidence=args.confidence,
                                  topics=input_topics(args), hold_out=args.hold_out,
                                  progress=bars)
        if args.out is not None:
            _write(Path(args.out), cal.model.text())
    except TdcmError as error:
        return fail("calibrate", error, args.json)
    if cal.warnings:  # before the table: on a terminal it is read first, not scrolled past
        print(f"tdcm calibrate: the fit is not usable: {'; '.join(cal.warnings)}",
              file=sys.stderr, flush=True)
    print(json.dumps(cal.to_json()) if args.json else format_calibration(cal))
    return UNUSABLE_FIT_EXIT if cal.warnings else 0


def _write(path: Path, text: str) -> None:
    """Write the model file ``text`` to ``path`` whole (a reader sees the old file or the new
    one, never part of it); a path that cannot be written is an :class:`InputError` naming
    ``--out``."""
    partial = path.with_name(f".{path.name}.partial")
    try:
        partial.write_text(text, encoding="utf-8")
        partial.replace(path)
    except OSError as error:
        raise InputError(f"--out = {str(path)!r} cannot be written: {error}", parameter="--out",
                         value=str(path), allowed="a writable file path") from error
    print(f"tdcm calibrate: wrote the fitted model to {path}", file=sys.stderr)
