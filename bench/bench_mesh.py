"""Mesh-body benchmark (issue 27): a body file naming an STL -> the first solve.

Run: ``python bench/bench_mesh.py [--notches 30] [--sides 200] [--repeats 3] [--results FILE]``.
Builds (manifold3d, the test extra) the paper's tube with ``--notches`` tee notches, each the
polygon of ``config/bodies/tee_notches.yaml``, its circles ``--sides``-gons (200: ~50 k
faces at 30 notches), writes it as a binary STL with a body file naming it, and times, in a
fresh process each (numba's compiled kernels loaded from its cache, as on any run after the
first), reading the body file and the first solve at 5 N: with the mesh never seen (an empty
``TDCM_CACHE_DIR``: reading the STL, slicing) and seen before (its slices cached,
:mod:`tdcm_ros.model.file_cache`), and the same for the preset ``paper-experiment`` (the
floor: imports, kernels, grid). Prints the face count, the medians and the target (body file
-> first solve <= 2 s). ``--write FILE``
only writes the STL (e.g. the shipped ``config/bodies/tee_notches.stl``); ``--slanted`` makes
the notches slanted cuts deepening toward the tip (``config/bodies/slanted_wrist.stl``).
``--results FILE`` also writes the printed figures as tables to a results file
(``bench/results.py``; not with ``--write``, which measures nothing).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from results import BenchResults, Column, add_results_argument
from shapely.geometry import Polygon

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from test.support.meshes import body_mesh, slanted_cut_mesh

TEE = Polygon([(-3.5, -1.5), (-2.5, -1.5), (-2.5, -0.3), (0.5, -0.3), (0.5, 0.3), (-2.5, 0.3),
               (-2.5, 1.5), (-3.5, 1.5)])  # mm, as config/bodies/tee_notches.yaml
TIMED = """
import json, sys, time
start = time.perf_counter()
from tdcm_ros.model import named_design, solve
design = named_design(sys.argv[1])
read = time.perf_counter()
result = solve(design, 5.0)
done = time.perf_counter()
print(json.dumps({"read_s": read - start, "total_s": done - start, "N": design.N,
                  "tip_x_m": float(result.positions[-1, 0])}))
"""


def tee_body(notches: int, sides: int) -> object:
    """The paper's tube (mm) with ``notches`` 2 mm tee notches 4 mm apart, 5 mm base tube."""
    segments: list[tuple] = [("tube", 5.0)]
    for k in range(notches):
        segments += [("notch", 2.0, TEE), ("tube", 4.0)]
    return body_mesh(segments, 3.92, 1.55, sides)


def slanted_body(notches: int, sides: int) -> object:
    """The paper's tube (mm) with ``notches`` 2 mm slanted cuts 4 mm apart after a 5 mm base
    tube, each from x = 1 mm at its base face to a depth growing toward the tip (x = -0.5,
    -1, -1.5, ... mm at its tip face): a variable-depth wrist whose notches' sections change
    along them."""
    cuts = [((5.0 + 6.0 * k, 7.0 + 6.0 * k), (1.0, -0.5 - 0.5 * k)) for k in range(notches)]
    return slanted_cut_mesh(3.92, 1.55, 5.0 + 6.0 * notches, cuts, sides)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--notches", type=int, default=30)
    parser.add_argument("--sides", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--write", type=Path, help="only write the STL to this file")
    parser.add_argument("--slanted", action="store_true",
                        help="slanted cuts deepening toward the tip instead of tee notches")
    add_results_argument(parser, "bench_mesh")
    args = parser.parse_args()
    results = BenchResults("bench_mesh")
    mesh = (slanted_body if args.slanted else tee_body)(args.notches, args.sides)
    if args.write:
        mesh.export(str(args.write))
        print(f"wrote {args.write}: {len(mesh.faces)} faces")
        return 0
    with tempfile.TemporaryDirectory() as folder:
        stl = Path(folder) / "body.stl"
        mesh.export(str(stl))
        size = stl.stat().st_size
        body = Path(folder) / "body.yaml"
        body.write_text("material: {E: 1.85e9}\ntendons:\n  - {offset: 2.75e-3}\n"
                        "mesh: {file: body.stl, unit: mm}\n")
        runs: dict[str, list[dict]] = {"cold": [], "warm": [], "preset": []}
        warm_cache = Path(folder) / "warm"
        for repeat in range(args.repeats + 1):  # the first compiles numba's cache if cold
            for case, name, cache in (("cold", str(body), Path(folder) / f"cold{repeat}"),
                                      ("warm", str(body), warm_cache),
                                      ("preset", "paper-experiment", warm_cache)):
                out = subprocess.run([sys.executable, "-c", TIMED, name], cwd=REPO,
                                     env={**os.environ, "TDCM_CACHE_DIR": str(cache)},
                                     capture_output=True, text=True, check=True)
                runs[case].append(json.loads(out.stdout))
    runs = {case: rows[1:] for case, rows in runs.items()}

    def median(case: str, what: str) -> float:
        return float(np.median([r[what] for r in runs[case]]))

    print(f"mesh body: {len(mesh.faces)} faces, {runs['cold'][0]['N']} notches "
          f"({size} bytes); medians of {args.repeats}, a fresh process each")
    print(f"  read body file, mesh not seen     {median('cold', 'read_s'):.3f} s "
          "(imports, reading the STL, slicing)")
    print(f"  body file -> first solve, same    {median('cold', 'total_s'):.3f} s")
    print(f"  read body file, slices cached     {median('warm', 'read_s'):.3f} s "
          "(TDCM_CACHE_DIR: the mesh read before)")
    print(f"  body file -> first solve, same    {median('warm', 'total_s'):.3f} s (target <= 2 s)")
    print(f"  the preset, the same way          {median('preset', 'total_s'):.3f} s "
          "(paper-experiment: imports, kernels, grid)")
    print(f"  tip x at 5 N                      {runs['cold'][0]['tip_x_m'] * 1e3:.4f} mm "
          f"(cached: {runs['warm'][0]['tip_x_m'] * 1e3:.4f} mm)")
    results.table(
        f"Mesh body: {len(mesh.faces)} faces, {runs['cold'][0]['N']} notches",
        [Column("figure"), Column("measured"), Column("unit")],
        [["read body file, mesh not seen (imports, reading the STL, slicing)",
          median("cold", "read_s"), "s"],
         ["body file → first solve, mesh not seen", median("cold", "total_s"), "s"],
         ["read body file, slices cached", median("warm", "read_s"), "s"],
         ["body file → first solve, slices cached (target ≤ 2 s)", median("warm", "total_s"),
          "s"],
         ["the preset paper-experiment, the same way (imports, kernels, grid)",
          median("preset", "total_s"), "s"],
         ["tip x at 5 N", runs["cold"][0]["tip_x_m"] * 1e3, "mm"],
         ["tip x at 5 N, slices cached", runs["warm"][0]["tip_x_m"] * 1e3, "mm"]],
        note=f"{'slanted cuts' if args.slanted else 'tee notches'}, {args.sides}-gon circles, "
             f"STL {size} bytes; medians of {args.repeats}, a fresh process each")
    if args.results:
        results.write(args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
