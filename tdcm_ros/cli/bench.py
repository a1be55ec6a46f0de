"""``tdcm bench accuracy``: tip error against time for every method and accuracy knob."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING, Any

from tdcm_ros.cli.progress import ProgressBars, add_quiet_argument

if TYPE_CHECKING:
    from tdcm_ros.model.accuracy import Report


def register(subparsers: Any) -> None:
    """Add the ``bench`` subcommand with its ``accuracy`` benchmark."""
    parser = subparsers.add_parser(
        "bench", help="benchmarks that print measured figures",
        description="Benchmarks that print measured figures (the timing scripts behind the "
                    "docs' numbers are under bench/ in the source tree).",
        epilog="examples:\n"
               "  tdcm bench accuracy --quick\n"
               "  tdcm bench accuracy --markdown --plot accuracy_pareto.png")
    benches = parser.add_subparsers(dest="bench", required=True, metavar="BENCH")
    accuracy = benches.add_parser(
        "accuracy", help="tip error vs time per solve for every method and setting",
        description="Tip error against a converged reference and median time per solve, for "
                    "Algorithm 1's settings and the baselines, on every preset and hard "
                    "designs at 4-20 N (SI units).",
        epilog="examples:\n"
               "  tdcm bench accuracy --quick               # ~10 s, a subset\n"
               "  tdcm bench accuracy --json -q > accuracy.json")
    accuracy.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    accuracy.add_argument("--markdown", action="store_true",
                          help="also print the table as Markdown (the docs'), first")
    accuracy.add_argument("--plot", metavar="FILE", help="write the Pareto plot to a .png, .pdf "
                          "or .svg file in an existing folder")
    accuracy.add_argument("--quick", action="store_true",
                          help="a small subset (3 designs, 2 tensions, fewer knobs) for tests")
    add_quiet_argument(accuracy)
    accuracy.set_defaults(handler=run_accuracy)


def run_accuracy(args: argparse.Namespace) -> int:
    """Run the accuracy bench; the table (or JSON) on stdout, progress on stderr."""
    print_accuracy(args, measure_accuracy(args))
    return 0


def measure_accuracy(args: argparse.Namespace) -> Report:
    """The accuracy bench's report for ``args`` (progress on stderr; the plot written when
    ``args.plot`` names a file). bench/accuracy.py also records it in a results file."""
    from tdcm_ros.figures import plot_file
    from tdcm_ros.model.accuracy import plot_pareto, run_bench

    if args.plot:
        plot_file("--plot", args.plot)  # before the bench: a bad path fails at once
    with ProgressBars.of(args) as bars:
        report = run_bench(quick=args.quick, progress=bars)
    if args.plot:
        plot_pareto(report, args.plot)
    return report


def print_accuracy(args: argparse.Namespace, report: Report) -> None:
    """Print ``report`` as ``args`` ask: JSON, or the table (after the Markdown one)."""
    from tdcm_ros.model.accuracy import format_markdown, format_table

    if args.json:
        print(json.dumps(report.to_json(), default=float))
    else:
        if args.markdown:
            print(format_markdown(report) + "\n")
        print(format_table(report))
        if args.plot:
            print(f"Pareto plot written to {args.plot}")
