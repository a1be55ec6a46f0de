"""``tdcm design``: inverse design, the designs that reach a tip target within a tension budget."""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path
from time import perf_counter
from typing import Any

from tdcm_ros.cli.design_args import (
    add_design_arguments,
    add_sought_tendon,
    add_tip_targets,
    design_and_settings,
    sought_tendon,
    target_number,
)
from tdcm_ros.cli.design_shape import FILES as SHAPE_FILES
from tdcm_ros.cli.design_shape import HELP as PROBLEM_HELP
from tdcm_ros.cli.design_shape import add_problem_arguments, run_problem
from tdcm_ros.cli.progress import ProgressBars, add_quiet_argument
from tdcm_ros.errors import InputError, TdcmError
from tdcm_ros.model import (
    DEFAULT_ALLOWABLE_STRAIN,
    DEFAULT_DESIGN_LADDER,
    DEFAULT_DESIGN_SAMPLES,
    DEFAULT_TENSION_BUDGET_N,
    DEFAULT_TOL,
    FREE_FIELDS,
    SAMPLINGS,
    DesignSearch,
    NoDesignMeetsTargetError,
    search_designs,
)

EXIT_MEANINGS = {"design": {3: "no candidate reaches the target within the budget inside the "
                               "limits (the message names the closest)"}}
DEFAULT_TOP = 10
"""Pareto rows printed in the table."""
FILES = ("design.json", "pareto.csv", "pareto.png")
"""What ``--out DIR`` writes."""


def register(subparsers: Any) -> None:
    """Add the ``design`` subcommand."""
    parser = subparsers.add_parser(
        "design", help="inverse design: designs that reach a tip target within a tension "
                       "budget, or a pattern for a shape (--problem)",
        description="Uniform search (--tip-deflection or --tip-angle): sample designs (the base design with --free fields varied) and find for "
                    "each the tension within 0..--tension-max N that puts the tip at the target "
                    "deflection (m) or angle (rad), without exceeding --allowable-strain, "
                    "closing a notch or meeting the tendon singularity; print the Pareto set "
                    "(reach within the budget, peak strain at the target, tension needed). "
                    "--free L=MIN:MAX frees the total length (m), which then sets w_t. "
                    "Shape design (--problem FILE): per-notch variables and laws, shape "
                    "targets each at a tension or stroke, strain, hard-stop and fabrication "
                    "limits; differential evolution then least squares (scipy); --out writes "
                    "the body file, an STL of the body and the target-against-achieved plot.",
        epilog="examples:\n"
               "  tdcm design --tip-angle 0.45 --free w_n=0.5e-3:3e-3 --free N=3:12\n"
               "  tdcm design --tip-deflection 0.012 --free w_d=0.6e-3:2.2e-3 --free w_t=1e-3:6e-3 "
               "--samples 20000 --json\n"
               "  tdcm design --design fig2-wn-1.9 --tip-angle 0.2 --free w_n=1e-3:2.5e-3 "
               "--free L=0.04:0.06 --out design_out\n"
               "  tdcm design --design config/bodies/antagonistic_pair.yaml --tendon flexor "
               "--tensions 0,5 --tip-angle 0.2 --free w_n=1e-3:3e-3 --samples 64\n"
               "  tdcm design --problem config/design/constant_curvature.yaml --out cc_out\n"
               "  tdcm design --problem config/design/tip_first_wrist.yaml --workers 1 --json\n"
               "\n" + PROBLEM_HELP)
    targets = parser.add_mutually_exclusive_group(required=True)
    add_tip_targets(targets)
    add_problem_arguments(parser, targets)
    parser.add_argument("--free", action="append", default=[], metavar="NAME=MIN:MAX",
                        help=f"a field to vary over [MIN, MAX] (SI units; N integers): "
                             f"{', '.join(FREE_FIELDS)}; repeat for more")
    parser.add_argument("--tension-max", metavar="N",
                        help=f"tension budget 0..N (default {DEFAULT_TENSION_BUDGET_N:g} N)")
    parser.add_argument("--allowable-strain",
                        metavar="S", help="largest peak notch bending strain (default "
                                          f"{DEFAULT_ALLOWABLE_STRAIN:g})")
    parser.add_argument("--samples", metavar="K",
                        help=f"candidate designs (default {DEFAULT_DESIGN_SAMPLES})")
    parser.add_argument("--sampling", choices=SAMPLINGS,
                        help="scrambled Sobol' (default) or Latin hypercube")
    parser.add_argument("--seed", help="sampling or search seed (default 0; --problem: the file's)")
    parser.add_argument("--ladder", metavar="K",
                        help=f"tension rungs before refining (default {DEFAULT_DESIGN_LADDER})")
    parser.add_argument("--tol",
                        help=f"tolerance on the target, m or rad (default {DEFAULT_TOL:g})")
    parser.add_argument("--top", metavar="K",
                        help=f"Pareto rows in the table (default {DEFAULT_TOP}; all in JSON)")
    add_sought_tendon(parser)
    add_design_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    parser.add_argument("--out", metavar="DIR",
                        help=f"write {', '.join(FILES)} into DIR (created if missing); with "
                             f"--problem: {', '.join(SHAPE_FILES)}")
    add_quiet_argument(parser)
    parser.set_defaults(handler=run)


def _number(option: str, text: str, kind: type = float) -> Any:
    """``text`` of ``option`` as a ``kind``; the model checks its range."""
    try:
        return kind(text)
    except ValueError:
        noun = "an integer" if kind is int else "a number"
        raise InputError(f"{option} = {text!r} is not {noun}", parameter=option, value=text,
                         allowed=noun) from None


def _or(text: str | None, default: float) -> str:
    """An option's text, or its default's where it was not given."""
    return str(default) if text is None else text


