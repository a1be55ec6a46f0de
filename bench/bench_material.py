"""Material laws (issue 28): what the bilinear law costs per solve, against the linear law.

Run: ``python bench/bench_material.py [--repeats 30] [--results FILE]``. Prints interleaved
medians (one process, warm caches) of solves of the same bodies under the linear law and under
the bilinear law past its plateau: the paper's body at 20 N with a plateau from 1 % strain at
8 % of E, ``config/bodies/nitinol_wrist.yaml`` at 1.5 N and
``config/bodies/nitinol_polygon_wrist.yaml`` at 6 N (the polygon integral), each as a ratio to
its linear solve. The law's curvature is found per cell end in NumPy (false position with
Illinois's rule, :class:`~tdcm_ros.model.material_model.MaterialLaw`). Single-threaded: BLAS
threads are pinned before NumPy. ``--results FILE`` also writes the printed figures as tables
to a results file (``bench/results.py``).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from bench_tendons import interleaved
from results import BenchResults, Column, add_results_argument

from tdcm_ros.model import SolverSettings, preset, read_body_file
from tdcm_ros.model.material import Material

BODIES = Path(__file__).resolve().parents[1] / "config" / "bodies"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30)
    add_results_argument(parser, "bench_material")
    args = parser.parse_args()
    results = BenchResults("bench_material")
    paper = preset("paper-experiment")
    bodies = {
        "paper body, 20 N": (dataclasses.replace(paper, material=Material(
            "bilinear", 0.01, 0.08 * paper.E)), 20.0),
        "nitinol_wrist, 1.5 N": (read_body_file(BODIES / "nitinol_wrist.yaml").design(), 1.5),
        "nitinol_polygon_wrist, 6 N": (
            read_body_file(BODIES / "nitinol_polygon_wrist.yaml").design(), 6.0),
    }
    default = SolverSettings()
    cases = {}
    for name, (design, tension) in bodies.items():
        cases[f"{name}, linear"] = (dataclasses.replace(design, material=Material()), tension,
                                    default)
        cases[f"{name}, bilinear"] = (design, tension, default)
    medians = interleaved(cases, args.repeats)
    print("solve time, interleaved medians (one process)")
    rows = []
    for name in bodies:
        linear, law = medians[f"{name}, linear"], medians[f"{name}, bilinear"]
        print(f"  {name:28s} linear {linear * 1e3:8.3f} ms  bilinear {law * 1e3:8.3f} ms  "
              f"{law / linear:8.1f}x")
        rows.append([name, linear * 1e3, law * 1e3, law / linear])
    results.table(
        "Solve time, interleaved medians (one process)",
        [Column("body"), Column("linear law", "ms", ".3f"), Column("bilinear law", "ms", ".3f"),
         Column("× linear", format=".1f")], rows,
        note=f"{args.repeats} solves per case, warm caches; the paper body's bilinear law: a "
             "plateau from 1 % strain at 8 % of E; the linear case: the same body and tension "
             "under the linear law")
    if args.results:
        results.write(args.results)


if __name__ == "__main__":
    main()
