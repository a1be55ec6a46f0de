"""The compliance integrals of grid cells, one loop over cells for one design or many, and the
loops that lay the cells out member by member (:func:`lay_cells`, :func:`member_cells`).

Plain Python on NumPy arrays and scalars, in the subset numba compiles:
:mod:`tdcm_ros.model.compiled` runs these functions as they are (``TDCM_JIT=0``) or compiled,
as it does :mod:`tdcm_ros.model.kernel` (NumPy's error model in both builds: a float divided
by zero is inf or nan). :func:`tdcm_ros.model.grid.build_grid` (one design)
and :func:`~tdcm_ros.model.grid.build_grids` (many) both call :func:`cell_integrals` on the
prototype cells of :mod:`tdcm_ros.model.grid_layout`; the module docstring of
:mod:`tdcm_ros.model.grid` says what each integral is.

Per prototype cell ``i`` (inputs, SI units): ``shape[i]``; ``cell[i, :]`` =
``(is_notch, chord, u_a, u_b, a, length, seg_length, u_end, span)`` (``a`` from the segment
start, m). A cell may be the first part ``[u_a, u_b]`` of a whole one (a query station's,
:meth:`tdcm_ros.model.grid.Grid.query`): ``a``, ``length`` (m) and ``u_end`` are the whole
cell's start, arc length and end, so that ``xi`` and the centroid's end offsets are the whole
cell's, and ``span`` is the part's arc length (m), to which its ds weights sum; a whole cell
has ``u_end = u_b`` and ``span = length``.
Per notch shape ``k`` (a member's distinct notch; a tube cell names its member's first):
``design[k, :]`` = ``(profile kind, w_n, w_d, R_outer, r_inner, E, tube moment, w_o, I, x_bar,
fibre)`` with kinds :data:`CIRCULAR` (eq. 13), :data:`RECTANGULAR`, :data:`CUSTOM` (``h1``
read from ``custom[custom_row[i], p, 0]`` at the points ``p`` of :func:`points`, ``sigma``
linear in ``u``), :data:`PRISMATIC` (a section given whole, the same along the notch: its
centroidal ``I`` (m^4), centroid ``x_bar`` (m) and farthest fibre (m) in the last three
columns, unused by the other kinds; ``sigma`` linear in ``u``) and :data:`TABULATED` (a
section changing along the notch, given at every point: ``1/(E I)`` (1/(N m^2)), ``x_bar``
and the farthest fibre (m) in ``custom[custom_row[i], p, :]``; ``sigma`` linear in ``u``).
Every cell is evaluated at ``Q`` Gauss points, under the *nested* rule ``Q * Q`` nested points
(``Q`` per Gauss point, for the partial integrals ``A0``, ``A1``; the *interpolated* rule
takes them from the other points' values instead), ``PEAK_SAMPLES`` equally spaced probes and
its whole cell's two ends ``u_a``, ``u_end``, in that order (:func:`points`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Ints = NDArray[np.int64]
Flags = NDArray[np.bool_]

CIRCULAR = 0
RECTANGULAR = 1
CUSTOM = 2
PRISMATIC = 3
TABULATED = 4
"""Profile kinds of ``design[:, 0]``."""

IS_NOTCH, CHORD, U_A, U_B, START, LENGTH, SEG_LENGTH, U_END, SPAN = range(9)
"""Columns of ``cell``."""
KIND, W_N, W_D, R_OUTER, R_INNER, E, TUBE_MOMENT, W_O, SEC_I, SEC_XBAR, SEC_FIBRE = range(11)
"""Columns of ``design``."""
C0, C1, C0_T, C1_T, C_START, C_END, PEAK_C, PEAK_S, XB_START, XB_END, D_CELL = range(11)
"""Columns of the per-cell output ``fc`` (cells, 11)."""
S_Q, W_Q, XI_Q, C_Q, A0, A1, A0_T, A1_T, XB_Q, K0, K1, D_Q, K2 = range(13)
"""Rows of the per-Gauss-point output ``fq`` (cells, 13, Q)."""
N_JAC, N_XI, N_C, N_XB = range(4)
NODE_ROWS = 4
"""Rows of a cell's values at its Gauss points and probes (the interpolated rule's nodes):
``ds/du`` (m), ``xi``, ``c`` (1/(N m^2)), ``x_bar`` (m)."""

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(24)
STRIP_NODES = 0.5 * (_NODES + 1.0)
STRIP_WEIGHTS = 0.5 * _WEIGHTS
"""Gauss-Legendre nodes and weights on [0, 1] of :func:`disc_strip` (24: the integrand, a
trigonometric polynomial of degree 4 over at most pi, to rounding)."""

SERIES_BELOW = 0.05
"""Below this ``h/R`` the disc-strip moment (:func:`disc_strip_moment`) is its series."""


def disc_strip_moment(h: float, radius: float) -> float:
    """``J(h) = int_0^h y^2 sqrt(radius^2 - y^2) dy``, ``h`` clipped to [0, radius] (m^4); 0
    where ``radius <= 0``. Closed form ``(h/8)(2h^2 - R^2) sqrt(R^2 - h^2) + (R^4/8)
    asin(h/R)``; below ``h/R = SERIES_BELOW``, where its two terms cancel (relative error
    ~1e-16 (R/h)^2), its Taylor series in ``t = h/R`` (``t^2 sqrt(1 - t^2)`` expanded and
    integrated; truncation below 1e-15); at ``h >= radius`` the closed form's value
    ``radius^4 pi / 16`` without calling libm."""
    if radius <= 0.0:
        return 0.0
    r2 = radius * radius
    r4 = r2 * r2
    if h >= radius:
        return (r4 / 8.0) * (0.5 * math.pi)
    hc = max(h, 0.0)
    t = hc / radius
    if t < SERIES_BELOW:
        t2 = t * t
        series = ((((-5.0 / 1408.0) * t2 + (-1.0 / 144.0)) * t2 + (-1.0 / 56.0)) * t2
                  + (-1.0 / 10.0)) * t2 + 1.0 / 3.0
        return r4 * (t2 * t) * series
    root = math.sqrt(max(r2 - hc * hc, 0.0))
    return (hc / 8.0) * (2.0 * hc * hc - r2) * root + (r4 / 8.0) * math.asin(t)


def notched_inertia(h1: float, r_outer: float, r_inner: float) -> float:
    """Eq. 12 inside a notch: ``4 [J(h1, R_outer) - J(h2, r_inner)]``, ``h2 = min(h1,
    r_inner)`` (m^4), the second moment of the tube's annulus where ``|x| <= h1`` (m); the
    uncut tube's where ``h1 >= R_outer``."""
    return 4.0 * (disc_strip_moment(h1, r_outer) - disc_strip_moment(min(h1, r_inner), r_inner))


