"""Exact planar integration of eq. 2 over the cells, and the frame conventions.

Frame ``tdcm_base`` (REP 103): base at the origin, the straight body along +z, the tendon on
the +x side; bending happens in the x-z plane toward +x, a rotation by the tangent angle
``theta`` about +y. The body frame is ``R_y(theta)``: its z axis is the tangent
``t = (sin theta, 0, cos theta)`` and its x axis ``x_b = (cos theta, 0, -sin theta)`` points
to the tendon side. Curvature ``kappa = d theta / ds`` (1/m) is positive toward +x.

Internally a planar point is the complex number ``z + i x``; the tangent is then
``exp(i theta)`` and ``x_b`` is ``i exp(i theta)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.grid import Grid

Array = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
Scalar = TypeVar("Scalar", np.float64, np.complex128)


@dataclass(frozen=True)
class PlanarShape:
    """Midline nodes of one iterate: ``p = z + i x`` (m), tangent angle ``theta`` (rad) and
    the unit tangent ``tangent = exp(i theta)``. The last axis runs over grid nodes; leading
    axes, if any, are a batch."""

    p: ComplexArray
    theta: Array
    tangent: ComplexArray

    @property
    def x(self) -> Array:
        """x coordinates (m)."""
        return self.p.imag

    @property
    def z(self) -> Array:
        """z coordinates (m)."""
        return self.p.real


def integrate(grid: Grid, m_a: Array, m_b: Array) -> PlanarShape:
    """Shape from per-cell end moments ``m_a``, ``m_b`` (N m), exactly for linear moments.

    Each cell's tangent angle at its Gauss points is ``theta_a + m_a A0 + m_b A1``; the cell's
    displacement is the quadrature of the unit tangent over those points.
    """
    phi = m_a[..., None] * grid.A0 + m_b[..., None] * grid.A1
    local = np.sum(grid.w_q * np.exp(1j * phi), axis=-1)
    theta = _cumsum0(m_a * grid.C0 + m_b * grid.C1)
    tangent = np.exp(1j * theta)
    p = _cumsum0(tangent[..., :-1] * local)
    return PlanarShape(p=p, theta=theta, tangent=tangent)


def _cumsum0(values: NDArray[Scalar]) -> NDArray[Scalar]:
    """Cumulative sum along the last axis with a leading zero."""
    out = np.zeros(values.shape[:-1] + (values.shape[-1] + 1,), dtype=values.dtype)
    np.cumsum(values, axis=-1, out=out[..., 1:])
    return out


def quaternions_y(theta: Array) -> Array:
    """Quaternions ``(x, y, z, w)`` of rotations by ``theta`` (rad) about +y, shape (..., 4)."""
    half = 0.5 * np.asarray(theta, dtype=float)
    zeros = np.zeros_like(half)
    return np.stack([zeros, np.sin(half), zeros, np.cos(half)], axis=-1)
