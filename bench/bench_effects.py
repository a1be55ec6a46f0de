"""Cost of scenes and their effects: ``tdcm scene explain`` for each scene, plus the wall time
of one motion-capture frame (``World.markers``) over a schedule, which the mocap node pays at
the mocap rate.

    python3 bench/bench_effects.py [SCENE ...] [--samples 400] [--repeats 5] [--results FILE]

Prints figures only; nothing is asserted. ``--results FILE`` also writes the printed figures as
tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
from time import perf_counter

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.errors import PhysicsError
from tdcm_ros.scenes import load_scene
from tdcm_ros.scenes.explain import Explanation, explain, format_table
from tdcm_ros.scenes.paths import shipped_scenes


def frame_cost(name: str, frames_per_level: int = 50) -> tuple[float, float, int]:
    """Median and 95th percentile wall time (s) of ``World.markers`` over one trial of the
    scene's schedule (levels held for ``frames_per_level`` frames), and the frames timed."""
    scene = load_scene(name)
    world = scene.world()
    times: list[float] = []
    stamp = 0.0
    for level in scene.schedule.levels:
        for _ in range(frames_per_level):
            started = perf_counter()
            try:
                world.markers(stamp, level)
            except PhysicsError:
                break
            times.append(perf_counter() - started)
            stamp += 1.0 / scene.mocap_rate_hz
    return float(np.median(times)), float(np.percentile(times, 95)), len(times)


def record(report: Explanation, results: BenchResults) -> None:
    """``tdcm scene explain``'s table of one scene as a table of ``results``."""
    tip = ", ".join(f"{v * 1e3:.3f}" for v in report.true_tip_m)
    results.table(
        f"scene {report.scene}: effects at the schedule's top tension {report.top_tension_n:g} N",
        [Column("effect"), Column("stage"), Column("cost", "µs", ".1f"),
         Column("timing noise", "µs", ".2g"), Column("per"), Column("tip change", "mm", ".4f"),
         Column("note")],
        [[row.name, row.stage, row.cost_s * 1e6, None if row.noise_s is None else
          row.noise_s * 1e6, row.cost_unit, None if row.tip_change_m is None else
          row.tip_change_m * 1e3, row.note] for row in report.rows],
        note=f"base solve {report.base_solve_s * 1e3:.2f} ms; true tip (x, y, z) = ({tip}) mm. "
             "Timing noise: for a cost timed as a difference, the noise it is read against (a "
             "cost not above it is below the timing noise)"
             + ("" if report.rows else "; no effects: the world is the paper's base model"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", help="scene names or paths (default: all shipped)")
    parser.add_argument("--samples", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=5)
    add_results_argument(parser, "bench_effects")
    args = parser.parse_args()
    results = BenchResults("bench_effects")
    names = args.scenes or list(shipped_scenes())
    print("World.markers per frame (one trial, 50 frames per level):")
    frames = []
    for name in names:
        median, p95, count = frame_cost(name)
        print(f"  {name:20s} median {median * 1e6:8.1f} us  p95 {p95 * 1e6:8.1f} us  "
              f"({count} frames)")
        frames.append([name, median * 1e6, p95 * 1e6, count])
    results.table("World.markers per frame (one trial, 50 frames per level)",
                  [Column("scene"), Column("median", "µs", ".1f"), Column("p95", "µs", ".1f"),
                   Column("frames")], frames)
    for name in names:
        print()
        report = explain(load_scene(name), samples=args.samples, repeats=args.repeats)
        print(format_table(report))
        record(report, results)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
