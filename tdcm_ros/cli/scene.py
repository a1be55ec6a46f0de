"""``tdcm scene``: list, validate and explain scenes, and list the effects they can use."""

from __future__ import annotations

import argparse
import json
from typing import Any

from tdcm_ros.errors import out_of_range


def register(subparsers: Any) -> None:
    """Add the ``scene`` subcommand and its actions."""
    parser = subparsers.add_parser(
        "scene", help="list, validate and explain simulated scenes",
        description="Scenes describe the simulated world: design, true material, bench, "
                    "sensors and the effects it contains (only those are computed).",
        epilog="examples:\n"
               "  tdcm scene list\n"
               "  tdcm scene validate my_bench.yaml\n"
               "  tdcm scene explain paper-experiment")
    actions = parser.add_subparsers(dest="action", required=True, metavar="ACTION")
    listing = actions.add_parser("list", help="shipped scenes, one line each")
    listing.add_argument("--json", action="store_true", help="print one JSON object")
    listing.set_defaults(handler=run_list)
    validate = actions.add_parser("validate", help="check scene files (or shipped names)")
    validate.add_argument("scenes", nargs="+", metavar="SCENE", help="name or path to .yaml")
    validate.set_defaults(handler=run_validate)
    explain = actions.add_parser(
        "explain", help="the effects a scene runs, their measured cost and tip change",
        description="Measure each listed effect against the same scene without it, at the "
                    "schedule's top tension.")
    explain.add_argument("scene", metavar="SCENE", help="shipped name or path to .yaml")
    explain.add_argument("--samples", type=int, default=400,
                         help="mocap frames per sensing measurement (default: 400)")
    explain.add_argument("--repeats", type=int, default=5,
                         help="repetitions of each timing, fastest kept (default: 5)")
    explain.add_argument("--json", action="store_true", help="print one JSON object")
    explain.set_defaults(handler=run_explain)
    effects = actions.add_parser("effects", help="every effect: stage, parameters, units")
    effects.add_argument("--json", action="store_true", help="print one JSON object")
    effects.set_defaults(handler=run_effects)


def run_list(args: argparse.Namespace) -> int:
    """Print the shipped scenes with their effects and description."""
    from tdcm_ros.scenes import load_scene, shipped_scenes

    scenes = [load_scene(name) for name in shipped_scenes()]
    if args.json:
        print(json.dumps({s.name: {"description": s.description, "effects": list(s.effects),
                                   "file": str(s.source)} for s in scenes}))
        return 0
    width = max((len(s.name) for s in scenes), default=0)
    for s in scenes:
        effects = ", ".join(s.effects) or "no effects"
        print(f"{s.name.ljust(width)}  {s.description}  [{effects}]")
    return 0


def run_validate(args: argparse.Namespace) -> int:
    """Load each scene; the first invalid one raises (one line, exit status 2)."""
    from tdcm_ros.scenes import load_scene

    for name in args.scenes:
        scene = load_scene(name)
        print(f"{name}: ok ({len(scene.effects)} effects: {', '.join(scene.effects) or 'none'})")
    return 0


def run_explain(args: argparse.Namespace) -> int:
    """Measure and print the table (or JSON)."""
    from tdcm_ros.scenes import explain, format_table, load_scene

    for name, value, low in (("--samples", args.samples, 1), ("--repeats", args.repeats, 1)):
        if not low <= value <= 100000:
            raise out_of_range(name, value, f"integer in [{low}, 100000]")
    report = explain(load_scene(args.scene), samples=args.samples, repeats=args.repeats)
    print(json.dumps(report.to_dict()) if args.json else format_table(report))
    return 0


def run_effects(args: argparse.Namespace) -> int:
    """Print the effect registry: name, stage, summary and parameters."""
    from tdcm_ros.scenes import REGISTRY, param_table

    data: dict[str, dict[str, Any]] = {
        name: {"stage": cls.stage, "summary": cls.summary, "cost_unit": cls.cost_unit,
               "params": param_table(cls.params)} for name, cls in REGISTRY.items()}
    if args.json:
        print(json.dumps(data))
        return 0
    for name, info in data.items():
        print(f"{name} ({info['stage']}): {info['summary']}")
        for row in info["params"]:
            print(f"    {row['name']}: {row['description']}; default {row['default']}; "
                  f"allowed {row['allowed']}")
    return 0
