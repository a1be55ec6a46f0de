"""Algorithm 1's grid-level kernels, written once for a leading member axis.

Every function here is plain Python on NumPy arrays and scalars, in the subset of Python that
numba compiles: :mod:`tdcm_ros.model.compiled` runs these same functions either as they are
or compiled (lazily, on first use), with NumPy's error model in both builds (a float divided
by zero is inf or nan). A single solve is one member; a batch stacks many.

Member arrays (SI units; ``M`` members, ``n`` cells, ``Q`` quadrature points, ``K`` notches):

- ``fc`` (M, 7, n): the cells' ``C0``, ``C1`` (rad/(N m)), chord terms ``C0_T``, ``C1_T``
  (rad/(N^2 m)), the centroid's offset ``x_bar`` at the cell's start and end (m; 0 but in
  notches whose backbone is off the axis: the end moments are taken about the centroid) and
  ``D`` (rad/(N m): the bend of the moment's part the centroid's motion inside the cell adds,
  per newton of tendon tension, :func:`tdcm_ros.model.grid_kernel.cell_integrals`);
- ``fq`` (M, 10, n, Q): ``A0``, ``A1`` (rad/(N m)), ``w_q`` (m), ``A0_T``, ``A1_T``
  (rad/(N^2 m)), ``K0``, ``K1`` (m/(N m)), ``D_q`` (rad/N), ``K2`` (m/N) and ``W_A`` (m/N) at
  the Gauss points: off the axis a point's angle has ``- T D_q`` and the tube axis's ds weight
  is ``w_q + m_a K0 + m_b K1 - T K2`` (its stretch ``x_bar kappa``), and a compressible
  midline's weight has ``- T W_A`` (``W_A = w_q / (E A)``, zero when rigid) (:mod:`tdcm_ros.model.grid`: on a chord the moment is
  not linear in the cell, ``m'' = -T c m``; the integrals are then ``A0 + T A0_T`` etc. with
  ``T`` the chord's tension, and the chord terms are zero where the tendon follows the body);
- ``ic`` (M, 3, n): each cell's chord start node, chord end node, and 1 where the tendon
  follows the offset curve (0 on a chord);
- ``notch`` (M, 4, K): left and right node of every notch, -1 in padding, then 1 where its
  faces can meet on the +x and on the -x side (0 where the section keeps the wall there);
- ``scal`` (M, 4): ``R_c`` (m), ``R_outer`` (m), body length (m), constrained peak compliance.

A zero-length padding cell (every one of those zero) is neutral: it moves no node.
Planar points are complex numbers ``z + i x`` (see :mod:`tdcm_ros.model.kinematics`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Complex = NDArray[np.complex128]
Ints = NDArray[np.int64]

RUNNING = 0
CONVERGED = 1
NON_FINITE = 2
DIVERGING = 3
SLOWED = 4
EXHAUSTED = 5
"""Statuses of :func:`iterate` per member."""


SMALL_ANGLE = 0.25
"""Below this |angle| (rad) :func:`unit` sums Taylor series (truncation < 1e-19)."""
TINY_ANGLE = 0.03
"""Below this |angle| (rad) the series stop at degrees 8 and 9 (truncation < 1e-21)."""


def unit(phi: float) -> complex:
    """``exp(i phi)``: for ``|phi| <= SMALL_ANGLE`` (the angles inside a cell) by the Taylor
    series of cos and sin, to degrees 8 and 9 below ``TINY_ANGLE`` and 12 and 13 above
    (within 1 ulp of libm, 4-6x faster), otherwise by libm."""
    size = abs(phi)
    v = phi * phi
    if size <= TINY_ANGLE:
        return complex(1.0 + v * (-1.0 / 2 + v * (1.0 / 24 + v * (-1.0 / 720 + v * (1.0 / 40320)))),
                       phi * (1.0 + v * (-1.0 / 6 + v * (1.0 / 120 + v * (
                           -1.0 / 5040 + v * (1.0 / 362880))))))
    if size > SMALL_ANGLE:
        return complex(math.cos(phi), math.sin(phi))
    c = 1.0 + v * (-1.0 / 2 + v * (1.0 / 24 + v * (-1.0 / 720 + v * (
        1.0 / 40320 + v * (-1.0 / 3628800 + v * (1.0 / 479001600))))))
    s = phi * (1.0 + v * (-1.0 / 6 + v * (1.0 / 120 + v * (-1.0 / 5040 + v * (
        1.0 / 362880 + v * (-1.0 / 39916800 + v * (1.0 / 6227020800)))))))
    return complex(c, s)


def integrate_row(fc: Array, fq: Array, m_a: Array, m_b: Array, t: Array, t_axis: Array,
                  p: Complex, theta: Array, tangent: Complex) -> None:
    """Shape of one member from its cell end moments ``m_a``, ``m_b`` (N m), each cell's
    chord tension ``t`` (N: the tension of the tendons crossing it as a chord, where the
    moment inside the cell is ``m'' = -T c m`` to first order) and axial tension ``t_axis``
    (N: of every tendon pulling on the cell, whose centroid's motion off the axis adds
    ``- T dx``; elsewhere the moment is exactly linear): writes nodes ``p`` (m), ``theta``
    (rad) and ``tangent`` of the tube axis (stretched by ``x_bar kappa`` where the centroid is
    off it). One tendon passes its tension as both."""
    n = fc.shape[1]
    nq = fq.shape[2]
    pos = 0j
    th = 0.0
    tan = 1.0 + 0j
    p[0] = pos
    theta[0] = th
    tangent[0] = tan
    for i in range(n):
        a = m_a[i]
        b = m_b[i]
        local = 0j
        chord = fc[2, i] != 0.0 or fc[3, i] != 0.0
        off_axis = fc[4, i] != 0.0 or fc[5, i] != 0.0 or fq[5, i, 0] != 0.0
        compress = fq[9, i, 0] != 0.0
        if not (chord or off_axis or compress):  # the tendon follows the body: linear
            for q in range(nq):
                local += fq[2, i, q] * unit(a * fq[0, i, q] + b * fq[1, i, q])
            th = th + (a * fc[0, i] + b * fc[1, i])
        else:
            tension = t[i]
            pull = t_axis[i]
            for q in range(nq):
                if chord:
                    phi = (a * (fq[0, i, q] + tension * fq[3, i, q])
                           + b * (fq[1, i, q] + tension * fq[4, i, q]))
                else:
                    phi = a * fq[0, i, q] + b * fq[1, i, q]
                weight = fq[2, i, q]
                if off_axis:
                    phi -= pull * fq[7, i, q]
                    weight += a * fq[5, i, q] + b * fq[6, i, q] - pull * fq[8, i, q]
                if compress:
                    weight -= pull * fq[9, i, q]
                local += weight * unit(phi)
            if chord:
                bend = a * (fc[0, i] + tension * fc[2, i]) + b * (fc[1, i] + tension * fc[3, i])
            else:
                bend = a * fc[0, i] + b * fc[1, i]
            if off_axis:
                bend -= pull * fc[6, i]
            th = th + bend
        pos = pos + tan * local
        tan = complex(math.cos(th), math.sin(th))
        p[i + 1] = pos
        theta[i + 1] = th
        tangent[i + 1] = tan


def moments_row(r_c: float, p: Complex, tangent: Complex, t_a: Array, t_b: Array, ic: Ints,
                fc: Array, m_a: Array, m_b: Array) -> None:
    """Tendon moment ``m = (p_c - q) x (-T t_c)`` (N m) at each cell's ends for one member
    about the section's centroid ``q = p + x_bar n`` (``x_bar`` from ``fc``'s rows 4 and 5;
    ``n`` the +x direction; the tube axis ``p`` where ``x_bar = 0``), with the tension ``t_a``,
    ``t_b`` (N) at each cell's start and end: ``(R_c - x_bar) T`` where the tendon follows the
    offset curve, ``T`` times the distance to the chord line elsewhere."""
    n = ic.shape[1]
    offset = 1j * r_c
    for i in range(n):
        x_a = fc[4, i]
        x_b = fc[5, i]
        if ic[2, i] != 0:
            m_a[i] = (r_c - x_a) * t_a[i]
            m_b[i] = (r_c - x_b) * t_b[i]
        else:
            start = ic[0, i]
            end = ic[1, i]
            anchor = p[start] + offset * tangent[start]
            chord = p[end] + offset * tangent[end] - anchor
            chord = chord / abs(chord)
            at_a = p[i]
            at_b = p[i + 1]
            if x_a != 0.0:
                at_a = at_a + (1j * x_a) * tangent[i]
            if x_b != 0.0:
                at_b = at_b + (1j * x_b) * tangent[i + 1]
            m_a[i] = -t_a[i] * ((anchor - at_a).conjugate() * chord).imag
            m_b[i] = -t_b[i] * ((anchor - at_b).conjugate() * chord).imag


def gaps_row(r_outer: float, p: Complex, tangent: Complex, notch: Ints, out: Array) -> None:
    """Smallest gap (m) between the two faces of every notch of one member, on each side of
    the body where its cut opens (``notch[2, k]`` the +x side, ``notch[3, k]`` the -x side):
    the signed distance of each face's outer corner from the other face (``inf`` for padding
    notches: nodes -1, or both at one node, and where no side opens)."""
    for k in range(notch.shape[1]):
        left = notch[0, k]
        right = notch[1, k]
        if left < 0 or left == right:
            out[k] = math.inf
            continue
        t_l = tangent[left]
        t_r = tangent[right]
        span = p[right] - p[left]
        smallest = math.inf
        for row in range(2, 4):
            if notch[row, k] == 0:
                continue
            side = 1.0 if row == 2 else -1.0
            delta = span + (1j * side * r_outer) * (t_r - t_l)
            smallest = min(smallest, (t_l.conjugate() * delta).real,
                           (t_r.conjugate() * delta).real)
        out[k] = smallest


def integrate(fc: Array, fq: Array, m_a: Array, m_b: Array, t: Array, t_axis: Array,
              p: Complex, theta: Array, tangent: Complex) -> None:
    """:func:`integrate_row` for every member (``m_a``, ``m_b``, tensions ``t``, ``t_axis``
    (M, n); outputs (M, n+1))."""
    for j in range(m_a.shape[0]):
        integrate_row(fc[j], fq[j], m_a[j], m_b[j], t[j], t_axis[j], p[j], theta[j],
                      tangent[j])


def moments(scal: Array, p: Complex, tangent: Complex, t_a: Array, t_b: Array, ic: Ints,
            fc: Array, m_a: Array, m_b: Array) -> None:
    """:func:`moments_row` for every member (tensions and moments (M, n))."""
    for j in range(m_a.shape[0]):
        moments_row(scal[j, 0], p[j], tangent[j], t_a[j], t_b[j], ic[j], fc[j], m_a[j], m_b[j])


def gaps(scal: Array, p: Complex, tangent: Complex, notch: Ints, out: Array) -> None:
    """:func:`gaps_row` for every member (``out`` (M, K))."""
    for j in range(p.shape[0]):
        gaps_row(scal[j, 1], p[j], tangent[j], notch[j], out[j])


def row_scratch(n: int, notches: int) -> tuple[Array, Array, Complex, Array, Complex, Array]:
    """:func:`iterate_row`'s scratch for ``n`` cells and ``notches`` notches: ``g`` (2n,),
    ``t_a`` (n,), ``new_p``, ``new_theta``, ``new_tangent`` (n + 1,), ``notch_gaps``."""
    return (np.empty(2 * n), np.empty(n), np.empty(n + 1, np.complex128), np.empty(n + 1),
            np.empty(n + 1, np.complex128), np.empty(notches))


def iterate(fc: Array, fq: Array, ic: Ints, notch: Ints, scal: Array, rows: Ints,
            tension: Array, x: Array, p: Complex, theta: Array, tangent: Complex, tol: float,
            relaxation: float, slow: float, growth: float, info: Array) -> None:
    """Plain (or damped) fixed-point iteration of the constant-tension tendon moment.

    Member ``j`` is design row ``rows[j]`` of the cell arrays at tension ``tension[j]`` (N).
    Per member: the shape of the start ``x[j]`` (2n,), then repeatedly new moments ``g`` from
    the shape, ``x <- x + relaxation (g - x)`` and the new shape; the step is the largest
    node displacement (m). ``x`` and the shape ``p``, ``theta``, ``tangent`` (M, n+1)
    receive the last iterate; ``info`` (M, 3 + budget) the number of steps, the status, the
    smallest notch gap (m, :func:`gaps_row`) of the last shape, then the steps (m). Statuses:
    ``CONVERGED`` (step <= tol (m)), ``NON_FINITE`` (the step is not finite: the previous
    iterate is kept, no step recorded), ``DIVERGING`` (step > 2 L, or > ``growth`` x the
    smallest step after 5 steps), ``SLOWED`` (``slow > 0`` and a step > ``slow`` x the
    previous one), ``EXHAUSTED`` (``budget = info.shape[1] - 3`` steps).
    """
    g, t_a, new_p, new_theta, new_tangent, notch_gaps = row_scratch(fc.shape[2],
                                                                    notch.shape[2])
    for j in range(x.shape[0]):
        row = rows[j]
        iterate_row(fc[row], fq[row], ic[row], notch[row], scal[row], tension[j], x[j], p[j],
                    theta[j], tangent[j], tol, relaxation, slow, growth, info[j], g, t_a, new_p,
                    new_theta, new_tangent, notch_gaps)


def iterate_row(fc: Array, fq: Array, ic: Ints, notch: Ints, scal: Array, tension: float,
                x: Array, p: Complex, theta: Array, tangent: Complex, tol: float,
                relaxation: float, slow: float, growth: float, info: Array, g: Array, t_a: Array,
                new_p: Complex, new_theta: Array, new_tangent: Complex,
                notch_gaps: Array) -> None:
    """:func:`iterate` for one member: its design row's cell arrays, its tension (N), its
    ``x`` (2n,), shape (n + 1,) and ``info`` (3 + budget,), with the scratch ``g`` (2n,),
    ``t_a`` (n,), ``new_p``, ``new_theta``, ``new_tangent`` (n + 1,) and ``notch_gaps`` (K,)."""
    n = fc.shape[1]
    budget = info.shape[0] - 3
    r_c = scal[0]
    limit = 2.0 * scal[2]
    t_a[:] = tension
    integrate_row(fc, fq, x[:n], x[n:], t_a, t_a, p, theta, tangent)
    smallest = math.inf
    status = EXHAUSTED
    steps = 0
    for k in range(budget):
        moments_row(r_c, p, tangent, t_a, t_a, ic, fc, g[:n], g[n:])
        if relaxation != 1.0:
            for i in range(2 * n):
                g[i] = x[i] + relaxation * (g[i] - x[i])
        integrate_row(fc, fq, g[:n], g[n:], t_a, t_a, new_p, new_theta, new_tangent)
        step = 0.0
        for i in range(n + 1):
            d = abs(new_p[i] - p[i])
            if not d <= step:
                step = d
                if math.isnan(d):
                    break
        if not math.isfinite(step):
            status = NON_FINITE
            break
        info[3 + k] = step
        steps = k + 1
        x[:] = g
        p[:] = new_p
        theta[:] = new_theta
        tangent[:] = new_tangent
        smallest = min(smallest, step)
        if step <= tol:
            status = CONVERGED
            break
        if step > limit or (k >= 5 and step > growth * smallest):
            status = DIVERGING
            break
        if slow > 0.0 and k >= 1 and step > slow * info[2 + k]:
            status = SLOWED
            break
    gaps_row(scal[1], p, tangent, notch, notch_gaps)
    least = math.inf
    for k in range(notch_gaps.size):
        least = min(least, notch_gaps[k])
    info[0] = steps
    info[1] = status
    info[2] = least


def lay_out(cells: Ints, fields: Ints, source: Array, out: Array) -> None:
    """``out[f, j, :] = source[cells[j], fields[f], :]``: one design's rows ``fields`` of a
    prototype-cell table ``source`` (P, F, Q) laid out along its cells (``cells``: each one's
    prototype), field-major as the iteration reads them (``out`` (len(fields), W, Q))."""
    for f in range(fields.shape[0]):
        field = fields[f]
        for j in range(cells.shape[0]):
            row = cells[j]
            for q in range(out.shape[2]):
                out[f, j, q] = source[row, field, q]


def gather(index: Ints, fields: Ints, source: Array, out: Array) -> None:
    """:func:`lay_out` of every member: ``out[m, f, j, :] = source[index[m, j], fields[f],
    :]`` (``out`` (M, len(fields), W, Q))."""
    for m in range(index.shape[0]):
        lay_out(index[m], fields, source, out[m])


def iterate_prototypes(proto_fc: Array, proto_fq: Array, proto_strain: Array, fc_fields: Ints,
                       fq_fields: Ints, cell_proto: Ints, ic: Ints, notch: Ints, scal: Array,
                       notch_cells: Ints, notch_proto: Ints, rows: Ints, tension: Array,
                       x: Array, p: Complex, theta: Array, tangent: Complex, tol: float,
                       relaxation: float, slow: float, growth: float, info: Array,
                       strain: Array) -> None:
    """:func:`iterate` of members ``j`` of design rows ``rows[j]`` whose cell arrays are read
    from prototype-cell tables (a batch of many designs, :class:`tdcm_ros.model.grid.GridParts`),
    then each converged member's peak notch strain ``strain[j]`` (:func:`peak_strain_row`; the
    others' entries are left untouched).

    Per design row: ``cell_proto`` (W,) each cell's prototype, ``ic``, ``notch``, ``scal`` as
    :func:`iterate` reads them, ``notch_cells`` (notch cells; -1 padding) and ``notch_proto``
    their prototypes. The prototype tables: ``proto_fc`` (P, F, 1) and ``proto_fq`` (P, G, Q),
    of which rows ``fc_fields``, ``fq_fields`` are the iteration's ``fc`` and ``fq`` rows (its
    last ``fq`` row, ``W_A``, is zero: a rigid midline), and ``proto_strain`` (P, 2, samples),
    the strain coefficients ``S0``, ``S1``. A design's rows are laid out (:func:`lay_out`) into
    scratch arrays small enough to stay in cache when its first member comes, and kept for the
    members of the same row that follow it (members ordered by design lay each out once)."""
    n = cell_proto.shape[1]
    fc = np.empty(fc_fields.shape[0] * n)
    fc_rows = fc.reshape((fc_fields.shape[0], n))
    fc_out = fc.reshape((fc_fields.shape[0], n, 1))
    fq = np.zeros((fq_fields.shape[0] + 1, n, proto_fq.shape[2]))
    coefficients = np.empty((2, notch_proto.shape[1], proto_strain.shape[2]))
    both = np.arange(2)
    g, t_a, new_p, new_theta, new_tangent, notch_gaps = row_scratch(n, notch.shape[2])
    last = -1
    for j in range(x.shape[0]):
        row = rows[j]
        if row != last:
            lay_out(cell_proto[row], fc_fields, proto_fc, fc_out)
            lay_out(cell_proto[row], fq_fields, proto_fq, fq)
            lay_out(notch_proto[row], both, proto_strain, coefficients)
            last = row
        iterate_row(fc_rows, fq, ic[row], notch[row], scal[row], tension[j], x[j], p[j],
                    theta[j], tangent[j], tol, relaxation, slow, growth, info[j], g, t_a, new_p,
                    new_theta, new_tangent, notch_gaps)
        if info[j, 1] == CONVERGED:
            strain[j] = peak_strain_row(notch_cells[row], coefficients[0], coefficients[1],
                                        x[j])


def one_offsets(n: int) -> tuple[int, int, int, int, int]:
    """Where :func:`iterate_one`'s output buffer for ``n`` cells puts its parts: the starts of
    ``p``, ``tangent``, ``theta``, ``info`` and of its steps (``x`` is everything before ``p``)."""
    p = 2 * n
    tangent = p + 2 * (n + 1)
    theta = tangent + 2 * (n + 1)
    info = theta + n + 1
    return p, tangent, theta, info, info + 3


def one_size(n: int, budget: int) -> int:
    """Length of :func:`iterate_one`'s output buffer for ``n`` cells and ``budget`` steps."""
    return one_offsets(n)[4] + budget


