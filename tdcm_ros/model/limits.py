"""Physical limits of the model, checked explicitly so they surface as typed errors."""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.compiled import kernels
from tdcm_ros.model.errors import (
    NotchClosureError,
    TendonSingularityError,
    TensionRangeError,
)
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kinematics import PlanarShape, integrate
from tdcm_ros.model.quiet import quiet_fp
from tdcm_ros.model.tendons import TendonLayout

Array = NDArray[np.float64]

CLOSURE_BISECTIONS = 60


def check_tension(tension: Any) -> float:
    """Return ``tension`` (N) as a float, or raise :class:`TensionRangeError`.

    A tension is a real number (``int``, ``float``, ``fractions.Fraction`` or a NumPy integer or
    floating scalar), finite and ``>= 0``; ``bool``, strings and arrays are refused.
    """
    if type(tension) is float and math.isfinite(tension) and tension >= 0.0:
        return tension
    if isinstance(tension, (bool, np.bool_)) or not isinstance(tension, numbers.Real):
        raise TensionRangeError(
            f"tension = {tension!r} is not a real number; allowed: a finite number in [0, inf) N",
            parameter="tension", value=tension, allowed="[0, inf) N")
    value = float(tension)
    if not math.isfinite(value) or value < 0.0:
        raise out_of_range("tension", value, "[0, inf) N (finite)", unit="N",
                           error=TensionRangeError)
    return value


def check_tensions(tension: Any, count: int) -> tuple[float, ...]:
    """Base tensions (N) of ``count`` tendons: ``tension`` as one number (one tendon) or a
    sequence of ``count`` numbers, each as :func:`check_tension` (named ``tension[k]``);
    raises :class:`TensionRangeError`."""
    if isinstance(tension, (Sequence, np.ndarray)) and not isinstance(tension, (str, bytes)):
        values = list(np.asarray(tension, dtype=object).ravel()) if isinstance(
            tension, np.ndarray) else list(tension)
        if len(values) != count:
            raise out_of_range("tension", values, f"{count} tension(s) in N, one "
                               f"per tendon (the design has {count})", unit="N",
                               error=TensionRangeError)
        out = []
        for k, value in enumerate(values):
            try:
                out.append(check_tension(value))
            except TensionRangeError as error:
                raise out_of_range(f"tension[{k}]", value, str(error.allowed),
                                   error=TensionRangeError) from error
        return tuple(out)
    if count != 1:
        raise out_of_range("tension", tension, f"{count} tensions in N, one per tendon",
                           unit="N", error=TensionRangeError)
    return (check_tension(tension),)


@quiet_fp
def check_singularity(grid: Grid, m_a: Array, m_b: Array) -> None:
    """Raise :class:`TendonSingularityError` where the tendon follows the offset curve and
    ``(R_c - x_bar) * kappa`` reaches 1 (the curve ``p + R_c x_b`` cusps; ``x_bar`` the
    centroid's offset, 0 but in notches whose backbone is off the axis). ``kappa`` uses each
    cell's peak compliance, so the check is pointwise, not a cell average."""
    _check_cusp(grid, grid.constrained_cells, grid.r_c, m_a, m_b, "")


@quiet_fp
def check_tendons_singularity(grid: Grid, layout: TendonLayout, m_a: Array, m_b: Array
                              ) -> None:
    """:func:`check_singularity` for each tendon of ``layout`` on the cells it follows before
    its anchor, at its own signed offset (a tendon on -x cusps under a moment toward -x)."""
    for j in range(layout.count):
        _check_cusp(grid, layout.follow_cells[j], float(layout.offsets[j]), m_a, m_b,
                    f" ({layout.names[j]})")


def _check_cusp(grid: Grid, cells: NDArray[np.int64], offset: float, m_a: Array, m_b: Array,
                which: str) -> None:
    """Raise :class:`TendonSingularityError` where ``(offset - x_bar) kappa`` (signed; the
    worst of the cell's end moments and end centroids) reaches 1 on ``cells``."""
    if cells.size == 0:
        return
    arm_a = offset - grid.xbar_start[cells]
    arm_b = offset - grid.xbar_end[cells]
    worst_pair = np.maximum.reduce([arm_a * m_a[cells], arm_a * m_b[cells],
                                    arm_b * m_a[cells], arm_b * m_b[cells]])
    rc_kappa = worst_pair * grid.peak_c[cells]
    worst = int(np.argmax(rc_kappa))
    if rc_kappa[worst] >= 1.0:
        s = float(grid.peak_s[cells[worst]])
        raise TendonSingularityError(
            f"tendon-offset singularity{which}: R_c*kappa = {rc_kappa[worst]:.3g} >= 1 at s = "
            f"{s * 1e3:.3f} mm (the tendon path cusps); lower the tension or stiffen the notch",
            arc_length_m=s, rc_kappa=float(rc_kappa[worst]))


