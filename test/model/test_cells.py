"""Cells laid out straight from the grid parts equal the stacked single-design grids."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tdcm_ros.model import SolverSettings, preset
from tdcm_ros.model.cells import Cells
from tdcm_ros.model.design import MM
from tdcm_ros.model.design_space import couple
from tdcm_ros.model.grid import build_grid, grid_parts

FIELDS = ("fc", "fq", "ic", "notch", "scal")

paper_family = st.builds(
    lambda n, w_n, w_d, pitch: couple(preset("fig2-wn-1.9").with_overrides(
        N=n, w_n=w_n * MM, w_d=w_d * MM), "fixed-pitch", pitch * MM),
    st.integers(1, 16), st.floats(0.5, 2.5), st.floats(0.6, 3.0), st.floats(3.0, 8.0))


@settings(max_examples=20, suppress_health_check=[HealthCheck.too_slow])
@given(designs=st.lists(paper_family, min_size=1, max_size=8),
       routing=st.sampled_from(["paper", "free"]), quad_order=st.integers(2, 8))
def test_cells_of_parts_equal_the_single_grids_stacked_bit_for_bit(designs, routing,
                                                                  quad_order):
    cfg = SolverSettings(routing=routing, quad_order=quad_order)
    parts = grid_parts(designs, cfg)
    counts = parts.table.count
    for count in np.unique(counts):
        rows = np.flatnonzero(counts == count)
        laid = Cells.of_parts(parts, rows)
        single = Cells.stack([build_grid(designs[r], cfg) for r in rows])
        stacked = Cells.of_stack(parts.stack(rows))
        # Cells.stack pads the notches of a design with fewer with -1, the grid stack with
        # the tip node: both are never read as closed. Compare the stack's convention.
        single_notch = np.where(single.notch < 0, count, single.notch)
        for name in FIELDS:
            for other in (single, stacked):
                a, b = getattr(laid, name), getattr(other, name)
                if other is single and name == "notch":
                    b = single_notch
                assert a.dtype == b.dtype and a.shape == b.shape, name
                assert a.tobytes() == b.tobytes(), name
