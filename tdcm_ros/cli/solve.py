"""``tdcm solve``: the shape for one design and tension, as a summary, JSON or a plot."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

import numpy as np

from tdcm_ros.cli.design_args import (
    add_design_arguments,
    add_sought_tendon,
    design_and_settings,
    sought_tendon,
    target_number,
)
from tdcm_ros.errors import InputError, TdcmError
from tdcm_ros.model import (
    DEFAULT_TENSION_MAX_N,
    SolveResult,
    TensionRangeError,
    one_shot,
    solve,
    solve_inverse,
)


def register(subparsers: Any) -> None:
    """Add the ``solve`` subcommand."""
    parser = subparsers.add_parser(
        "solve", help="shape of the manipulator for one tension",
        description="Solve Algorithm 1 for one design and tendon tension, or the tension "
                    "that pulls the tendon in by a stroke (SI units).",
        epilog="examples:\n"
               "  tdcm solve --tension 20\n"
               "  tdcm solve --design fig2-wn-1.9 --tension 20 --json\n"
               "  tdcm solve --tension 12 --set E=1.2e9 --plot shape.png\n"
               "  tdcm solve --design config/bodies/antagonistic_pair.yaml --tension 25,5\n"
               "  tdcm solve --stroke 0.0005\n"
               "  tdcm solve --design config/bodies/antagonistic_pair.yaml --stroke 0.0004 "
               "--tendon extensor --tensions 12,0")
    drive = parser.add_mutually_exclusive_group(required=True)
    drive.add_argument("--tension", type=str, help="tendon tension (N); one per tendon, "
                       "comma-separated, for a body file with several (base to tip order of "
                       "its tendons list)")
    drive.add_argument("--stroke", metavar="M", help="tendon stroke (m): how far the tendon's "
                       "actuator pulls it in against the straight body (its slack and stretch "
                       "included where the body file gives them); the tension is found within "
                       f"[0, {DEFAULT_TENSION_MAX_N:g}] N (tdcm inverse --tendon-stroke sets "
                       "the bounds)")
    add_sought_tendon(parser)
    add_design_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    parser.add_argument("--plot", metavar="FILE", help="draw midline and curvature to a .png, "
                        ".pdf or .svg file in an existing folder")
    parser.set_defaults(handler=run)


def _tension(text: str) -> float | list[float]:
    """``--tension`` text as a number (N), or comma-separated numbers (one per tendon); the
    solver checks their count and range."""
    try:
        values = [float(item) for item in text.split(",")]
    except ValueError:
        raise TensionRangeError(f"--tension = {text!r} is not a number or comma-separated "
                                "numbers; allowed: finite numbers in [0, inf) N",
                                parameter="--tension", value=text,
                                allowed="[0, inf) N, one per tendon") from None
    return values[0] if len(values) == 1 else values


def run(args: argparse.Namespace) -> int:
    """Solve and report; typed errors become exit status 2 (input) or 3 (physics)."""
    try:
        name, design, settings = design_and_settings(args)
        if args.plot:
            from tdcm_ros.figures import plot_file

            plot_file("--plot", args.plot)
        with one_shot():  # one solve and its report: the plain-Python kernel, numba not imported
            if args.stroke is None:
                if args.tendon is not None or args.tensions is not None:
                    raise InputError("--tendon and --tensions go with --stroke; allowed: "
                                     "--tension N,N,... gives every tendon's tension",
                                     parameter="--tendon", value=args.tendon,
                                     allowed="--stroke")
                result = solve(design, _tension(args.tension), settings=settings)
            else:
                stroke = target_number("--stroke", args.stroke, "[0, inf) m")
                result = solve_inverse(design, tendon_stroke=stroke, settings=settings,
                                       **sought_tendon(args)).result
            report = json.dumps(result.summary()) if args.json else _notch_line(result)
    except TdcmError as error:
        if args.json:
            print(json.dumps({"error": {"kind": error.kind, "message": str(error)}}))
        print(f"tdcm solve: {error}", file=sys.stderr)
        return error.exit_code
    if args.json:
        print(report)
    else:
        x, _, z = result.tip_position * 1e3
        print(f"design {name}: L = {design.length * 1e3:.3f} mm, E = {design.E:.4g} Pa, "
              f"routing {settings.routing}, loads {settings.loads}"
              + (", axial compressible" if settings.axial == "compressible" else ""))
        tensions = ", ".join(f"{t:g}" for t in result.tensions_n)
        print(f"tension {tensions} N -> tip (x, z) = ({x:.4f}, {z:.4f}) mm, "
              f"angle {result.tip_angle_rad:.5f} rad, deflection "
              f"{result.tip_deflection_m * 1e3:.4f} mm")
        for name, tension, length, stroke, actuator in zip(
                result.tendons.names, result.tensions_n, result.tendon_lengths_m,
                result.tendon_strokes_m, result.actuator_strokes_m, strict=True):
            travel = "" if actuator == stroke else f", actuator {actuator * 1e3:.6f} mm"
            print(f"{name}: {tension:g} N, length {length * 1e3:.6f} mm, stroke "
                  f"{stroke * 1e3:.6f} mm{travel}")
        print(report)
        print(f"converged in {result.iterations} iterations ({result.strategy}), "
              f"{result.solve_time_s * 1e6:.0f} us")
    if args.plot:
        from tdcm_ros.plotting import plot_solution

        plot_solution(result, args.plot)
        if not args.json:
            print(f"plot written to {args.plot}")
    return 0


def _notch_line(result: SolveResult) -> str:
    """One line on the notches: their bend range, the least stop margin and the peak strain."""
    angles = result.notch_angles_rad * 1e3
    margins = result.notch_stop_margins_rad
    strains = result.notch_peak_strains
    tight = int(np.argmin(margins))
    peak = int(np.argmax(strains))
    return (f"{angles.size} notches: bend {angles.min():.3f}..{angles.max():.3f} mrad, least stop "
            f"margin {margins[tight]:.4f} rad (notch {tight + 1}), peak strain "
            f"{strains[peak] * 100:.3f} % (notch {peak + 1})")
