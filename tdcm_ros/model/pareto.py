"""The Pareto set of points with several objectives, all minimised."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import InputError

BLOCK = 256
"""Candidates compared at once (a ``BLOCK x front`` comparison per step)."""


def non_dominated(objectives: ArrayLike) -> NDArray[np.int64]:
    """Indices (ascending) of the rows of ``objectives`` (points x objectives, finite, each
    minimised) that no other row dominates: no other row is ``<=`` in every objective and
    ``<`` in one. Equal rows do not dominate each other, so duplicates are all kept.

    Rows are visited in lexicographic order, in which a row can only be dominated by rows
    before it; each block of rows is checked against the front so far and against itself
    (a row dominated by a dominated row is also dominated by a front row).
    """
    points = np.asarray(objectives, dtype=float)
    if points.ndim != 2:
        raise InputError(f"objectives of shape {points.shape} are not 2-D; allowed: (points, "
                         "objectives)", parameter="objectives", value=points.shape,
                         allowed="2-D (points, objectives)")
    if not np.all(np.isfinite(points)):
        raise InputError("objectives are not all finite; allowed: finite numbers",
                         parameter="objectives", value="NaN or inf", allowed="finite numbers")
    order = np.lexsort(points.T[::-1])
    ordered = points[order]
    front = np.empty((0, points.shape[1]))
    kept: list[NDArray[np.int64]] = []
    for start in range(0, ordered.shape[0], BLOCK):
        block = ordered[start:start + BLOCK]
        alive = ~_dominated_by(block, front)
        alive &= ~_dominated_by(block, block)
        front = np.concatenate([front, block[alive]])
        kept.append(order[start:start + BLOCK][alive])
    return np.sort(np.concatenate(kept)) if kept else np.empty(0, np.int64)


def _dominated_by(points: NDArray[np.float64], others: NDArray[np.float64]
                  ) -> NDArray[np.bool_]:
    """Whether each of ``points`` is dominated by one of ``others``."""
    if others.shape[0] == 0:
        return np.zeros(points.shape[0], bool)
    no_worse = np.all(others[None, :, :] <= points[:, None, :], axis=2)
    better = np.any(others[None, :, :] < points[:, None, :], axis=2)
    return np.any(no_worse & better, axis=1)
