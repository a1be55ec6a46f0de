"""Time alignment: the nearest stamp within a tolerance (the association evo uses)."""

from __future__ import annotations

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
