"""Single grids' kernel arrays stacked member by member, padded by hand: the reference that
the package's many-design layout (:meth:`tdcm_ros.model.grid.GridParts.cells`) is checked
against."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tdcm_ros.model.cells import FC_ROWS, FQ_ROWS, NOTCH_ROWS, Cells


def stack_cells(parts: Sequence[Cells]) -> Cells:
    """Members = the one member of each of ``parts`` (single grids' ``cells``), padded to the
    largest cell and notch counts: zero cells, chord nodes 0 and constrained, notches -1 with
    no side to close."""
    n = max(c.n_cells for c in parts)
    k = max(c.notch.shape[2] for c in parts)
    q = max(c.fq.shape[3] for c in parts)
    fc = np.zeros((len(parts), FC_ROWS, n))
    fq = np.zeros((len(parts), FQ_ROWS, n, q))
    ic = np.zeros((len(parts), 3, n), np.int64)
    ic[:, 2] = 1
    notch = np.full((len(parts), NOTCH_ROWS, k), -1, np.int64)
    notch[:, 2:] = 0
    for j, c in enumerate(parts):
        cells, notches, points = c.n_cells, c.notch.shape[2], c.fq.shape[3]
        fc[j, :, :cells] = c.fc[0]
        fq[j, :, :cells, :points] = c.fq[0]
        ic[j, :, :cells] = c.ic[0]
        notch[j, :, :notches] = c.notch[0]
    return Cells(fc=fc, fq=fq, ic=ic, notch=notch, scal=np.concatenate([c.scal for c in parts]))
