"""``tdcm demo``: the paper's experiment end to end, with no hardware, on zenoh or rclpy.

A scene's simulated bench (device twin on a pty, simulated Vicon markers) runs with the real
tension driver, model node, mocap node, metrics node and recorder, each its own process, on a
private zenoh router (``--runtime zenoh``, the default unless ``TDCM_RUNTIME`` says otherwise) or
as rclpy nodes in the environment's ROS domain (``--runtime rclpy``). After the schedule (default: the scene's, the paper's 3 trials of
0 -> 20 N in 4 N steps) the bag is evaluated (Table I metrics, per-step table, plots) and the
model's E is calibrated on it, with the metrics after calibration.

A scene with a ``trajectory`` section (``--scene tracking``) runs the shape controller instead
of the schedule: the demo publishes the circle's tip targets, feed-forward laps then feedback
laps, and reports the tracking error of each phase from the bag (no calibration).
"""

from __future__ import annotations

import argparse
import os
import socket
import time
from pathlib import Path

from tdcm_ros.cli.progress import ProgressBars, add_quiet_argument
from tdcm_ros.cli.runtime_option import add_runtime_option
from tdcm_ros.errors import InputError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``demo`` subcommand."""
    parser = subparsers.add_parser(
        "demo", help="run the paper's experiment end to end (simulated)",
        description="Run the paper's experiment with no hardware: a scene's simulated bench "
                    "(device twin, simulated Vicon markers) drives the real tension driver, "
                    "model, mocap and metrics nodes and a recorder, each its own process. Then "
                    "the bag is evaluated (Table I, per-step table, OUT/plots, "
                    "OUT/metrics.json) and E is calibrated on it.",
        epilog="examples:\n"
               "  tdcm demo                                 # the paper's 3 x (0 -> 20 N)\n"
               "  tdcm demo --scene friction-hysteresis --out /tmp/demo --trials 1\n"
               "  tdcm demo --runtime rclpy --no-calibrate\n"
               "  tdcm demo --scene tracking                # follow a circle of tip targets\n\n"
               "scenes: tdcm scene list; each scene YAML documents its bench.")
    parser.add_argument("--scene", default="paper-experiment",
                        help="shipped scene name or scene YAML path (default paper-experiment)")
    parser.add_argument("--out", default=None,
                        help="output folder: logs, plots, metrics.json (default tdcm_demo/<scene>-<time>)")
    parser.add_argument("--trials", type=int, default=None,
                        help="override the scene's number of trials")
    parser.add_argument("--hold", type=float, default=None,
                        help="override the scene's hold time per level (s)")
    parser.add_argument("--no-calibrate", action="store_true", help="skip the calibration of E")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="evaluation setting over the scene's, as `tdcm evaluate --set` "
                             "(step settings default to ones derived from the hold time)")
    parser.add_argument("--bag", default=None,
                        help="where the recorder writes the bag (default OUT/bag; must not exist)")
    parser.add_argument("--record", default=None,
                        help="comma-separated topics to record (default: the demo graph's "
                             "topics, tdcm_ros.demo.plan.RECORDED_TOPICS)")
    parser.add_argument("--endpoint", default=None,
                        help="zenoh router endpoint (default: a private router on a free port)")
    add_runtime_option(parser, "the graph", "; rclpy uses ROS_DOMAIN_ID and "
                       "ROS_AUTOMATIC_DISCOVERY_RANGE from the environment")
    add_quiet_argument(parser)
    parser.set_defaults(handler=run)


def _free_endpoint() -> str:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{probe.getsockname()[1]}"


def _out_dir(requested: str | None, scene_name: str) -> Path:
    return Path(requested) if requested else Path("tdcm_demo") / (
        f"{scene_name}-{time.strftime('%Y%m%d-%H%M%S')}")


def _check_new(bag: Path, option: str) -> None:
    if bag.exists():
        raise InputError(f"{option} {str(bag)!r} already exists; allowed: a path that does not "
                         "exist yet (recorded data is never overwritten)", parameter=option,
                         value=str(bag), allowed="a new path")


def _check_tracking_options(args: argparse.Namespace) -> None:
    """A tracking scene's timing is its trajectory section: the staircase options do not apply."""
    for option, given in (("--trials", args.trials is not None), ("--hold", args.hold is not None),
                          ("--set", bool(args.set))):
        if given:
            raise InputError(f"{option} applies to a scene's tension schedule; a scene with a "
                             "trajectory section runs its laps (set them in the scene file's "
                             "trajectory section)", parameter=option,
                             allowed="no value for a tracking scene")


