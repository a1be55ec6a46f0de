"""Occlusion: which reported marker positions are real.

Vicon software reports a marker it cannot see as a gap (an empty CSV cell, read as NaN) or, in
the real-time stream, as the origin ``(0, 0, 0)``. Both are dropped here and never published as
positions. A marker sitting exactly on the mocap origin is indistinguishable from an occluded one
and is dropped too.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def visible(positions: ArrayLike) -> NDArray[np.bool_]:
    """Mask (k,) of rows of ``positions`` (k, 3) that are finite and not all exactly zero."""
    p = np.asarray(positions, dtype=float).reshape(-1, 3)
    return np.all(np.isfinite(p), axis=1) & np.any(p != 0.0, axis=1)