def _free(pairs: list[str]) -> dict[str, tuple[float, float]]:
    """``--free NAME=MIN:MAX`` options as ``{name: (min, max)}``."""
    out: dict[str, tuple[float, float]] = {}
    for pair in pairs:
        name, sep, span = pair.partition("=")
        low, colon, high = span.partition(":")
        name = name.strip().removeprefix("design.")
        if not sep or not colon or not name:
            raise InputError(f"--free {pair!r} is not NAME=MIN:MAX", parameter="--free",
                             value=pair, allowed="NAME=MIN:MAX, SI units")
        if name in out:
            raise InputError(f"--free {name} given twice", parameter="--free", value=pair,
                             allowed="each field once")
        kind: type = int if name == "N" else float
        out[name] = (_number(f"--free {name} min", low.strip(), kind),
                     _number(f"--free {name} max", high.strip(), kind))
    return out


def run(args: argparse.Namespace) -> int:
    """Search and report; typed errors become exit status 2 (input) or 3 (no design)."""
    if args.problem is not None:
        return run_problem(args)
    started = perf_counter()
    name = ""
    try:
        name, design, settings = design_and_settings(args)
        target: dict[str, Any] = (
            {"tip_deflection": target_number("--tip-deflection", args.tip_deflection,
                                             "(0, inf) m")}
            if args.tip_deflection is not None else
            {"tip_angle": target_number("--tip-angle", args.tip_angle, "(0, inf) rad")})
        top = _number("--top", _or(args.top, DEFAULT_TOP), int)
        if top < 0:
            raise InputError(f"--top = {top} is out of range; allowed: an integer >= 0",
                             parameter="--top", value=top, allowed="an integer >= 0")
        with ProgressBars.of(args) as bars:
            search = search_designs(
                design, _free(args.free), **target, settings=settings, progress=bars,
                tension_max=_number("--tension-max", _or(args.tension_max,
                                                          DEFAULT_TENSION_BUDGET_N)),
                allowable_strain=_number("--allowable-strain", _or(
                    args.allowable_strain, DEFAULT_ALLOWABLE_STRAIN)),
                samples=_number("--samples", _or(args.samples, DEFAULT_DESIGN_SAMPLES), int),
                sampling=args.sampling or SAMPLINGS[0],
                seed=_number("--seed", _or(args.seed, 0), int),
                ladder=_number("--ladder", _or(args.ladder, DEFAULT_DESIGN_LADDER), int),
                tol=_number("--tol", _or(args.tol, DEFAULT_TOL)),
                **sought_tendon(args))
    except TdcmError as error:
        if args.json:
            print(json.dumps({"error": {"kind": error.kind, "message": str(error)}}))
        print(f"tdcm design: {error}", file=sys.stderr)
        if isinstance(error, NoDesignMeetsTargetError) and args.out:
            _write(error.search, name, Path(args.out), plot=False)
        return error.exit_code
    summary = {"design": name, **search.summary(), "time_s": perf_counter() - started}
    if args.out:
        for path in _write(search, name, Path(args.out), plot=True):
            print(f"wrote {path}", file=sys.stderr)
    if args.json:
        print(json.dumps(summary))
    else:
        _print(name, search, summary["time_s"], top)
    return 0


def _write(search: DesignSearch, name: str, out: Path, *, plot: bool) -> list[Path]:
    """``design.json`` (the summary), ``pareto.csv`` and (``plot``) ``pareto.png`` in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / "design.json", out / "pareto.csv"]
    paths[0].write_text(json.dumps({"design": name, **search.summary()}, indent=1) + "\n")
    rows = [search.row(int(i)) for i in search.pareto]
    with paths[1].open("w", newline="") as handle:
        columns = [r.name for r in search.ranges] + [
            "tension_n", search.target_kind, "peak_strain", "reach", "reach_tension_n"]
        writer = csv.writer(handle)
        writer.writerow(columns)
        for row in rows:
            writer.writerow([row["free"][c] if c in row["free"] else row[c] for c in columns])
    if plot:
        from tdcm_ros.plotting import plot_search

        paths.append(plot_search(search, out / "pareto.png"))
    return paths


def _print(name: str, search: DesignSearch, seconds: float, top: int) -> None:
    """The human summary: counts, then the Pareto set by tension needed (mm, %, N, rad)."""
    scale, unit = (1e3, "mm") if search.unit == "m" else (1.0, "rad")
    counts = ", ".join(f"{v} {k}" for k, v in search.counts().items() if v)
    print(f"design {name}: {search.target_kind.replace('_', ' ')} {search.target * scale:g} "
          f"{unit} within 0-{search.tension_max_n:g} N, allowable strain "
          f"{search.allowable_strain:g}; {search.outcome.size} candidates ({counts}) in "
          f"{seconds:.1f} s, {search.solves} solves")
    print(f"Pareto set: {search.pareto.size} designs (reach, peak strain, tension needed); "
          f"by tension needed:")
    names = [r.name for r in search.ranges]
    header = [*(f"{n} (mm)" if n != "N" else "N" for n in names), "tension (N)",
              "peak strain (%)", f"reach ({unit})", "reach at (N)"]
    print("  ".join(f"{h:>12}" for h in header))
    for i in search.pareto[:top]:
        cells = [f"{search.values[n][i]:.0f}" if n == "N" else f"{search.values[n][i] * 1e3:.4f}"
                 for n in names]
        cells += [f"{search.tension_n[i]:.6f}", f"{search.peak_strain[i] * 100:.4f}",
                  f"{search.reach[i] * scale:.6g}", f"{search.reach_tension_n[i]:.4g}"]
        print("  ".join(f"{c:>12}" for c in cells))
    if search.pareto.size > top:
        print(f"... {search.pareto.size - top} more (--top, --json or --out)")
