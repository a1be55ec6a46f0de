"""Grid building for many different designs: ``build_grids`` (numpy over the member axis)
against one ``build_grid`` per design, in the same run (issue 15, item 3).

Run: ``python bench/bench_grids.py [--designs 2000] [--repeat 3]``. Designs are paper-like
(``w_n``, ``w_d`` drawn around the paper's), every one different, so no cache helps; the
grid cache is cleared before each single-design pass. Single-threaded.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from tdcm_ros.model import SolverSettings, preset
from tdcm_ros.model.design import MM
from tdcm_ros.model.grid import _build_grid, build_grid, build_grids


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    base = preset("paper-experiment")
    designs = [base.with_overrides(w_n=float(rng.uniform(1.0, 2.5)) * MM,
                                   w_d=float(rng.uniform(1.2, 2.0)) * MM)
               for _ in range(args.designs)]
    for label, settings in (("default (adaptive), paper", SolverSettings()),
                            ("default (adaptive), free", SolverSettings(routing="free")),
                            ("uniform cpn=4 cpt=1 q=4", SolverSettings(
                                grid="uniform", cells_per_notch=4, cells_per_tube=1,
                                quad_order=4))):
        stacked, single = [], []
        for _ in range(args.repeat):
            start = time.perf_counter()
            stack = build_grids(designs, settings)
            stacked.append(time.perf_counter() - start)
            _build_grid.cache_clear()
            start = time.perf_counter()
            for design in designs:
                build_grid(design, settings)
            single.append(time.perf_counter() - start)
        fast, slow = min(stacked), min(single)
        print(f"{label:<28} cells/design {stack.n_cells.mean():6.1f}  build_grids "
              f"{args.designs / fast:9.0f} grids/s ({fast / args.designs * 1e6:6.1f} us)  "
              f"build_grid loop {args.designs / slow:7.0f} grids/s  ratio {slow / fast:5.1f}x")


if __name__ == "__main__":
    main()
