"""``tdcm urdf``: the body as a URDF (robot_description), from a preset or a body file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from tdcm_ros.cli.design_args import DEFAULT_DESIGN
from tdcm_ros.errors import InputError


def register(subparsers: Any) -> None:
    """Add the ``urdf`` subcommand."""
    parser = subparsers.add_parser(
        "urdf", help="the body as a URDF chain (robot_description) for robot_state_publisher",
        description="Write the body's URDF: from the link tdcm_base, the roll joint, then per "
                    "segment (tube or notch, base to tip) a turn (revolute), a chord "
                    "(prismatic) and a bend (revolute) joint, so that the joint values "
                    "model_node computes put the chain exactly on the solved midline; tubes "
                    "drawn as cylinders, notches as their backbones.",
        epilog="examples:\n"
               "  tdcm urdf > body.urdf\n"
               "  tdcm urdf --design config/bodies/tip_first_wrist.yaml -o wrist.urdf\n"
               "  tdcm urdf --name wrist --prefix left_ -o left_wrist.urdf")
    parser.add_argument("--design", metavar="NAME|FILE", default=DEFAULT_DESIGN,
                        help=f"a preset or a body file (default {DEFAULT_DESIGN})")
    parser.add_argument("-o", "--output", metavar="FILE", help="write here (default: stdout)")
    parser.add_argument("--name", default="tdcm_body",
                        help="the robot's name, before every link and joint (default tdcm_body)")
    parser.add_argument("--prefix", default="",
                        help="put before every link and joint name (two bodies in one URDF; "
                             "with robot_state_publisher's frame_prefix leave it empty)")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Write the URDF; typed errors propagate to ``tdcm``'s handler."""
    from tdcm_ros.model import body_urdf, named_design
    from tdcm_ros.runtime import validate_frame_prefix

    text = body_urdf(named_design(args.design), name=args.name,
                     prefix=validate_frame_prefix(args.prefix, "--prefix"))
    if args.output is None:
        sys.stdout.write(text)
        return 0
    try:
        Path(args.output).write_text(text, encoding="utf-8")
    except OSError as error:
        raise InputError(f"--output = {args.output!r} cannot be written: {error}",
                         parameter="--output", value=args.output,
                         allowed="a writable file path") from error
    print(f"wrote {args.output}", file=sys.stderr)
    return 0
