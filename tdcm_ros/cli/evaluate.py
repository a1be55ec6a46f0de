"""``tdcm evaluate``: Table I metrics of recorded bags against the model re-run at each step."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING, Any

from tdcm_ros.cli.deprecation import DeprecatedAlias
from tdcm_ros.cli.progress import ProgressBars, add_quiet_argument
from tdcm_ros.errors import InputError, TdcmError

if TYPE_CHECKING:
    from tdcm_ros.metrics.api import Topics

SET_HELP = ("override in SI units: a design field (E=1.2e9, w_d=0.0014) or design.preset=NAME, "
            "steps.tolerance_n, steps.min_hold_s, steps.settle_s, steps.zero_n, "
            "markers.arc_lengths=0.015,0.033,0.053, markers.labels=m1,m2,m3, "
            "markers.ball_radius, markers.side_deg, align.tolerance_s, mape_threshold_m, "
            "stations, deflection_axis=marker|body, roll.tolerance_rad, solver.<setting>")


def add_input_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments shared by ``evaluate`` and ``calibrate``."""
    parser.add_argument("bags", nargs="+", metavar="BAG",
                        help="rosbag2 folder or .mcap file (several: trials numbered on)")
    parser.add_argument("--tension-topic", action="append", metavar="TOPIC|NAME=TOPIC",
                        help="TOPIC (default: tension): a geometry_msgs/msg/WrenchStamped "
                             "(force.z) or std_msgs/msg/Float64 for a body with one tendon, or a "
                             "sensor_msgs/msg/JointState with an effort (N) per tendon, named as "
                             "in the body file; or NAME=TOPIC once per tendon NAME: a "
                             "WrenchStamped or Float64 topic each, aligned on the first one's "
                             "stamps within align.tolerance_s")
    parser.add_argument("--markers-topic", default="markers",
                        help="mocap4r2_msgs/msg/Markers topic (default: markers)")
    parser.add_argument("--joint-states-topic", default="joint_states",
                        help="sensor_msgs/msg/JointState topic holding the roll (default: "
                             "joint_states; absent from a bag: roll 0 throughout)")
    parser.add_argument("--roll-joint", default="roll",
                        help="joint of --joint-states-topic the body rolls by, rad about the "
                             "base +z axis (default: roll)")
    parser.add_argument("--design", metavar="NAME|FILE",
                        help="design preset or body file (.yaml) the model starts from (default: "
                             "paper-experiment); the same as --set design.preset=NAME")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help=SET_HELP)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    add_quiet_argument(parser)


def design_sets(args: argparse.Namespace) -> list[str]:
    """``--set`` values with ``--design NAME`` first as ``design.preset=NAME`` (given once)."""
    if args.design is None:
        return list(args.set)
    if any(pair.partition("=")[0].strip() == "design.preset" for pair in args.set):
        raise InputError(f"--design {args.design!r} and --set design.preset=... both name the "
                         "design; allowed: one of them", parameter="--design", value=args.design,
                         allowed="--design NAME or --set design.preset=NAME, not both")
    return [f"design.preset={args.design}", *args.set]


def input_topics(args: argparse.Namespace) -> Topics:
    """The topics ``--tension-topic`` (default ``tension``), ``--markers-topic`` and
    ``--joint-states-topic`` name, with ``--roll-joint``."""
    from tdcm_ros.metrics.api import Topics

    return Topics(tuple(args.tension_topic or ("tension",)), args.markers_topic,
                  args.joint_states_topic, args.roll_joint)


def register(subparsers: Any) -> None:
    """Add the ``evaluate`` subcommand."""
    parser = subparsers.add_parser(
        "evaluate", help="Table I metrics of bags against the model",
        description="Detect tension steps in the bags (holds of every tendon's tension), average "
                    "the markers per step and compare them with the model at each step's mean "
                    "tension, one per tendon (MAPE, RMSE, MAE, shape error, deflection mean).",
        epilog="examples:\n"
               "  tdcm evaluate bags/paper_experiment\n"
               "  tdcm evaluate run.mcap --design paper-experiment --set E=0.7e9 --out plots\n"
               "  tdcm evaluate trial1 trial2 --json > table1.json\n"
               "  tdcm evaluate pair_run --design config/bodies/antagonistic_pair.yaml\n"
               "  tdcm evaluate pair_topics --design config/bodies/antagonistic_pair.yaml "
               "--tension-topic flexor=/flexor --tension-topic extensor=/extensor")
    add_input_arguments(parser)
    parser.add_argument("--out", metavar="DIR",
                        help="write the plots shapes.png and error_vs_tension.png into DIR "
                             "(created if missing; its parent must exist; needs matplotlib)")
    parser.add_argument("--plots", metavar="DIR", action=DeprecatedAlias, replacement="--out")
    parser.set_defaults(handler=run)


def fail(command: str, error: TdcmError, as_json: bool) -> int:
    """Report a known error in one line (and as JSON on stdout with ``--json``)."""
    if as_json:
        print(json.dumps({"error": {"kind": error.kind, "message": str(error)}}))
    print(f"tdcm {command}: {error}", file=sys.stderr)
    return error.exit_code


def run(args: argparse.Namespace) -> int:
    """Evaluate; known errors become one line and a non-zero exit status."""
    from tdcm_ros.metrics import format_evaluation, options_from_sets
    from tdcm_ros.metrics.api import evaluate_paths
    from tdcm_ros.model import one_shot

    try:
        options = options_from_sets(design_sets(args))
        # One solve per step (tens to hundreds): the plain kernel takes about as long as numba's
        # import and cache load, without its ~60 MiB (bench/bench_evaluate_memory.py).
        with one_shot(), ProgressBars.of(args) as bars:
            ev = evaluate_paths(args.bags, options, progress=bars, topics=input_topics(args))
        plots = []
        out = args.out or args.plots  # --plots: the deprecated spelling
        option = "--out" if args.out else "--plots"
        if out:
            from tdcm_ros.metrics import write_plots

            plots = write_plots(ev, out, option=option)
    except TdcmError as error:
        return fail("evaluate", error, args.json)
    if args.json:
        print(json.dumps(ev.to_json()))
    else:
        print(format_evaluation(ev))
        for path in plots:
            print(f"plot written to {path}")
    return 0
