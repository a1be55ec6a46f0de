"""``tdcm urdf``: the body as a URDF (robot_description) or a xacro macro, from a preset, a body
file or model_node's parameter file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tdcm_ros.cli.design_args import DEFAULT_DESIGN
from tdcm_ros.errors import InputError

if TYPE_CHECKING:
    from tdcm_ros.model import Design

#: model_node's parameters that name the design the others override.
_DESIGN_SOURCES = ("design.file", "design.preset")


def register(subparsers: Any) -> None:
    """Add the ``urdf`` subcommand."""
    parser = subparsers.add_parser(
        "urdf", help="the body as a URDF chain (robot_description) for robot_state_publisher",
        description="Write the body's URDF: from the link tdcm_base, the roll joint, then per "
                    "segment (tube or notch, base to tip) a turn (revolute), a chord "
                    "(prismatic) and a bend (revolute) joint, so that the joint values "
                    "model_node computes put the chain exactly on the solved midline; tubes "
                    "drawn as cylinders, notches as their backbones. --xacro writes a macro "
                    "that a larger robot's description includes under its tool link.",
        epilog="examples:\n"
               "  tdcm urdf > body.urdf\n"
               "  tdcm urdf --params config/model_node.yaml   # the body model_node models\n"
               "  tdcm urdf --design config/bodies/tip_first_wrist.yaml -o wrist.urdf\n"
               "  tdcm urdf --xacro -o tdcm_body.urdf.xacro   # <xacro:tdcm_body parent=\"tool0\"/>\n"
               "  tdcm urdf --name wrist --prefix left_ -o left_wrist.urdf")
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--design", metavar="NAME|FILE",
                        help=f"a preset or a body file (default {DEFAULT_DESIGN})")
    source.add_argument("--params", metavar="FILE",
                        help="model_node's parameter file: its design.file or design.preset and "
                             "design.* values, as the node starts with them")
    parser.add_argument("--node", default="/model_node", metavar="NAME",
                        help="with --params: the node's fully qualified name (default "
                             "/model_node)")
    parser.add_argument("--xacro", action="store_true",
                        help="a xacro macro NAME(parent, prefix, xyz, rpy) mounting the body by a "
                             "fixed joint under the link parent, instead of a robot")
    parser.add_argument("-o", "--output", metavar="FILE", help="write here (default: stdout)")
    parser.add_argument("--name", default="tdcm_body",
                        help="the robot's (or the macro's) name, before every link and joint "
                             "(default tdcm_body, the names model_node publishes)")
    parser.add_argument("--prefix", default="",
                        help="put before every link and joint name (two bodies in one URDF; "
                             "with robot_state_publisher's frame_prefix leave it empty; the "
                             "macro takes it as its argument)")
    parser.set_defaults(handler=run)


def node_design(params_file: str, node: str = "/model_node") -> Design:
    """The design model_node ``node`` starts with under ``params_file``: its ``design.file``, else
    its ``design.preset`` (default the CLI's), with its other ``design.*`` values over it."""
    from tdcm_ros.model import named_design
    from tdcm_ros.runtime import node_parameters

    if not Path(params_file).is_file():
        raise InputError(f"--params = {params_file!r} is no file", parameter="--params",
                         value=params_file, allowed="model_node's parameter file (.yaml)")
    values = node_parameters([params_file], node)
    base = named_design(str(values.get("design.file") or values.get("design.preset")
                            or DEFAULT_DESIGN))
    return base.with_overrides(**{key.removeprefix("design."): value
                                  for key, value in values.items()
                                  if key.startswith("design.") and key not in _DESIGN_SOURCES})


def run(args: argparse.Namespace) -> int:
    """Write the URDF; typed errors propagate to ``tdcm``'s handler."""
    from tdcm_ros.model import body_urdf, body_xacro, named_design
    from tdcm_ros.runtime import validate_frame_prefix

    if args.xacro and args.prefix:
        raise InputError(f"--prefix = {args.prefix!r} with --xacro: the macro takes the prefix "
                         "as its argument", parameter="--prefix", value=args.prefix,
                         allowed="'' with --xacro")
    design = (node_design(args.params, args.node) if args.params
              else named_design(args.design or DEFAULT_DESIGN))
    text = (body_xacro(design, name=args.name) if args.xacro
            else body_urdf(design, name=args.name,
                           prefix=validate_frame_prefix(args.prefix, "--prefix")))
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
