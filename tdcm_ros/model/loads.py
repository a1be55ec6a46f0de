"""Bending moment exerted by the tendon on the midline (eqs. 3-11), in two forms.

Both return per-cell one-sided end moments ``(m_a, m_b)`` (N m, about +y) for a shape.

**Closed form** (default). For a frictionless tendon of constant tension ``T``, equilibrium
of the tendon piece from ``s`` to ``L`` gives ``m(s) = (p_c(s) - p(s)) x (-T t_c(s))``. Where
the tendon follows the offset curve ``p + R_c x_b`` its tangent is the body's and
``m = R_c T`` exactly; on a straight run (a chord, eqs. 3-4) ``m`` is ``T`` times the signed
distance from ``p(s)`` to the chord line.

**Literal form**: the paper's sum ``m_a + m_n + m_cn`` (eqs. 8-10) evaluated on the grid:
anchor force at ``p_c(L)``; distributed normal forces ``T kappa_c n_tendon`` from the Frenet
formulas (eqs. 5-6) integrated by the cells' Gauss points, reading eq. 9's ``d xi`` as the
tendon's own arc-length element ``|p_c'| d xi`` (the reading under which eqs. 8-11 are the
tendon's equilibrium); concentrated forces ``n T sin(theta)`` at every kink with ``theta``
from eq. 7 (``asin`` of cross over dot, its small-angle form) and ``n`` along ``t+ - t-``.
Positions inside a cell are taken on the cell's mean-curvature arc, so the literal form
converges to the closed form as cells are refined.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.cells import Cells
from tdcm_ros.model.compiled import kernels
from tdcm_ros.model.errors import ModelLimitError
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kinematics import PlanarShape

Array = NDArray[np.float64]


class KinkAngleError(ModelLimitError):
    """Eq. 7 is undefined for a tendon kink beyond 45 degrees (use the closed form)."""

    kind = "kink_angle"


def closed_form(grid: Grid | Cells, shape: PlanarShape, tension: float | Array
                ) -> tuple[Array, Array]:
    """Per-cell end moments ``(m_a, m_b)`` (N m) from ``m = (p_c - p) x (-T t_c)``.

    ``tension`` (N) is a scalar or has the shape's batch dimensions (one grid), or one per
    member for :class:`Cells`.
    """
    tension = np.asarray(tension, dtype=float)
    n = shape.p.shape[-1] - 1
    t = np.ascontiguousarray(np.broadcast_to(tension[..., None], (*tension.shape, n)))
    return closed_form_cells(grid, shape, t, t)


def closed_form_cells(grid: Grid | Cells, shape: PlanarShape, t_a: Array, t_b: Array
                      ) -> tuple[Array, Array]:
    """:func:`closed_form` with a tension that varies along ``s``
    (:func:`tdcm_ros.model.kernel.moments_row`).

    ``t_a``, ``t_b`` (N, shape (cells,), or the shape's batch dimensions first) are the tendon
    tensions at each cell's start and end, one-sided like the moments. Equilibrium of the
    tendon piece beyond the cut still gives ``m(s) = (p_c(s) - p(s)) x (-T(s) t_c(s))`` with
    ``T(s)`` the tension at the cut: friction between tendon and channel is internal to the
    tendon + distal body. On a chord the tendon runs free, so the caller passes the chord's
    one tension at both ends.
    """
    cells = grid.cells if isinstance(grid, Grid) else grid
    p = shape.p
    lead = p.shape[:-1]
    n = p.shape[-1] - 1
    rows = int(np.prod(lead, dtype=np.int64)) if lead else 1
    scal, ic, fc = cells.scal, cells.ic, cells.fc
    if rows != cells.members:
        scal = np.ascontiguousarray(np.broadcast_to(scal, (rows, *scal.shape[1:])))
        ic = np.ascontiguousarray(np.broadcast_to(ic, (rows, *ic.shape[1:])))
        fc = np.ascontiguousarray(np.broadcast_to(fc, (rows, *fc.shape[1:])))

    def flat(values: NDArray[np.generic]) -> NDArray[np.generic]:
        return np.ascontiguousarray(np.broadcast_to(values, (*lead, values.shape[-1])
                                                    ).reshape(rows, -1))

    m_a = np.empty((rows, n))
    m_b = np.empty((rows, n))
    kernels().moments(scal, flat(p), flat(shape.tangent), flat(np.asarray(t_a, dtype=float)),
                      flat(np.asarray(t_b, dtype=float)), ic, fc, m_a, m_b)
    return m_a.reshape(*lead, n), m_b.reshape(*lead, n)


def tendon_wrap(grid: Grid, shape: PlanarShape) -> tuple[Array, Array]:
    """Cumulative absolute turning (rad) of the tendon from the base, at every node.

    Returns ``(before, after)``, shape (nodes,): the turning up to each node excluding and
    including the kink there (eqs. 3-4: a chord meeting the offset curve). The tendon arrives
    at the base along +z (the clamped base's tangent); the first kink, if any, is where it
    enters its first chord. Inside a cell where the tendon follows the offset curve it turns
    by the body's ``|theta_b - theta_a|``; along a chord it does not turn.
    """
    n = grid.n_cells
    con = grid.constrained
    start = shape.tangent[:-1].copy()
    end = shape.tangent[1:].copy()
    cells = grid.chord_cells
    if cells.size:
        _, chord = _chords(grid, shape, cells)
        start[cells] = chord
        end[cells] = chord
    previous = np.concatenate([np.ones(1, dtype=complex), end[:-1]])
    kink = np.abs(np.angle(np.conj(previous) * start))
    within = np.where(con, np.abs(np.diff(shape.theta)), 0.0)
    steps = np.empty(2 * n)
    steps[0::2] = kink
    steps[1::2] = within
    total = np.cumsum(steps)
    before = np.zeros(n + 1)
    before[1:] = total[1::2]
    after = before.copy()
    after[:-1] = total[0::2]
    return before, after


def _chords(grid: Grid, shape: PlanarShape, cells: NDArray[np.int64]
            ) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """Start point and unit direction (``z + i x``) of the tendon chord over each cell."""
    p_c = shape.p + (1j * grid.r_c) * shape.tangent
    anchor = p_c[grid.chord_start_node[cells]]
    chord = p_c[grid.chord_end_node[cells]] - anchor
    return anchor, chord / np.abs(chord)


def literal(grid: Grid, shape: PlanarShape, tension: float, m_a: Array, m_b: Array
            ) -> tuple[Array, Array]:
    """Per-cell end moments (N m) as the paper's sum of eqs. 8-10, for one (unbatched) shape.

    ``m_a``, ``m_b`` are the moments that produced ``shape``; they give the curvature the
    distributed forces need.
    """
    r_c = grid.r_c
    x, z, th = shape.x, shape.z, shape.theta
    n = grid.n_cells
    a_nodes = np.arange(n)
    # Tendon tangent on each cell (one-sided at both ends), eqs. 3-4.
    pcx = x + r_c * np.cos(th)
    pcz = z - r_c * np.sin(th)
    start, end = grid.chord_start_node, grid.chord_end_node
    chord = np.stack([pcx[end] - pcx[start], pcz[end] - pcz[start]], axis=-1)
    chord /= np.linalg.norm(chord, axis=-1, keepdims=True)
    body_a = np.stack([np.sin(th[:-1]), np.cos(th[:-1])], axis=-1)
    body_b = np.stack([np.sin(th[1:]), np.cos(th[1:])], axis=-1)
    con = grid.constrained[:, None]
    t_start = np.where(con, body_a, chord)
    t_end = np.where(con, body_b, chord)

    # Forces on the body with their points of application (x, z) and the arc length they act at.
    points: list[Array] = []
    forces: list[Array] = []
    where: list[Array] = []

    # Eq. 8: anchor force at the tip.
    points.append(np.array([[pcx[-1], pcz[-1]]]))
    forces.append(-tension * t_end[-1:])
    where.append(np.array([grid.s_nodes[-1]]))

    # Eqs. 5-6, 9: distributed normal forces on constrained cells at the Gauss points.
    cells = np.flatnonzero(grid.constrained)
    if cells.size:
        kappa = (m_a[cells, None] * (1.0 - grid.xi_q[cells]) + m_b[cells, None] * grid.xi_q[cells]
                 ) * grid.c_q[cells]
        phi = m_a[cells, None] * grid.A0[cells] + m_b[cells, None] * grid.A1[cells]
        theta_q = th[cells, None] + phi
        sigma = grid.s_q[cells] - grid.s_nodes[cells, None]
        mean_k = ((th[cells + 1] - th[cells]) / grid.length[cells])[:, None]
        along, across = arc_offsets(mean_k, sigma)
        ta = np.stack([np.sin(th[cells]), np.cos(th[cells])], axis=-1)[:, None, :]
        na = np.stack([np.cos(th[cells]), -np.sin(th[cells])], axis=-1)[:, None, :]
        p_q = (np.stack([x[cells], z[cells]], axis=-1)[:, None, :]
               + along[..., None] * ta + across[..., None] * na)
        tangent = np.stack([np.sin(theta_q), np.cos(theta_q)], axis=-1)
        normal = np.stack([np.cos(theta_q), -np.sin(theta_q)], axis=-1)
        pc_q = p_q + r_c * normal
        stretch = 1.0 - r_c * kappa
        d1 = stretch[..., None] * tangent
        d2 = (stretch * kappa)[..., None] * normal
        cross = d1[..., 1] * d2[..., 0] - d1[..., 0] * d2[..., 1]
        speed = np.abs(stretch)
        kappa_c = np.abs(cross) / speed**3
        # n = p' x (p'' x p') / (|p' x p''| |p'|): in the plane, p'' minus its tangential part.
        proj = np.sum(d2 * d1, axis=-1, keepdims=True) / speed[..., None] ** 2
        n_vec = (d2 - proj * d1) * speed[..., None] ** 2
        n_norm = np.maximum(np.abs(cross) * speed, np.finfo(float).tiny)[..., None]
        n_c = n_vec / n_norm
        f = tension * kappa_c[..., None] * n_c * speed[..., None] * grid.w_q[cells, :, None]
        points.append(pc_q.reshape(-1, 2))
        forces.append(f.reshape(-1, 2))
        where.append(grid.s_q[cells].reshape(-1))

    # Eqs. 7, 10: concentrated forces where the tendon direction jumps between cells (a zero
    # jump, inside a straight run or along the offset curve, gives a zero force).
    t_minus = t_end[:-1]
    t_plus = t_start[1:]
    kink = np.arange(n - 1)
    if kink.size:
        tm, tp = t_minus[kink], t_plus[kink]
        cross = tm[:, 1] * tp[:, 0] - tm[:, 0] * tp[:, 1]
        dot = np.abs(np.sum(tm * tp, axis=-1))
        ratio = cross / dot
        if np.any(np.abs(ratio) > 1.0):
            worst = float(np.degrees(np.arctan(np.max(np.abs(ratio)))))
            raise KinkAngleError(
                f"tendon kink of {worst:.1f} deg exceeds eq. 7's 45 deg domain; use loads=closed")
        sin_theta = np.sin(np.arcsin(np.abs(ratio)))
        jump = tp - tm
        direction = jump / np.maximum(np.linalg.norm(jump, axis=-1, keepdims=True),
                                      np.finfo(float).tiny)
        node = kink + 1
        points.append(np.stack([pcx[node], pcz[node]], axis=-1))
        forces.append(tension * sin_theta[:, None] * direction)
        where.append(grid.s_nodes[node])

    pts = np.concatenate(points)
    frc = np.concatenate(forces)
    at = np.concatenate(where)
    order = np.argsort(at, kind="stable")
    pts, frc, at = pts[order], frc[order], at[order]
    # Suffix sums of (p_c x F) and F, so that m(s) = sum_{xi >= s} (p_c - p(s)) x F.
    torque = pts[:, 1] * frc[:, 0] - pts[:, 0] * frc[:, 1]
    suffix_t = np.append(np.cumsum(torque[::-1])[::-1], 0.0)
    suffix_fx = np.append(np.cumsum(frc[::-1, 0])[::-1], 0.0)
    suffix_fz = np.append(np.cumsum(frc[::-1, 1])[::-1], 0.0)

    def moment(node: NDArray[np.int64], strict: bool) -> Array:
        s = grid.s_nodes[node]
        first = np.searchsorted(at, s, side="right" if strict else "left")
        return suffix_t[first] - (z[node] * suffix_fx[first] - x[node] * suffix_fz[first])

    return moment(a_nodes, strict=True), moment(a_nodes + 1, strict=False)


def arc_offsets(curvature: Array, length: Array) -> tuple[Array, Array]:
    """Along-tangent and toward-normal displacement (m) after ``length`` on a circular arc."""
    angle = curvature * length
    small = np.abs(angle) < 1e-8
    safe = np.where(small, 1.0, curvature)
    along = np.where(small, length, np.sin(angle) / safe)
    across = np.where(small, 0.5 * curvature * length**2, (1.0 - np.cos(angle)) / safe)
    return along, across
