"""``tdcm figures``: the paper's Figs. 2 and 3 and a feasibility map, as PNG files."""

from __future__ import annotations

import argparse
from time import perf_counter
from typing import Any

from tdcm_ros.cli.progress import ProgressBars, add_quiet_argument

DEFAULT_OUT = "tdcm_figures"
"""Output folder when ``--out`` is not given (in the working directory)."""


def register(subparsers: Any) -> None:
    """Add the ``figures`` subcommand."""
    parser = subparsers.add_parser(
        "figures", help="reproduce the paper's Figs. 2-3 and a feasibility map as PNG",
        description="Write fig2.png, fig3.png and feasibility.png: midlines, curvature and the "
                    "design space of the paper's simulation designs, and where designs are "
                    "feasible (needs matplotlib: pip install 'tdcm_ros[plot]').",
        epilog="examples:\n"
               "  tdcm figures                              # into ./tdcm_figures\n"
               "  tdcm figures --out figs --points 81 --dpi 200 -q")
    parser.add_argument("--out", default=DEFAULT_OUT, metavar="DIR",
                        help=f"output folder (default: {DEFAULT_OUT}; created if missing, its "
                             "parent must exist)")
    parser.add_argument("--points", type=int, default=41,
                        help="grid points per sweep axis (default: 41)")
    parser.add_argument("--dpi", type=int, default=130, help="PNG resolution (default: 130)")
    add_quiet_argument(parser)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Write the figures and list them; typed errors propagate to ``tdcm``'s handler."""
    from tdcm_ros.figures import write_figures

    started = perf_counter()
    with ProgressBars.of(args) as bars:
        paths = write_figures(args.out, points=args.points, dpi=args.dpi, progress=bars)
    for path in paths:
        print(path)
    print(f"{len(paths)} figures in {perf_counter() - started:.1f} s")
    return 0
