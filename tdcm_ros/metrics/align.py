"""Time alignment: the nearest stamp within a tolerance (the association evo uses)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range


def nearest_within(query_s: ArrayLike, reference_s: ArrayLike, tolerance_s: float
                   ) -> NDArray[np.int64]:
    """For each query stamp (s), the index of the nearest reference stamp (ascending, s), or -1
    when none lies within ``tolerance_s`` (s, >= 0). Ties go to the earlier reference."""
    if not (np.isfinite(tolerance_s) and tolerance_s >= 0.0):
        raise out_of_range("tolerance_s", tolerance_s, "[0, inf)", unit="s")
    q = np.asarray(query_s, dtype=float)
    ref = np.asarray(reference_s, dtype=float)
    if ref.size == 0:
        return np.full(q.shape, -1, dtype=np.int64)
    right = np.clip(np.searchsorted(ref, q, side="left"), 0, ref.size - 1)
    left = np.clip(right - 1, 0, ref.size - 1)
    take_left = np.abs(q - ref[left]) <= np.abs(ref[right] - q)
    best = np.where(take_left, left, right)
    return np.where(np.abs(ref[best] - q) <= tolerance_s, best, -1).astype(np.int64)


def on_first_stamps(stamps_s: Sequence[ArrayLike], values: Sequence[ArrayLike],
                    tolerance_s: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Several sampled series (each stamps ascending, s, and values) on the stamps of the first:
    each of its samples takes every other series' nearest sample within ``tolerance_s`` (s,
    :func:`nearest_within`); a sample some series has none for is left out. Returns the stamps
    kept (m,) s and the values (m, series)."""
    first = np.asarray(stamps_s[0], dtype=float)
    index = [nearest_within(first, t, tolerance_s) for t in stamps_s[1:]]
    keep = np.all([i >= 0 for i in index], axis=0) if index else np.ones(first.size, bool)
    columns = [np.asarray(values[0], dtype=float)[keep],
               *(np.asarray(v, dtype=float)[i[keep]] for v, i in zip(values[1:], index,
                                                                      strict=True))]
    return first[keep], np.column_stack(columns)