def notched_inertias(h1: Array, r_outer: Array, r_inner: Array, out: Array) -> None:
    """:func:`notched_inertia` (m^4) of each ``h1[i]``, ``r_outer[i]``, ``r_inner[i]`` (m; 1-D
    arrays of one length) into ``out[i]``."""
    for i in range(h1.shape[0]):
        out[i] = notched_inertia(h1[i], r_outer[i], r_inner[i])


def notch_compliance(h1: float, r_outer: float, r_inner: float, e: float) -> float:
    """``1/(E I)`` (1/(N m^2)) of eq. 12's notched section at half-width ``h1`` (m)."""
    return 1.0 / (e * notched_inertia(h1, r_outer, r_inner))


def disc_strip(lo: float, hi: float, radius: float, about: float
               ) -> tuple[float, float, float]:
    """Area (m^2), ``int (x - about) dA`` (m^3) and ``int (x - about)^2 dA`` (m^4) of the part
    of a disc of ``radius`` (m) centred at ``x = 0`` where ``lo <= x <= hi`` (clipped to the
    disc); zeros for an empty part. By Gauss-Legendre quadrature in the angle ``t`` (``x = R
    sin t``, ``dA = 2 R^2 cos^2 t dt``): the integrand is smooth, every term of the area and of
    the second moment is positive, so a thin strip far from the centre (a deep one-sided cut's
    backbone) keeps full precision where the closed forms' differences lose digits."""
    if radius <= 0.0:
        return 0.0, 0.0, 0.0
    a = min(max(lo, -radius), radius)
    b = min(max(hi, -radius), radius)
    if b <= a:
        return 0.0, 0.0, 0.0
    t_a = math.asin(a / radius)
    span = math.asin(b / radius) - t_a
    area = 0.0
    first = 0.0
    second = 0.0
    for k in range(STRIP_NODES.shape[0]):
        t = t_a + span * STRIP_NODES[k]
        cosine = math.cos(t)
        weight = 2.0 * radius * radius * cosine * cosine * span * STRIP_WEIGHTS[k]
        arm = radius * math.sin(t) - about
        area += weight
        first += weight * arm
        second += weight * arm * arm
    return area, first, second


