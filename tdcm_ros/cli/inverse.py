"""``tdcm inverse``: the tendon tension that puts the tip at a target, as a summary or JSON."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from tdcm_ros.cli.design_args import (
    add_design_arguments,
    add_sought_tendon,
    add_tip_targets,
    design_and_settings,
    sought_tendon,
    target_number,
)
from tdcm_ros.device import constants
from tdcm_ros.errors import TdcmError, out_of_range
from tdcm_ros.model import (
    DEFAULT_TENSION_MAX_N,
    InvalidTargetError,
    InverseResult,
    solve_inverse,
)

EXIT_MEANINGS = {"inverse": {3: "the target is out of reach within the tension bounds, or a "
                                "physical limit of the model"}}


def register(subparsers: Any) -> None:
    """Add the ``inverse`` subcommand."""
    parser = subparsers.add_parser(
        "inverse", help="tendon tension that puts the tip at a target",
        description="The tension (N) within [--tension-min, --tension-max] that puts the tip "
                    "at a deflection (m), an angle (rad) or a point (x, z in tdcm_base, m; "
                    "least squares), or that pulls the tendon in by a stroke (m), with the "
                    "achieved tip, the residual and d(tip)/dT.",
        epilog="examples:\n"
               "  tdcm inverse --tip-angle 0.3\n"
               "  tdcm inverse --design fig2-wn-1.9 --tip-deflection 0.005 --json\n"
               "  tdcm inverse --tip-point=0.006,0.0525 --set E=1.2e9 --tension-max 22\n"
               "  tdcm inverse --tendon-stroke 0.0005\n"
               "  tdcm inverse --design config/bodies/antagonistic_pair.yaml --tip-angle 0.2 "
               "--tendon flexor --tensions 0,5")
    target = parser.add_mutually_exclusive_group(required=True)
    add_tip_targets(target)
    target.add_argument("--tip-point", metavar="X,Z", help="tip point in tdcm_base (m); write a negative X as "
                        "--tip-point=-0.001,0.05")
    target.add_argument("--tendon-stroke", metavar="M",
                        help="how far the tendon is pulled in against the straight body (m)")
    parser.add_argument("--tension-min", default="0", metavar="N",
                        help="lower tension bound (N, default 0)")
    parser.add_argument("--tension-max", default=str(DEFAULT_TENSION_MAX_N), metavar="N",
                        help=f"upper tension bound (N, default {DEFAULT_TENSION_MAX_N:g})")
    parser.add_argument("--device-max", default=str(DEVICE_MAX_N), metavar="N",
                        help=f"largest tension the device can hold (N, default {DEVICE_MAX_N:g}: "
                             "the tension device's largest setpoint; give your driver's "
                             "tension_max): a target that needs more is said to be out of reach")
    add_sought_tendon(parser)
    add_design_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    parser.set_defaults(handler=run)


#: N: the tension device's largest setpoint (the firmware refuses more).
DEVICE_MAX_N = constants.SETPOINT_MAX_MN / 1000


def _target(args: argparse.Namespace) -> dict[str, Any]:
    """The target keyword of :func:`~tdcm_ros.model.solve_inverse` the options name."""
    if args.tip_deflection is not None:
        return {"tip_deflection": target_number("--tip-deflection", args.tip_deflection, "[0, inf) m")}
    if args.tip_angle is not None:
        return {"tip_angle": target_number("--tip-angle", args.tip_angle, "a finite number, rad")}
    if args.tendon_stroke is not None:
        return {"tendon_stroke": target_number("--tendon-stroke", args.tendon_stroke,
                                               "[0, inf) m")}
    parts = args.tip_point.split(",")
    if len(parts) != 2:
        raise InvalidTargetError(f"--tip-point = {args.tip_point!r} is not X,Z; allowed: two "
                                 "numbers (m) separated by a comma", parameter="--tip-point",
                                 value=args.tip_point, allowed="X,Z (m)")
    return {"tip_point": tuple(target_number("--tip-point", p, "X,Z (m)") for p in parts)}


def run(args: argparse.Namespace) -> int:
    """Find the tension and report; typed errors become exit status 2 (input) or 3 (out of
    reach, physics)."""
    try:
        name, design, settings = design_and_settings(args)
        found = solve_inverse(
            design, **_target(args), settings=settings, **sought_tendon(args),
            tension_min=target_number("--tension-min", args.tension_min, "[0, tension-max) N"),
            tension_max=target_number("--tension-max", args.tension_max, "(tension-min, inf) N"))
        device_max = target_number("--device-max", args.device_max, "> 0 N")
        if not 0.0 < device_max < float("inf"):
            raise out_of_range("--device-max", device_max, "a finite number > 0", unit="N")
    except TdcmError as error:
        if args.json:
            print(json.dumps({"error": {"kind": error.kind, "message": str(error)}}))
        print(f"tdcm inverse: {error}", file=sys.stderr)
        return error.exit_code
    within = found.tension_n <= device_max
    if args.json:
        print(json.dumps({**found.summary(), "device_max_n": device_max,
                          "within_device": within}))
    else:
        _print(name, found)
    if not within:
        print(f"tdcm inverse: WARNING: the target needs {found.tension_n:.4g} N, more than the "
              f"device holds ({device_max:g} N, --device-max)", file=sys.stderr)
    return 0


def _print(name: str, found: InverseResult) -> None:
    """The human summary in the units the target is given in: m (and rad, N), as the JSON."""
    x, z = found.tip_point_m
    result, sens = found.result, found.sensitivity
    unit = "rad" if found.target_kind == "tip_angle" else "m"
    print(f"design {name}: {found.target_kind.replace('_', ' ')} {found.target} {unit} -> "
          f"tension {found.tension_n:.9g} N")
    print(f"achieved tip (x, z) = ({x:.9f}, {z:.9f}) m, angle {result.tip_angle_rad:.9f} rad, "
          f"deflection {result.tip_deflection_m:.9f} m, tendon stroke "
          f"{result.tendon_strokes_m[found.tendon]:.9f} m; residual {found.residual:.3g} {unit}")
    dx, dz = sens.tip_point_m_per_n
    print(f"d(tip)/dT: (x, z) ({dx:.6g}, {dz:.6g}) m/N, angle {sens.tip_angle_rad_per_n:.6g} "
          f"rad/N ({sens.method} difference, step {sens.step_n:g} N); "
          f"{found.forward_solves} forward solves")