def iterate_one(fc: Array, fq: Array, ic: Ints, notch: Ints, scal: Array, tension: float,
                x0: Array | None, out: Array, tol: float, relaxation: float, slow: float,
                growth: float) -> tuple[int, int, float]:
    """:func:`iterate` for one member (design row 0) at ``tension`` (N) from ``x0`` (2n,) N m,
    or where None the tendon's own moment ``R_c T`` on the straight body, into the caller's
    ``out`` (:func:`one_size`): the last iterate ``x`` (2n,) N m, the nodes ``p`` (m) and
    ``tangent`` as (real, imag) pairs (2 (n + 1) each), ``theta`` (n + 1) rad, then
    :func:`iterate`'s ``info`` (steps, status, smallest gap (m), the steps (m)); the budget
    is what is left of ``out``. Returns that ``info``'s steps, status and smallest gap."""
    n = fc.shape[2]
    p_at, tangent_at, theta_at, info_at, _ = one_offsets(n)
    x = out[:p_at]
    if x0 is None:
        x[:] = scal[0, 0] * tension
    else:
        x[:] = x0
    p = out[p_at:tangent_at].view(np.complex128)
    tangent = out[tangent_at:theta_at].view(np.complex128)
    theta = out[theta_at:info_at]
    info = out[info_at:]
    g, t_a, new_p, new_theta, new_tangent, notch_gaps = row_scratch(n, notch.shape[2])
    iterate_row(fc[0], fq[0], ic[0], notch[0], scal[0], tension, x, p, theta, tangent, tol,
                relaxation, slow, growth, info, g, t_a, new_p, new_theta, new_tangent, notch_gaps)
    return int(info[0]), int(info[1]), info[2]