def run(args: argparse.Namespace) -> int:
    """Run the demo; returns the exit status."""
    from tdcm_ros.demo import (
        make_plan,
        record_live,
        report,
        scene_options,
        tracking_report,
    )
    from tdcm_ros.metrics import options_from_sets
    from tdcm_ros.runtime.run_node import configure_logging, resolve_runtime
    from tdcm_ros.runtime.zenoh_runtime import ENDPOINT_ENV
    from tdcm_ros.scenes import load_scene

    configure_logging("WARNING")
    runtime = resolve_runtime(args.runtime)
    started = time.monotonic()
    scene = load_scene(args.scene)
    out = _out_dir(args.out, scene.name)
    topics = None if args.record is None else tuple(
        t.strip() for t in args.record.split(",") if t.strip())
    if scene.trajectory is not None:
        _check_tracking_options(args)
    plan = make_plan(scene, args.scene, out, trials=args.trials, hold_s=args.hold,
                     bag=Path(args.bag) if args.bag else None, recorded_topics=topics)
    _check_new(plan.bag, "--bag" if args.bag else "--out")
    options = (options_from_sets(args.set, base=scene_options(plan))  # checked before the run
               if plan.targets is None else None)
    out.mkdir(parents=True, exist_ok=True)
    endpoint = args.endpoint or _free_endpoint()
    os.environ[ENDPOINT_ENV] = endpoint
    levels = ", ".join(f"{v:g}" for v in plan.schedule.levels)
    print(f"tdcm demo: scene {scene.name!r} ({scene.description})")
    effects = ', '.join(scene.effect_names()) or 'none'
    if plan.targets is None:
        print(f"  schedule: {plan.schedule.trials} trial(s) of [{levels}] N, "
              f"{plan.schedule.hold:g} s per level ({plan.schedule.duration:g} s); effects: "
              f"{effects}")
    else:
        circle = plan.targets.circle
        print(f"  trajectory: circle of radius {circle.radius * 1e3:g} mm about "
              f"({circle.centre[0] * 1e3:g}, {circle.centre[1] * 1e3:g}) mm, {circle.period:g} s "
              f"per lap, {circle.feedforward_laps} feed-forward then {circle.feedback_laps} "
              f"feedback lap(s)"
              + (f" then {circle.learned_feedforward_laps} feed-forward with the learned gain"
                 if circle.learned_feedforward_laps else "")
              + f" ({circle.duration:g} s); effects: {effects}")
    graph = (f"router {endpoint}" if runtime == "zenoh" else
             f"rclpy, ROS_DOMAIN_ID {os.environ.get('ROS_DOMAIN_ID', '0')}")
    print(f"  output: {plan.out}   runtime: {graph}")
    record_live(plan, endpoint=endpoint, runtime=runtime)
    if options is None:
        assert plan.targets is not None
        tracking_report(plan.bag, plan.targets.circle, plan.out, scene.name,
                        world_gain=scene.design.E / scene.true_design.E)
    else:
        with ProgressBars.of(args) as bars:
            report(plan, options, calibrate=not args.no_calibrate, progress=bars)
    print(f"tdcm demo: done in {time.monotonic() - started:.1f} s; outputs in {plan.out}")
    return 0
