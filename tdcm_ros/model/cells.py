"""Grids with a leading member axis, packed for :mod:`tdcm_ros.model.kernel`.

:class:`Cells` holds one grid (one member) or a stack of grids; it has the fields of
:class:`~tdcm_ros.model.grid.Grid` the kernels read (``C0``, ``C1``, ``A0``, ``A1``, ``w_q``,
the chord terms ``C0_T``, ``C1_T``, ``A0_T``, ``A1_T``, the off-axis centroid's ``xbar_start``,
``xbar_end``, ``K0``, ``K1``, ``chord_start_node``, ``chord_end_node``, ``constrained``, ``notch_left_node``,
``notch_right_node``, ``notch_open``), each with the member axis first. Grids of different cell or notch
counts stack by padding with zero-length cells at the tip (they move no node) and with
notches marked -1 (never checked).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model import grid_kernel
from tdcm_ros.model.compiled import grid_kernels
from tdcm_ros.model.grid import CellArrays, Grid, GridParts, GridStack, arm_weighted

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

    @classmethod
    def of(cls, grid: Grid) -> Cells:
        """The one-member cells of ``grid`` (cached per grid)."""
        return _cells_of(grid)

    @classmethod
    def stack(cls, grids: Sequence[Grid]) -> Cells:
        """Members = ``grids``, padded to the largest cell and notch counts."""
        parts = [cls.of(g) for g in grids]
        n = max(c.n_cells for c in parts)
        k = max(c.notch.shape[2] for c in parts)
        q = max(c.fq.shape[3] for c in parts)
        fc = np.zeros((len(parts), FC_ROWS, n))
        fq = np.zeros((len(parts), FQ_ROWS, n, q))
        ic = np.zeros((len(parts), 3, n), np.int64)
        ic[:, 2] = 1
        notch = np.full((len(parts), NOTCH_ROWS, k), -1, np.int64)
        notch[:, 2:] = 0  # a padding notch has no nodes (-1) and no side to close
        for j, c in enumerate(parts):
            cells, notches, points = c.n_cells, c.notch.shape[2], c.fq.shape[3]
            fc[j, :, :cells] = c.fc[0]
            fq[j, :, :cells, :points] = c.fq[0]
            ic[j, :, :cells] = c.ic[0]
            notch[j, :, :notches] = c.notch[0]
        return cls(fc=fc, fq=fq, ic=ic, notch=notch,
                   scal=np.concatenate([c.scal for c in parts]))

    @classmethod
    def of_stack(cls, stack: GridStack) -> Cells:
        """Members = the designs of a :func:`~tdcm_ros.model.grid.build_grids` stack (its
        zero-length padding cells and tip-node padding notches are neutral here too)."""
        r_c = np.array([d.R_c for d in stack.designs])
        peak = np.where(stack.constrained & (stack.length > 0.0), arm_weighted(
            stack.peak_c, stack.xbar_start, stack.xbar_end, r_c[:, None]), 0.0)
        return _packed(stack, lambda values: values, np.stack(
            [r_c,
             np.array([d.R_outer for d in stack.designs]),
             np.array([d.length for d in stack.designs]),
             np.max(peak, axis=1, initial=0.0)], axis=1))

    @classmethod
    def of_parts(cls, parts: GridParts, rows: Ints) -> Cells:
        """Members = designs ``rows`` of ``parts``, laid out straight from their prototype
        cells (the same values as :meth:`of_stack` of ``parts.stack(rows)``, without the
        stack's other arrays)."""
        cell, proto, valid = parts.cells_of(rows)
        table, members = parts.table, parts.members
        build = grid_kernels()
        fc = np.empty((rows.size, FC_ROWS, cell.shape[1], 1))
        build.gather(proto, _FC_FIELDS, parts.proto_fc[..., None], fc)
        fq = np.empty((rows.size, FQ_ROWS, cell.shape[1], parts.gauss_u.size))
        build.gather(proto, _FQ_FIELDS, parts.proto_fq, fq)
        tip = table.count[rows][:, None]
        constrained = np.where(valid, table.constrained[cell], True)
        ic = np.stack([np.where(valid, table.chord_start_node[cell], tip),
                       np.where(valid, table.chord_end_node[cell], tip),
                       constrained], axis=1).astype(np.int64)
        notches = int(members.N[rows].max())
        fc_of = parts.proto_fc[proto]
        peak = np.where(constrained, arm_weighted(
            fc_of[..., grid_kernel.PEAK_C], fc_of[..., grid_kernel.XB_START],
            fc_of[..., grid_kernel.XB_END], members.R_c[rows][:, None]), 0.0)
        scal = np.stack([members.R_c[rows], members.R_outer[rows], members.length[rows],
                         np.max(peak, axis=1, initial=0.0)], axis=1)
        return cls(fc=fc[..., 0], fq=fq, ic=ic,
                   notch=np.concatenate([np.stack([table.notch_left_node[rows, :notches],
                                                   table.notch_right_node[rows, :notches]],
                                                  axis=1),
                                         members.notch_open[rows][:, :, :notches]], axis=1),
                   scal=scal)

    def take(self, rows: Ints) -> Cells:
        """The members ``rows`` (repeats allowed)."""
        return Cells(fc=self.fc[rows], fq=self.fq[rows], ic=self.ic[rows],
                     notch=self.notch[rows], scal=self.scal[rows])

    @property
    def members(self) -> int:
        """Number of members."""
        return int(self.fc.shape[0])

    @property
    def n_cells(self) -> int:
        """Cells per member (padding included)."""
        return int(self.fc.shape[2])

    @property
    def C0(self) -> Array:
        """``int (1 - xi) c ds`` per cell (rad/(N m)), (members, cells)."""
        return self.fc[:, 0]

    @property
    def C1(self) -> Array:
        """``int xi c ds`` per cell (rad/(N m)), (members, cells)."""
        return self.fc[:, 1]

    @property
    def A0(self) -> Array:
        """``A0`` at the Gauss points (rad/(N m)), (members, cells, points)."""
        return self.fq[:, 0]

    @property
    def A1(self) -> Array:
        """``A1`` at the Gauss points (rad/(N m)), (members, cells, points)."""
        return self.fq[:, 1]

    @property
    def w_q(self) -> Array:
        """ds weights of the Gauss points (m), (members, cells, points)."""
        return self.fq[:, 2]

    @property
    def C0_T(self) -> Array:
        """Chord term of ``C0`` per newton of tension (rad/(N^2 m)), (members, cells)."""
        return self.fc[:, 2]

    @property
    def C1_T(self) -> Array:
        """Chord term of ``C1`` per newton of tension (rad/(N^2 m)), (members, cells)."""
        return self.fc[:, 3]

    @property
    def A0_T(self) -> Array:
        """Chord term of ``A0`` at the Gauss points (rad/(N^2 m)), (members, cells, points)."""
        return self.fq[:, 3]

    @property
    def A1_T(self) -> Array:
        """Chord term of ``A1`` at the Gauss points (rad/(N^2 m)), (members, cells, points)."""
        return self.fq[:, 4]

    @property
    def chord_start_node(self) -> Ints:
        """First node of each cell's tendon run, (members, cells)."""
        return self.ic[:, 0]

    @property
    def chord_end_node(self) -> Ints:
        """Last node of each cell's tendon run, (members, cells)."""
        return self.ic[:, 1]

    @property
    def constrained(self) -> NDArray[np.bool_]:
        """Cells where the tendon follows the offset curve, (members, cells)."""
        return self.ic[:, 2] != 0

    @property
    def notch_left_node(self) -> Ints:
        """Node at each notch's start (-1: padding), (members, notches)."""
        return self.notch[:, 0]

    @property
    def notch_right_node(self) -> Ints:
        """Node at each notch's end (-1: padding), (members, notches)."""
        return self.notch[:, 1]

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


_FC_NAMES = ("C0", "C1", "C0_T", "C1_T", "xbar_start", "xbar_end", "D")
_FQ_NAMES = ("A0", "A1", "w_q", "A0_T", "A1_T", "K0", "K1", "D_q", "K2")
_FC_FIELDS = np.array([grid_kernel.C0, grid_kernel.C1, grid_kernel.C0_T, grid_kernel.C1_T,
                       grid_kernel.XB_START, grid_kernel.XB_END, grid_kernel.D_CELL])
_FQ_FIELDS = np.array([grid_kernel.A0, grid_kernel.A1, grid_kernel.W_Q, grid_kernel.A0_T,
                       grid_kernel.A1_T, grid_kernel.K0, grid_kernel.K1, grid_kernel.D_Q,
                       grid_kernel.K2])
#: Rows of :attr:`Cells.fc` and :attr:`Cells.fq` (the kernel's layout).
FC_ROWS, FQ_ROWS = _FC_FIELDS.size, _FQ_FIELDS.size
#: Rows of :attr:`Cells.notch`: each notch's first and last node, then whether its faces can
#: meet on the +x and on the -x side (:meth:`~tdcm_ros.model.design.Design.open_faces`).
NOTCH_ROWS = 4


@lru_cache(maxsize=512)
def _cells_of(grid: Grid) -> Cells:
    d = grid.design
    return _packed(grid, lambda values: values[None],
                   np.array([[d.R_c, d.R_outer, d.length, grid.constrained_peak_c]]))


def _packed(grids: CellArrays, member_axis: Callable[[NDArray[Any]], NDArray[Any]],
            scal: Array) -> Cells:
    """The kernel layout of ``grids``' arrays; ``member_axis`` gives each its leading member
    axis (a stack has it already, one grid gets one of length 1)."""
    def packed(*names: str) -> NDArray[Any]:
        return np.ascontiguousarray(np.stack(
            [member_axis(getattr(grids, name)) for name in names], axis=1))

    return Cells(fc=packed(*_FC_NAMES), fq=packed(*_FQ_NAMES),
                 ic=packed("chord_start_node", "chord_end_node", "constrained").astype(np.int64),
                 notch=np.concatenate([packed("notch_left_node", "notch_right_node"),
                                       member_axis(grids.notch_open)], axis=1).astype(np.int64),
                 scal=scal)
