"""Shape-design benchmark (issue 30): each problem file of ``config/design`` searched on one
core, with several seeds.

Run: ``python bench/bench_shape_design.py [--seeds 5] [--workers 1] [--results FILE] [FILE ...]``.

Printed per problem and seed: CPU seconds of the process (``process_time``) and wall seconds
of the search, generations, evaluations, whether every target is met, and what the design
achieves (tip angle in degrees, each notch-angle target's spread from the mean and
distal/proximal ratio, the peak strain); then the median and range over the seeds. Then the
STL round trip of each problem's design and of the paper's preset: the design exported
(``write_body_stl``, mm), read back through its body file (the mesh path), solved at the
problem's first load, and the tip's distance from the design's own tip over the tip's
displacement. Warm: the kernels are compiled and loaded before timing. ``--results FILE`` also
writes the printed figures as tables to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import (
    Capstan,
    Design,
    Loading,
    NoShapeDesignError,
    NotchAngleTarget,
    ShapeDesign,
    design_for_shape,
    mesh_body_file_text,
    named_design,
    preset,
    read_problem_file,
    solve,
    warm_up,
    write_body_stl,
)

PROBLEMS = sorted((Path(__file__).resolve().parents[1] / "config" / "design").glob("*.yaml"))


def describe(found: ShapeDesign) -> str:
    parts = []
    for goal in found.problem.goals:
        result = found.evaluation.results.get(goal.load)
        if result is None:
            continue
        if isinstance(goal.target, NotchAngleTarget):
            phi = result.notch_angles_rad
            spread = float(np.max(np.abs(phi / phi.mean() - 1.0)))
            parts.append(f"notch spread {spread * 100:.3f} %, ratio {phi[-1] / phi[0]:.3f}")
        else:
            parts.append(f"tip {math.degrees(result.tip_angle_rad):.4f} deg")
    strains = [float(np.max(r.notch_peak_strains)) for r in found.evaluation.results.values()]
    if strains:
        parts.append(f"peak strain {max(strains) * 100:.3f} %")
    return "; ".join(parts)


def round_trip(design: Design, tension: float, mu: float = 0.0) -> float:
    """The exported STL's tip error over the tip displacement (see the module docstring)."""
    loading = Loading(tension_profile=Capstan(mu)) if mu else None
    with tempfile.TemporaryDirectory() as folder:
        write_body_stl(design, Path(folder) / "body.stl")
        body = Path(folder) / "body.yaml"
        body.write_text(mesh_body_file_text(design, "body.stl"))
        meshed = solve(named_design(str(body)), tension, loading=loading)
    own = solve(design, tension, loading=loading)
    return float(np.linalg.norm(meshed.tip_position - own.tip_position)
                 / np.linalg.norm(own.tip_position - [0.0, 0.0, design.length]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*", type=Path, default=PROBLEMS)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--workers", type=int, default=1)
    add_results_argument(parser, "bench_shape_design")
    args = parser.parse_args()
    results = BenchResults("bench_shape_design")
    warm_up()
    seeds: list[list[object]] = []
    medians: list[list[object]] = []
    trips: list[list[object]] = []
    for path in args.files:
        problem = read_problem_file(path)
        cpu, wall = [], []
        print(f"{path.name}: {problem.problem.variables.size} variables")
        for seed in range(args.seeds):
            started_cpu, started = time.process_time(), time.perf_counter()
            try:
                found = design_for_shape(problem.problem, seed=seed,
                                         popsize=problem.search.popsize,
                                         maxiter=problem.search.maxiter, workers=args.workers)
            except NoShapeDesignError as error:
                found = error.found
            cpu.append(time.process_time() - started_cpu)
            wall.append(time.perf_counter() - started)
            print(f"  seed {seed}: {cpu[-1]:.2f} CPU s, {wall[-1]:.2f} s wall, "
                  f"{found.generations} generations, {found.evaluations} evaluations, "
                  f"met {found.evaluation.met}; {describe(found)}")
            seeds.append([path.name, seed, cpu[-1], wall[-1], found.generations,
                          found.evaluations, found.evaluation.met, describe(found)])
        print(f"  median {statistics.median(cpu):.2f} CPU s (range {min(cpu):.2f}-{max(cpu):.2f}),"
              f" wall {statistics.median(wall):.2f} s (range {min(wall):.2f}-{max(wall):.2f})")
        medians.append([path.name, problem.problem.variables.size, statistics.median(cpu),
                        min(cpu), max(cpu), statistics.median(wall), min(wall), max(wall)])
        load = problem.problem.loads[0]
        if found.design is not None and load.tension is not None:
            error = round_trip(found.design, load.tension, load.mu)
            print(f"  STL round trip of the last design at {load.label}: tip error "
                  f"{error:.2e} of its displacement")
            trips.append([f"{path.name}, the last seed's design", load.label, error])
    error = round_trip(preset("paper-experiment"), 20.0)
    print("STL round trip of paper-experiment at 20 N: tip error "
          f"{error:.2e} of its displacement")
    trips.append(["paper-experiment (preset)", "20 N", error])
    seconds = [Column("CPU", "s", ".2f"), Column("wall", "s", ".2f")]
    results.table(
        "Each problem and seed",
        [Column("problem"), Column("seed"), *seconds, Column("generations"),
         Column("evaluations"), Column("met"), Column("achieved")], seeds,
        note="achieved: the tip angle, each notch-angle target's spread from the mean and "
             "distal/proximal ratio, the peak strain")
    results.table(
        f"Median over {args.seeds} seeds",
        [Column("problem"), Column("variables"), Column("CPU", "s", ".2f"),
         Column("min", "s", ".2f"), Column("max", "s", ".2f"), Column("wall", "s", ".2f"),
         Column("min", "s", ".2f"), Column("max", "s", ".2f")], medians)
    results.table(
        "STL round trip: exported, read back through its body file, solved",
        [Column("design"), Column("load"),
         Column("tip error / tip displacement", format=".1e")], trips)
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
