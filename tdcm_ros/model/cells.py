"""The kernel's arrays of grids with a leading member axis: :mod:`tdcm_ros.model.kernel` reads
them, and :class:`~tdcm_ros.model.grid.Grid` and :class:`~tdcm_ros.model.grid.GridStack` hold
their kernel fields in them (one copy of each number: a grid's ``C0`` is a view of its
:attr:`Cells.fc`).

:class:`Cells` holds one grid (one member) or a stack of grids; it has the fields of
:class:`~tdcm_ros.model.grid.Grid` the kernels read (``C0``, ``C1``, ``A0``, ``A1``, ``w_q``,
the chord terms ``C0_T``, ``C1_T``, ``A0_T``, ``A1_T``, the off-axis centroid's ``xbar_start``,
``xbar_end``, ``D``, ``K0``, ``K1``, ``D_q``, ``K2``, ``chord_start_node``, ``chord_end_node``,
``constrained``, ``notch_left_node``, ``notch_right_node``, ``notch_open``), each with the
member axis first (:data:`FC_NAMES`, :data:`FQ_NAMES`, :data:`IC_NAMES`, :data:`NOTCH_NAMES`
name their rows). Grids of different cell or notch counts stack by padding with zero-length
cells at the tip (they move no node) and with notches marked -1 (never checked).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model import grid_kernel

Array = NDArray[np.float64]
Ints = NDArray[np.int64]


@dataclass(frozen=True, eq=False)
class Cells:
    """Packed cell arrays of ``members`` grids (layout in :mod:`tdcm_ros.model.kernel`)."""

    fc: Array
    fq: Array
    ic: Ints
    notch: Ints
    scal: Array

    @property
    def members(self) -> int:
        """Number of members."""
        return int(self.fc.shape[0])

    @property
    def n_cells(self) -> int:
        """Cells per member (padding included)."""
        return int(self.fc.shape[2])

    @property
    def r_c(self) -> Array:
        """Tendon offset ``R_c`` (m) per member."""
        return self.scal[:, 0]

    @property
    def r_outer(self) -> Array:
        """Outer radius (m) per member."""
        return self.scal[:, 1]

    @property
    def length(self) -> Array:
        """Body length (m) per member."""
        return self.scal[:, 2]

    @property
    def constrained_peak_c(self) -> Array:
        """Largest compliance (1/(N m^2)) where the tendon follows the body, per member."""
        return self.scal[:, 3]


FC_NAMES = ("C0", "C1", "C0_T", "C1_T", "xbar_start", "xbar_end", "D")
"""Rows of :attr:`Cells.fc` (members, rows, cells): per cell, :mod:`tdcm_ros.model.grid`'s names."""
FQ_NAMES = ("A0", "A1", "w_q", "A0_T", "A1_T", "K0", "K1", "D_q", "K2", "W_A")
"""Rows of :attr:`Cells.fq` (members, rows, cells, Gauss points); the last, ``W_A``
(``w_q / (E A)``, m/N: each Gauss point's shortening per newton of axial load), is zero
unless the midline is compressible (:class:`~tdcm_ros.model.settings.SolverSettings`'s
``axial``) and is not one of the grid kernel's outputs."""
IC_NAMES = ("chord_start_node", "chord_end_node", "constrained")
"""Rows of :attr:`Cells.ic` (members, rows, cells); ``constrained`` as 0/1."""
NOTCH_NAMES = ("notch_left_node", "notch_right_node", "notch_open")
"""Rows of :attr:`Cells.notch` (members, 4, notches): each notch's first and last node, then
(two rows, ``notch_open``) whether its faces can meet on the +x and on the -x side
(:meth:`~tdcm_ros.model.design.Design.open_faces`)."""
FC_FIELDS = np.array([grid_kernel.C0, grid_kernel.C1, grid_kernel.C0_T, grid_kernel.C1_T,
                      grid_kernel.XB_START, grid_kernel.XB_END, grid_kernel.D_CELL])
"""The grid kernel's per-cell columns of :data:`FC_NAMES`, in order."""
FQ_FIELDS = np.array([grid_kernel.A0, grid_kernel.A1, grid_kernel.W_Q, grid_kernel.A0_T,
                      grid_kernel.A1_T, grid_kernel.K0, grid_kernel.K1, grid_kernel.D_Q,
                      grid_kernel.K2])
"""The grid kernel's per-Gauss-point rows of :data:`FQ_NAMES` but the last, in order."""
FC_ROWS, FQ_ROWS = FC_FIELDS.size, FQ_FIELDS.size + 1
W_A_ROW = FQ_ROWS - 1
NOTCH_ROWS = 4