def offset_section(h1: float, offset: float, r_outer: float, r_inner: float
                   ) -> tuple[float, float, float, float]:
    """``(A, I, x_bar, fibre)`` of the tube ``r_inner <= rho <= r_outer`` where ``offset - h1
    <= x <= offset + h1`` (m): the area (m^2), the second moment about the centroid's axis
    (m^4), the centroid's offset from the tube axis (m, + toward the tendon) and the distance
    from it to the farthest material (m). Moments are taken about the strip's middle, then
    about the centroid (:func:`disc_strip`), each the outer disc's less the lumen's."""
    lo = max(offset - h1, -r_outer)
    hi = min(offset + h1, r_outer)
    middle = 0.5 * (lo + hi)
    area, first, _ = disc_strip(lo, hi, r_outer, middle)
    hole, hole_first, _ = disc_strip(lo, hi, r_inner, middle)
    area -= hole
    x_bar = middle + (first - hole_first) / area
    _, _, second = disc_strip(lo, hi, r_outer, x_bar)
    _, _, hole_second = disc_strip(lo, hi, r_inner, x_bar)
    return area, second - hole_second, x_bar, max(hi - x_bar, x_bar - lo)


def geometry(kind: float, w_n: float, w_d: float, u: float,
             custom: float) -> tuple[float, float, float]:
    """``(sigma, d sigma/du, h1)`` (m) at ``u`` in a notch of profile ``kind``; ``custom`` is
    ``h1`` of a :data:`CUSTOM` profile there (ignored otherwise)."""
    if kind == CIRCULAR:
        angle = math.pi * u
        sine = math.sin(angle)
        return (0.5 * w_n * (1.0 - math.cos(angle)), 0.5 * w_n * math.pi * sine,
                0.5 * (w_n + w_d) - 0.5 * w_n * sine)
    if kind == RECTANGULAR:
        return w_n * u, w_n, 0.5 * w_d
    return w_n * u, w_n, custom


def profile_points(kind: float, w_n: Array, w_d: Array, u: Array, sigma: Array, h1: Array
                   ) -> None:
    """:func:`geometry`'s ``sigma`` and ``h1`` (m) of profile ``kind`` (not :data:`CUSTOM`)
    at each ``u[i]`` of a notch of widths ``w_n[i]``, ``w_d[i]`` (m; 1-D arrays of one
    length) into ``sigma[i]``, ``h1[i]``."""
    for i in range(u.shape[0]):
        s_i, _, h_i = geometry(kind, w_n[i], w_d[i], u[i], 0.0)
        sigma[i] = s_i
        h1[i] = h_i


def point(notch: bool, d: Array, seg_length: float, u: float, custom: Array
          ) -> tuple[float, float, float, float, float]:
    """``(sigma, ds/du, 1/(E I), x_bar, fibre)`` at ``u`` in a cell's segment (m, m,
    1/(N m^2), m, m) of a notch shape with ``design`` row ``d``: the section's centroid offset
    and the distance from it to its farthest fibre (0 in tubes, where no strain is sampled);
    ``custom`` is the point's row of the custom table (module docstring)."""
    if not notch:
        return seg_length * u, seg_length, 1.0 / (d[E] * d[TUBE_MOMENT]), 0.0, 0.0
    if d[KIND] == PRISMATIC:
        return d[W_N] * u, d[W_N], 1.0 / (d[E] * d[SEC_I]), d[SEC_XBAR], d[SEC_FIBRE]
    if d[KIND] == TABULATED:
        return d[W_N] * u, d[W_N], custom[0], custom[1], custom[2]
    sigma, jac, h1 = geometry(d[KIND], d[W_N], d[W_D], u, custom[0])
    if d[W_O] == 0.0:  # eq. 12's symmetric section: the paper's formula, centroid on the axis
        return (sigma, jac, notch_compliance(h1, d[R_OUTER], d[R_INNER], d[E]), 0.0,
                min(h1, d[R_OUTER]))
    _, inertia, x_bar, fibre = offset_section(h1, d[W_O], d[R_OUTER], d[R_INNER])
    return sigma, jac, 1.0 / (d[E] * inertia), x_bar, fibre


