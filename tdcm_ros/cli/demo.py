"""``tdcm demo``: the paper's experiment end to end on the embedded runtime, with no hardware.

A scene's simulated bench (device twin on a pty, simulated Vicon markers) runs with the real
tension driver, model node, mocap node, metrics node and recorder, each its own process, on a
private zenoh router. After the schedule (default: the scene's, the paper's 3 trials of
0 -> 20 N in 4 N steps) the bag is evaluated (Table I metrics, per-step table, plots) and the
model's E is calibrated on it, with the metrics after calibration.
"""

from __future__ import annotations

import argparse
import os
import socket
import time
from pathlib import Path

from tdcm_ros.errors import InputError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``demo`` subcommand."""
    parser = subparsers.add_parser("demo", help="run the paper's experiment end to end (simulated)")
    parser.add_argument("--scene", default="paper_experiment",
                        help="shipped scene name or scene YAML path (default paper_experiment)")
    parser.add_argument("--out", default=None,
                        help="output folder (default tdcm_demo/<scene>-<time>); must not hold a bag")
    parser.add_argument("--trials", type=int, default=None,
                        help="override the scene's number of trials")
    parser.add_argument("--hold", type=float, default=None,
                        help="override the scene's hold time per level (s)")
    parser.add_argument("--no-calibrate", action="store_true", help="skip the calibration of E")
    parser.add_argument("--endpoint", default=None,
                        help="zenoh router endpoint (default: a private router on a free port)")
    parser.set_defaults(handler=run)


def _free_endpoint() -> str:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{probe.getsockname()[1]}"


def _out_dir(requested: str | None, scene_name: str) -> Path:
    out = Path(requested) if requested else Path("tdcm_demo") / (
        f"{scene_name}-{time.strftime('%Y%m%d-%H%M%S')}")
    if (out / "bag").exists():
        raise InputError(f"--out {str(out)!r} already holds a bag; allowed: a new or empty folder "
                         "(recorded data is never overwritten)", parameter="--out",
                         value=str(out), allowed="a folder without bag/")
    out.mkdir(parents=True, exist_ok=True)
    return out


def run(args: argparse.Namespace) -> int:
    """Run the demo; returns the exit status."""
    from tdcm_ros.demo.plan import make_plan
    from tdcm_ros.demo.report import report
    from tdcm_ros.demo.run import record_live
    from tdcm_ros.runtime.run_node import configure_logging
    from tdcm_ros.runtime.zenoh_runtime import ENDPOINT_ENV
    from tdcm_ros.scenes import load_scene

    configure_logging("WARNING")
    started = time.monotonic()
    scene = load_scene(args.scene)
    plan = make_plan(scene, args.scene, _out_dir(args.out, scene.name), trials=args.trials,
                     hold_s=args.hold)
    endpoint = args.endpoint or _free_endpoint()
    os.environ[ENDPOINT_ENV] = endpoint
    levels = ", ".join(f"{v:g}" for v in plan.schedule.levels)
    print(f"tdcm demo: scene {scene.name!r} ({scene.description})")
    print(f"  schedule: {plan.schedule.trials} trial(s) of [{levels}] N, {plan.schedule.hold:g} s "
          f"per level ({plan.schedule.duration:g} s); effects: "
          f"{', '.join(scene.effect_names()) or 'none'}")
    print(f"  output: {plan.out}   router: {endpoint}")
    record_live(plan, endpoint=endpoint)
    report(plan, calibrate=not args.no_calibrate)
    print(f"tdcm demo: done in {time.monotonic() - started:.1f} s; outputs in {plan.out}")
    return 0