def peak_strain_row(cells: Ints, s0: Array, s1: Array, x: Array) -> float:
    """Largest ``|m_a S0 + m_b S1|`` of one member over its notch ``cells`` (-1 padding) and
    their samples ``s0``, ``s1`` (notch cells, samples), from its finite moments ``x`` (2n,)
    N m. Per cell the largest and smallest value are tracked in two independent chains (no
    ``abs``; about 1.4x faster than one ``max(abs)`` chain); the maximum is exact in any
    order, so the result is the same float."""
    n = x.shape[0] // 2
    largest = 0.0
    for k in range(cells.shape[0]):
        i = cells[k]
        if i < 0:
            continue
        a = x[i]
        b = x[n + i]
        high = 0.0
        low = 0.0
        for q in range(s0.shape[1]):
            value = a * s0[k, q] + b * s1[k, q]
            high = max(high, value)
            low = min(low, value)
        largest = max(largest, high, -low)
    return largest


def peak_strains(rows: Ints, cells: Ints, s0: Array, s1: Array, x: Array, out: Array) -> None:
    """:func:`peak_strain_row` of every member ``j`` (design row ``rows[j]`` of ``cells``
    (design row, notch cells) and ``s0``, ``s1`` (design row, notch cells, samples)) from its
    moments ``x[j]`` (M, 2n) N m."""
    for j in range(x.shape[0]):
        row = rows[j]
        out[j] = peak_strain_row(cells[row], s0[row], s1[row], x[j])


KERNELS = ("unit", "integrate_row", "moments_row", "gaps_row", "integrate", "moments", "gaps",
           "peak_strain_row", "iterate_row", "row_scratch", "iterate", "lay_out", "gather",
           "iterate_prototypes", "one_offsets", "iterate_one", "peak_strains")
"""The functions :mod:`tdcm_ros.model.compiled` compiles, callees before callers."""