def points(cell: Array, gauss_u: Array, probe: Array, nested: bool, out: Array) -> None:
    """Reference coordinates ``u`` of every evaluation point of each cell (cells, P): Gauss
    points, nested points (only for the ``nested`` rule), probes, ends (module docstring)."""
    q_count = gauss_u.shape[0]
    first = q_count + (q_count * q_count if nested else 0)
    for i in range(cell.shape[0]):
        u_a = cell[i, U_A]
        span = cell[i, U_B] - u_a
        for q in range(q_count):
            u_q = u_a + span * gauss_u[q]
            out[i, q] = u_q
            if nested:
                inner = u_q - u_a
                for k in range(q_count):
                    out[i, q_count + q * q_count + k] = u_a + inner * gauss_u[k]
        for k in range(probe.shape[0]):
            out[i, first + k] = u_a + span * probe[k]
        out[i, first + probe.shape[0]] = u_a
        out[i, first + probe.shape[0] + 1] = cell[i, U_END]


def cell_integrals(shape: Ints, cell: Array, design: Array, custom_row: Ints,
                   custom_table: Array, gauss_u: Array, gauss_w: Array, matrix: Array,
                   partial: Array, partial_node: Ints, probe: Array, fc: Array, fq: Array,
                   strain: Array) -> None:
    """Every integral of each cell (module docstring) into ``fc`` (cells, 11) and ``fq``
    (cells, 13, Q); ``strain`` (cells, 2, probes) gets the bending-strain coefficients
    ``(1 - xi, xi) c fibre`` at the probes of notch cells (0 elsewhere; ``fibre`` from the
    centroid to the farthest material, ``min(h1, R_outer)`` for the paper's section).
    ``matrix`` (Q, Q) is the Gauss points' partial-integration matrix on [0, 1].

    The partial integrals ``A0``, ``A1``, ``D_Q`` from the cell's start to each Gauss point
    take one of two rules: ``partial`` of shape (Q, 0) selects the *nested* one (a Q-point
    Gauss rule on each ``[u_a, u_q]``: Q * Q more evaluations); ``partial`` of shape (Q, K)
    is the *interpolated* one, weights on [0, 1] of the values at the nodes ``partial_node``
    (K,), columns of the cell's Gauss points (0 to Q - 1) then probes (Q on)
    (:func:`tdcm_ros.model.grid.partial_weights`: no evaluation beyond those).

    Where a notch's backbone is off the axis (``w_o``): ``XB_START``, ``XB_END`` are the
    centroid's offset ``x_bar`` at the cell's ends, about which its end moments are taken, and
    ``XB_Q`` at the Gauss points. The moment about the moving centroid is the line between the
    end moments less ``T dx``, ``dx = x_bar - ((1 - xi) x_bar_a + xi x_bar_b)`` (the tendon's
    pull ``T`` along the body, exact where the tendon follows it): ``D_Q`` and ``D_CELL`` are
    ``int c dx ds`` to each Gauss point and over the cell (rad/(N m)), taken ``T`` times from
    its angles. The tube axis, ``-x_bar`` from the neutral fibre, stretches by ``x_bar kappa``
    (m/m): ``K0``, ``K1``, ``K2`` are ``w_q x_bar c`` times ``1 - xi``, ``xi`` and ``dx``, and
    its ds weight is ``w_q + m_a K0 + m_b K1 - T K2``."""
    q_count = gauss_u.shape[0]
    p_count = probe.shape[0]
    nested = partial.shape[1] == 0
    first = q_count + (q_count * q_count if nested else 0)
    ends = first + p_count
    no_custom = np.zeros((ends + 2, custom_table.shape[2]))
    node = np.empty((NODE_ROWS, q_count + p_count))
    for i in range(cell.shape[0]):
        d = design[shape[i]]
        c = cell[i]
        custom = custom_table[custom_row[i]] if custom_row[i] >= 0 else no_custom
        notch = c[IS_NOTCH] != 0.0
        seg_length = c[SEG_LENGTH]
        u_a = c[U_A]
        span = c[U_B] - u_a
        start = c[START]
        length = c[LENGTH]
        out = fq[i]
        _, _, fc[i, C_START], x_a, _ = point(notch, d, seg_length, u_a, custom[ends])
        _, _, fc[i, C_END], x_b, _ = point(notch, d, seg_length, c[U_END], custom[ends + 1])
        fc[i, XB_START] = x_a
        fc[i, XB_END] = x_b
        total = 0.0
        for q in range(q_count):
            u_q = u_a + span * gauss_u[q]
            sigma, jac, c_q, x_bar, _ = point(notch, d, seg_length, u_q, custom[q])
            out[W_Q, q] = span * gauss_w[q] * jac
            total += out[W_Q, q]
            out[S_Q, q] = sigma
            out[XI_Q, q] = (sigma - start) / length
            out[C_Q, q] = c_q
            out[XB_Q, q] = x_bar
            node[N_JAC, q] = jac
            node[N_XI, q] = out[XI_Q, q]
            node[N_C, q] = c_q
            node[N_XB, q] = x_bar
        _probes(notch, d, seg_length, u_a, span, start, length, probe, custom[first:ends],
                q_count, node, fc[i], strain[i])
        if nested:
            _nested_partials(notch, d, seg_length, u_a, span, start, length, x_a, x_b,
                             gauss_u, gauss_w, custom[q_count:first], out)
        else:
            _interpolated_partials(span, x_a, x_b, partial, partial_node, node, out)
        _weights_and_chords(c[CHORD] != 0.0, c[SPAN] / total if total > 0.0 else 0.0,
                            gauss_w, matrix, out, fc[i])
        whole = 0.0
        for q in range(q_count):
            xi = out[XI_Q, q]
            w_c = out[W_Q, q] * out[C_Q, q]
            off = out[XB_Q, q] - ((1.0 - xi) * x_a + xi * x_b)
            stretch = w_c * out[XB_Q, q]
            out[K0, q] = stretch * (1.0 - xi)
            out[K1, q] = stretch * xi
            out[K2, q] = stretch * off
            whole += w_c * off
        fc[i, D_CELL] = whole


