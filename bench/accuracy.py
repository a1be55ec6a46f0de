"""Accuracy vs time of every method and setting; same as ``tdcm bench accuracy``.

Usage: ``python bench/accuracy.py [--json] [--markdown] [--plot FILE.png] [--quick]
[--results FILE]``. ``--results FILE`` (this script's only option beyond the command's) also
writes the figures as tables to a results file (``bench/results.py``): every configuration's
errors (m) and median time (ms), the model differences, the reference's own spread and the
findings.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from results import BenchResults, Column, add_results_argument

from tdcm_ros.cli.bench import measure_accuracy, print_accuracy
from tdcm_ros.cli.main import build_parser
from tdcm_ros.cli.main import main as tdcm_main
from tdcm_ros.errors import TdcmError
from tdcm_ros.model.accuracy import Report, _speedup_text


def subparser(parser: argparse.ArgumentParser, *names: str) -> argparse.ArgumentParser:
    """The parser of the subcommand ``names`` (e.g. ``bench``, ``accuracy``) under ``parser``."""
    for name in names:
        action = next(a for a in parser._actions  # argparse keeps subparsers only there
                      if isinstance(a, argparse._SubParsersAction))
        parser = action.choices[name]
    return parser


def record(report: Report, results: BenchResults) -> None:
    """The report's figures as tables of ``results``."""
    results.table(
        "Accuracy against time per solve, fastest first",
        [Column("configuration"), Column("model"), Column("worst tip error", "m", ".2e"),
         Column("median error", "m", ".2e"), Column("median time", "ms", ".3f"),
         Column("Pareto front"), Column("solves"), Column("not converged"), Column("failed")],
        [[r.label, r.model, r.max_error_m, r.median_error_m, r.median_time_s * 1e3,
          "yes" if r.on_front else "", r.solves, r.not_converged, r.failed]
         for r in sorted(report.rows, key=lambda r: r.median_time_s)],
        note=f"designs: {', '.join(report.designs)}; tensions "
             f"{', '.join(f'{t:g}' for t in report.tensions)} N; default: "
             f"{report.default_label}; timing: {report.timing_note}. Not converged: the "
             "method's own flag said so.")
    spread = report.reference["max_tip_change_to_coarser_m"]
    results.table(
        "Reference: largest tip change against a coarser reference",
        [Column("model"), Column("tip change", "m", ".1e")], list(spread.items()),
        note="reference: Algorithm 1, adaptive grid, 64 cells per notch, 16 per tube, "
             "quadrature order 12, tol 1e-13; coarser: 32 and 8 cells, order 8")
    results.table(
        "Model differences: tip, between converged references (not discretisation error)",
        [Column("models"), Column("largest tip difference", "m", ".2e")],
        list(report.model_differences.items()))
    results.table(
        "Findings", [Column("finding"), Column("text")],
        [["the default", report.default_reason],
         ["speed-up of the default over shooting at equal or better accuracy",
          _speedup_text(report.speedup)],
         *(["where shooting fails", finding] for finding in report.shooting_findings)])


def main(argv: Sequence[str]) -> int:
    """``tdcm bench accuracy`` with ``argv``; with ``--results FILE`` also the results file."""
    parser = build_parser(["bench", "accuracy"])
    add_results_argument(subparser(parser, "bench", "accuracy"), "accuracy")
    args = parser.parse_args(["bench", "accuracy", *argv])  # -h shows --results too
    if args.results is None:
        return tdcm_main(["bench", "accuracy", *argv])
    results = BenchResults("accuracy")
    try:
        report = measure_accuracy(args)
    except TdcmError as error:
        print(f"tdcm bench: {error}", file=sys.stderr)
        return error.exit_code
    print_accuracy(args, report)
    record(report, results)
    results.write(args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