def notch_gaps(grid: Grid, shape: PlanarShape) -> Array:
    """Smallest gap (m) between the two faces of every notch, on either side of the body.

    The faces are the planes normal to the tangent at ``l_i`` and ``r_i``; the gap is the
    signed distance of each face's outer corner (at ``R_outer``) from the other face
    (:func:`tdcm_ros.model.kernel.gaps_row`).
    """
    cells = grid.cells
    out = np.empty((1, cells.notch.shape[2]))
    kernels().gaps(cells.scal, np.ascontiguousarray(shape.p).reshape(1, -1),
                   np.ascontiguousarray(shape.tangent).reshape(1, -1), cells.notch, out)
    return out[0]


@quiet_fp
def check_tendon_singularity(grid: Grid, tension: float) -> None:
    """:func:`check_singularity` for the tendon's own moment ``(R_c - x_bar) T`` (exact for
    the closed form on the offset curve), in O(1) from the grid's arm-weighted peak
    compliance (:func:`tdcm_ros.model.grid.arm_weighted`)."""
    if grid.constrained_cells.size == 0:
        return
    rc_kappa = grid.r_c ** 2 * tension * grid.constrained_peak_c
    if rc_kappa >= 1.0:
        arm = grid.r_c - np.minimum(grid.xbar_start, grid.xbar_end)
        check_singularity(grid, arm * tension, arm * tension)


@quiet_fp
def check_closure(grid: Grid, shape: PlanarShape, tension: float) -> None:
    """Raise :class:`NotchClosureError` if any notch's faces touch or overlap."""
    gaps = notch_gaps(grid, shape)
    worst = int(np.argmin(gaps))
    if gaps[worst] <= 0.0:
        raise NotchClosureError(
            f"notch {worst + 1} closes at tension {tension:g} N (face gap {gaps[worst] * 1e3:.3f}"
            " mm): its faces touch, which the base model does not include",
            notch=worst + 1, gap_m=float(gaps[worst]))


@lru_cache(maxsize=64)
def closure_angles(grid: Grid) -> Array:
    """Bend angle (rad) across each notch, base to tip, at which its faces touch
    (:func:`notch_gaps` = 0) under a moment uniform over the notch; ``inf`` if they do not
    touch below pi. Notches of the same shape share it (found once per shape). For a
    uniform-curvature notch it is ``w_n / R_outer`` exactly. The array is shared: do not
    modify it."""
    notch = grid.notch_index
    first_of_shape: dict[int, int] = {}
    for k in range(grid.notch_left_node.size):
        first_of_shape.setdefault(int(grid.shape[grid.notch_left_node[k]]), k)
    angles = {shape: _closure_angle(grid, k, np.flatnonzero(notch == k))
              for shape, k in first_of_shape.items()}
    out = np.array([angles[int(grid.shape[node])] for node in grid.notch_left_node])
    out.setflags(write=False)
    return out


def _closure_angle(grid: Grid, k: int, cells: NDArray[np.int64]) -> float:
    """:func:`closure_angles` of notch ``k`` (0-based), whose cells are ``cells``."""
    per_moment = float(np.sum(grid.C0[cells] + grid.C1[cells]))

    def gap(angle: float) -> float:
        moment = np.zeros(grid.n_cells)
        moment[cells] = angle / per_moment
        return float(notch_gaps(grid, integrate(grid, moment, moment))[k])

    low, high = 0.0, math.pi * (1.0 - 1e-9)
    if gap(high) > 0.0:
        return math.inf
    for _ in range(CLOSURE_BISECTIONS):
        middle = 0.5 * (low + high)
        if gap(middle) > 0.0:
            low = middle
        else:
            high = middle
    return low