def _probes(notch: bool, d: Array, seg_length: float, u_a: float, span: float, start: float,
            length: float, probe: Array, custom: Array, column: int, node: Array, fc: Array,
            strain: Array) -> None:
    """One cell's values at its probes ``u_a + span probe[k]``: the peak compliance
    ``PEAK_C`` (1/(N m^2)) and where it is ``PEAK_S`` (m from the segment start) into ``fc``,
    the strain coefficients into ``strain`` (2, probes), and ``ds/du`` (m), ``xi``, ``c`` and
    ``x_bar`` (m) into ``node[:, column + k]`` (``custom``: the probes' rows of the custom
    table)."""
    peak = -1.0
    for k in range(probe.shape[0]):
        s_k, jac_k, c_k, x_k, fibre = point(notch, d, seg_length, u_a + span * probe[k],
                                            custom[k])
        if c_k > peak:
            peak = c_k
            fc[PEAK_C] = c_k
            fc[PEAK_S] = s_k
        weight = c_k * fibre
        xi = (s_k - start) / length
        strain[0, k] = (1.0 - xi) * weight
        strain[1, k] = xi * weight
        node[N_JAC, column + k] = jac_k
        node[N_XI, column + k] = xi
        node[N_C, column + k] = c_k
        node[N_XB, column + k] = x_k


