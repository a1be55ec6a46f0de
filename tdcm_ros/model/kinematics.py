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

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.cells import Cells
from tdcm_ros.model.compiled import kernels
from tdcm_ros.model.grid import Grid

Array = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


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

    @property
    def positions(self) -> Array:
        """Node positions (..., n, 3) m in ``tdcm_base``: ``(x, 0, z)``."""
        positions = np.zeros((*self.p.shape, 3))
        positions[..., 0] = self.p.imag
        positions[..., 2] = self.p.real
        return positions


def integrate(grid: Grid | Cells, m_a: Array, m_b: Array,
              tension: float | Array = 0.0, axis_tension: float | Array | None = None
              ) -> PlanarShape:
    """Shape from per-cell end moments ``m_a``, ``m_b`` (N m) under tendon ``tension`` (N).

    Each cell's tangent angle at its Gauss points is ``theta_a + m_a A0 + m_b A1``; the cell's
    displacement is the quadrature of the unit tangent over those points
    (:func:`tdcm_ros.model.kernel.integrate_row`). Exact for moments linear in a cell, i.e.
    where the tendon follows the body; on a chord the moment bows (``m'' = -T c m``) and the
    grid's chord terms, times ``tension`` (a scalar or one per cell, broadcast against the
    moments; 0 treats every moment as linear), carry it; ``axis_tension`` (N, the same
    shapes; default ``tension``) is the tension of every tendon pulling on each cell, for the
    centroid's motion off the axis (several tendons: only some cross a cell as a chord).
    ``grid`` is one grid, whose moments
    may carry leading batch axes, or :class:`Cells` of ``M`` members with moments (M, cells).
    """
    cells = grid.cells if isinstance(grid, Grid) else grid
    m_a = np.asarray(m_a, dtype=float)
    lead = m_a.shape[:-1]
    n = m_a.shape[-1]
    rows = int(np.prod(lead, dtype=np.int64)) if lead else 1
    a = np.ascontiguousarray(m_a.reshape(rows, n))
    b = np.ascontiguousarray(np.asarray(m_b, dtype=float).reshape(rows, n))
    t = np.ascontiguousarray(np.broadcast_to(np.asarray(tension, dtype=float),
                                             m_a.shape).reshape(rows, n))
    t_axis = t if axis_tension is None else np.ascontiguousarray(np.broadcast_to(
        np.asarray(axis_tension, dtype=float), m_a.shape).reshape(rows, n))
    fc, fq = cells.fc, cells.fq
    if rows != cells.members:
        fc = np.ascontiguousarray(np.broadcast_to(fc, (rows, *fc.shape[1:])))
        fq = np.ascontiguousarray(np.broadcast_to(fq, (rows, *fq.shape[1:])))
    p = np.empty((rows, n + 1), np.complex128)
    theta = np.empty((rows, n + 1))
    tangent = np.empty((rows, n + 1), np.complex128)
    kernels().integrate(fc, fq, a, b, t, t_axis, p, theta, tangent)
    nodes = (*lead, n + 1)
    return PlanarShape(p=p.reshape(nodes), theta=theta.reshape(nodes),
                       tangent=tangent.reshape(nodes))


def quaternions_y(theta: Array) -> Array:
    """Quaternions ``(x, y, z, w)`` of rotations by ``theta`` (rad) about +y, shape (..., 4)."""
    half = 0.5 * np.asarray(theta, dtype=float)
    zeros = np.zeros_like(half)
    return np.stack([zeros, np.sin(half), zeros, np.cos(half)], axis=-1)
