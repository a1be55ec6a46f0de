"""Cost of scenes and their effects: ``tdcm scene explain`` for each scene, plus the wall time
of one motion-capture frame (``World.markers``) over a schedule, which the mocap node pays at
the mocap rate.

    python3 bench/bench_effects.py [SCENE ...] [--samples 400] [--repeats 5]

Prints figures only; nothing is asserted.
"""

from __future__ import annotations

import argparse
from time import perf_counter

import numpy as np

from tdcm_ros.errors import PhysicsError
from tdcm_ros.scenes import load_scene
from tdcm_ros.scenes.explain import explain, format_table
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", help="scene names or paths (default: all shipped)")
    parser.add_argument("--samples", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    names = args.scenes or list(shipped_scenes())
    print("World.markers per frame (one trial, 50 frames per level):")
    for name in names:
        median, p95, count = frame_cost(name)
        print(f"  {name:20s} median {median * 1e6:8.1f} us  p95 {p95 * 1e6:8.1f} us  "
              f"({count} frames)")
    for name in names:
        print()
        print(format_table(explain(load_scene(name), samples=args.samples,
                                   repeats=args.repeats)))


if __name__ == "__main__":
    main()