def _nested_partials(notch: bool, d: Array, seg_length: float, u_a: float, span: float,
                     start: float, length: float, x_a: float, x_b: float, gauss_u: Array,
                     gauss_w: Array, custom: Array, out: Array) -> None:
    """The nested rule: ``A0``, ``A1`` (rad/(N m)) and ``D_Q`` (rad/(N m)) of one cell by a
    Gauss rule on each ``[u_a, u_q]`` into ``out`` (``custom``: the nested points' rows of
    the custom table)."""
    q_count = gauss_u.shape[0]
    for q in range(q_count):
        inner = (u_a + span * gauss_u[q]) - u_a
        a0 = 0.0
        a1 = 0.0
        d0 = 0.0
        for k in range(q_count):
            s_k, jac_k, c_k, x_k, _ = point(notch, d, seg_length, u_a + inner * gauss_u[k],
                                            custom[q * q_count + k])
            ds = inner * gauss_w[k] * jac_k
            xi = (s_k - start) / length
            a0 += ds * (1.0 - xi) * c_k
            a1 += ds * xi * c_k
            d0 += ds * c_k * (x_k - ((1.0 - xi) * x_a + xi * x_b))
        out[A0, q] = a0
        out[A1, q] = a1
        out[D_Q, q] = d0


def _interpolated_partials(span: float, x_a: float, x_b: float, partial: Array,
                           partial_node: Ints, node: Array, out: Array) -> None:
    """The interpolated rule: ``A0``, ``A1`` and ``D_Q`` (rad/(N m)) of one cell from its
    values at the Gauss points and probes ``node`` (rows ``N_JAC``, ``N_XI``, ``N_C``,
    ``N_XB``), of which the weights ``partial`` (Q, K) on [0, 1] take columns
    ``partial_node`` (K,), into ``out``."""
    for q in range(partial.shape[0]):
        a0 = 0.0
        a1 = 0.0
        d0 = 0.0
        for k in range(partial.shape[1]):
            j = partial_node[k]
            ds = span * partial[q, k] * node[N_JAC, j]
            xi = node[N_XI, j]
            c_j = node[N_C, j]
            a0 += ds * (1.0 - xi) * c_j
            a1 += ds * xi * c_j
            d0 += ds * c_j * (node[N_XB, j] - ((1.0 - xi) * x_a + xi * x_b))
        out[A0, q] = a0
        out[A1, q] = a1
        out[D_Q, q] = d0


def _weights_and_chords(chord: bool, scale: float, gauss_w: Array, matrix: Array,
                        out: Array, fc: Array) -> None:
    """Scale one cell's ds weights ``out[W_Q]`` by ``scale`` (so they sum to its length), then
    its ``C0``, ``C1`` and chord terms (``tdcm_ros.model.grid``: ``m'' = -T c m`` on a chord,
    ``G0 = xi int_a^b A0 ds - int_a^s A0 ds``, ``C0_T = int c G0 ds``, ``A0_T(s) = int_a^s c G0``
    by the partial-integration ``matrix``; zero where the tendon follows the body)."""
    q_count = gauss_w.shape[0]
    ds_du = np.empty(q_count)
    cg = np.empty(q_count)
    c0 = 0.0
    c1 = 0.0
    for q in range(q_count):
        out[W_Q, q] *= scale
        ds_du[q] = out[W_Q, q] / gauss_w[q]
        w_c = out[W_Q, q] * out[C_Q, q]
        c0 += w_c * (1.0 - out[XI_Q, q])
        c1 += w_c * out[XI_Q, q]
    fc[C0] = c0
    fc[C1] = c1
    for term in range(2):
        a_row = A0 + term
        whole = 0.0
        for q in range(q_count):
            whole += out[W_Q, q] * out[a_row, q]
        c_t = 0.0
        for q in range(q_count):
            partial = 0.0
            for k in range(q_count):
                partial += out[a_row, k] * ds_du[k] * matrix[q, k]
            cg[q] = out[C_Q, q] * (out[XI_Q, q] * whole - partial)
            c_t += out[W_Q, q] * cg[q]
        fc[C0_T + term] = c_t if chord else 0.0
        for q in range(q_count):
            partial = 0.0
            for k in range(q_count):
                partial += cg[k] * ds_du[k] * matrix[q, k]
            out[A0_T + term, q] = partial if chord else 0.0


