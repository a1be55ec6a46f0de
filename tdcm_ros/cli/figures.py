"""``tdcm figures``: the paper's Figs. 2 and 3 and a feasibility map, as PNG files."""

from __future__ import annotations

import argparse
from time import perf_counter
from typing import Any


def register(subparsers: Any) -> None:
    """Add the ``figures`` subcommand."""
    parser = subparsers.add_parser(
        "figures", help="reproduce the paper's Figs. 2-3 and a feasibility map as PNG",
        description="Write fig2.png, fig3.png and feasibility.png (needs matplotlib: "
                    "pip install 'tdcm_ros[plot]').")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="output directory (created if missing; its parent must exist)")
    parser.add_argument("--points", type=int, default=41,
                        help="grid points per sweep axis (default: 41)")
    parser.add_argument("--dpi", type=int, default=130, help="PNG resolution (default: 130)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Write the figures and list them; typed errors propagate to ``tdcm``'s handler."""
    from tdcm_ros.figures import write_figures

    started = perf_counter()
    paths = write_figures(args.out, points=args.points, dpi=args.dpi)
    for path in paths:
        print(path)
    print(f"{len(paths)} figures in {perf_counter() - started:.1f} s")
    return 0
