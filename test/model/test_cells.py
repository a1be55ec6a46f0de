"""Cells laid out straight from the grid parts equal the stacked single-design grids, and a
grid's named kernel fields are the grid kernel's outputs of its cells (read here by plain
indexing of the prototype cells' integrals, not by the compiled gather)."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tdcm_ros.model import SolverSettings, grid_kernel, preset
from tdcm_ros.model.cells import FC_FIELDS, FC_NAMES, FQ_FIELDS, FQ_NAMES
from tdcm_ros.model.design import MM
from tdcm_ros.model.design_space import couple
from tdcm_ros.model.grid import build_grid, grid_parts
from test.support.cells import stack_cells

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
        laid = parts.cells(rows)
        single = stack_cells([build_grid(designs[r], cfg).cells for r in rows])
        stacked = parts.stack(rows).cells
        # stack_cells pads the notches of a design with fewer with -1, the grid stack with
        # the tip node: both are never read as closed. Compare the stack's convention.
        single_notch = np.where(single.notch < 0, count, single.notch)
        for name in FIELDS:
            for other in (single, stacked):
                a, b = getattr(laid, name), getattr(other, name)
                if other is single and name == "notch":
                    b = single_notch
                assert a.dtype == b.dtype and a.shape == b.shape, name
                assert a.tobytes() == b.tobytes(), name


@settings(max_examples=10, suppress_health_check=[HealthCheck.too_slow])
@given(designs=st.lists(paper_family, min_size=1, max_size=4),
       routing=st.sampled_from(["paper", "free"]))
def test_a_grids_named_kernel_fields_are_its_cells_integrals(designs, routing):
    parts = grid_parts(designs, SolverSettings(routing=routing))
    rows = np.arange(len(designs))
    stack = parts.stack(rows)
    cell, proto, valid = parts.cells_of(rows)
    table = parts.table
    for name, column in zip(FC_NAMES, FC_FIELDS, strict=True):
        assert getattr(stack, name).tobytes() == parts.proto_fc[proto, column].tobytes(), name
    for name, row in zip(FQ_NAMES[:-1], FQ_FIELDS, strict=True):
        assert getattr(stack, name).tobytes() == parts.proto_fq[proto, row].tobytes(), name
    assert FQ_NAMES[-1] == "W_A" and not np.any(stack.W_A)  # a rigid midline's shortening
    constrained = np.where(valid, table.constrained[cell], True)
    assert stack.constrained.dtype == np.bool_
    np.testing.assert_array_equal(stack.constrained, constrained)
    for m, design in enumerate(designs):
        grid = stack.grid(m)
        n = int(table.count[m])
        assert grid.r_c == design.R_c and grid.C0.shape == (n,)
        np.testing.assert_array_equal(grid.w_q, parts.proto_fq[proto[m, :n], grid_kernel.W_Q])
        np.testing.assert_array_equal(grid.chord_start_node, table.chord_start_node[cell[m, :n]])
        np.testing.assert_array_equal(grid.notch_left_node,
                                      table.notch_left_node[m, :design.N])
        np.testing.assert_array_equal(grid.notch_open, design.open_faces())
        assert grid.constrained_peak_c == stack.cells.constrained_peak_c[m]