def lay_cells(seg_counts: Ints, slot_kind: Ints, kind_first: Ints, kind_is_notch: Flags,
              start: Array, shape_first: Ints, proto_shape: Ints, proto_a: Array,
              proto_seg_length: Array, proto_u_a: Array, proto_u_b: Array, follows: bool,
              ints: Ints, floats: Array, flags: Flags) -> None:
    """Every member's segments end to end, each a copy of its kind's prototype cells: the
    cells of :class:`tdcm_ros.model.grid_layout.CellTable`, flat (members one after another,
    base to tip).

    Per member ``m`` and slot ``s`` (base, then notch ``i`` and the tube after it):
    ``seg_counts`` its cells (0 for an absent segment), ``slot_kind`` its segment kind,
    ``start`` its start along the body (m); per member and kind ``kind_first`` its first
    prototype cell, ``kind_is_notch``; per member ``shape_first`` (its first notch shape); per
    prototype cell its notch shape and its ``a`` (from the segment start), ``seg_length``,
    ``u_a``, ``u_b``; ``follows``: the tendon follows the body in notches (else in tubes).
    Writes per cell ``ints`` (6, cells): member, prototype, shape (within the member; 0 in
    tubes), notch index (-1 in tubes), chord start and end node (its segment's end nodes,
    within the member); ``floats`` (5, cells): segment start, segment length (m), ``u_a``,
    ``u_b``, start along the body ``a`` (m); ``flags`` (2, cells): is a notch, the tendon
    follows the body there."""
    c = 0
    for m in range(seg_counts.shape[0]):
        node = 0
        for s in range(seg_counts.shape[1]):
            kind = slot_kind[m, s]
            notch = kind_is_notch[m, kind]
            size = seg_counts[m, s]
            begin = start[m, s]
            for j in range(size):
                p = kind_first[m, kind] + j
                ints[0, c] = m
                ints[1, c] = p
                ints[2, c] = proto_shape[p] - shape_first[m] if notch else 0
                ints[3, c] = (s - 1) // 2 if notch else -1
                ints[4, c] = node
                ints[5, c] = node + size
                floats[0, c] = begin
                floats[1, c] = proto_seg_length[p]
                floats[2, c] = proto_u_a[p]
                floats[3, c] = proto_u_b[p]
                floats[4, c] = begin if j == 0 else begin + proto_a[p]
                flags[0, c] = notch
                flags[1, c] = notch == follows
                c += 1
            node += size


def member_cells(rows: Ints, first: Ints, count: Ints, prototype: Ints, is_notch: Flags,
                 constrained: Flags, chord_start: Ints, chord_end: Ints, pad: int,
                 cell_proto: Ints, ic: Ints, notch_cells: Ints, notch_proto: Ints) -> None:
    """For members ``rows`` of a flat cell table (their cells ``first`` on, ``count`` of them;
    per cell its ``prototype``, ``is_notch``, ``constrained``, chord start and end node),
    padded to ``W = cell_proto.shape[1]`` cells: each slot's prototype cell ``cell_proto`` (R,
    W; ``pad``, the zero row, in padding), the iteration's ``ic`` (R, 3, W: chord start and end
    node, 1 where the tendon follows the body; in padding the tip node twice and 1), and its
    notch cells ``notch_cells`` (R, notch cells; -1 in padding) with their prototypes
    ``notch_proto`` (``pad`` in padding)."""
    for r in range(rows.shape[0]):
        m = rows[r]
        tip = count[m]
        k = 0
        for j in range(cell_proto.shape[1]):
            if j < tip:
                c = first[m] + j
                cell_proto[r, j] = prototype[c]
                ic[r, 0, j] = chord_start[c]
                ic[r, 1, j] = chord_end[c]
                ic[r, 2, j] = 1 if constrained[c] else 0
                if is_notch[c]:
                    notch_cells[r, k] = j
                    notch_proto[r, k] = prototype[c]
                    k += 1
            else:
                cell_proto[r, j] = pad
                ic[r, 0, j] = tip
                ic[r, 1, j] = tip
                ic[r, 2, j] = 1
        for j in range(k, notch_cells.shape[1]):
            notch_cells[r, j] = -1
            notch_proto[r, j] = pad


KERNELS = ("disc_strip_moment", "notched_inertia", "notched_inertias", "notch_compliance",
           "disc_strip", "offset_section", "geometry", "profile_points", "point", "points",
           "_weights_and_chords", "_probes", "_nested_partials",
           "_interpolated_partials", "cell_integrals", "lay_cells", "member_cells")
"""The functions :mod:`tdcm_ros.model.compiled` compiles, callees before callers."""
