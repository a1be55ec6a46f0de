"""Discretisation of the body into cells, with every compliance integral Algorithm 1 needs.

The body is split into segments (tubes and notches); cell boundaries fall on every ``l_i``
and ``r_i``. Within a cell the bending moment is taken linear between its one-sided end
values ``m_a``, ``m_b`` (N m) and the compliance ``c(s) = 1/(E I(s))`` (1/(N m^2)) is
integrated exactly by Gauss-Legendre quadrature in the profile's reference coordinate ``u``.
For each cell the grid stores:

- ``C0 = int (1 - xi) c ds``, ``C1 = int xi c ds`` so the cell's bend angle is
  ``m_a C0 + m_b C1`` (``xi = (s - a)/(b - a)``);
- at each quadrature point ``s_q``, the partial integrals ``A0_q``, ``A1_q`` of the same
  integrands from ``a`` to ``s_q``, so the tangent angle there is known exactly and the
  cell's planar displacement (eq. 2) is one quadrature of ``(sin, cos)`` of it.

Grids depend only on the design and the discretisation settings and are cached.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.section import notched_moment
from tdcm_ros.model.settings import SolverSettings

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
#: ``(cells, A0_s, A1_s, A0_r, A1_r, w_r)`` of :meth:`Grid.query`.
Query = tuple[IntArray, Array, Array, Array, Array, Array]

PEAK_SAMPLES = 17
#: Distinct query station sets a grid keeps (see :meth:`Grid.query`).
QUERY_CACHE_SIZE = 8


@dataclass(frozen=True, eq=False)
class Grid:
    """Cells of one design under one discretisation (see module docstring); SI units."""

    design: Design
    s_nodes: Array
    is_notch: NDArray[np.bool_]
    notch_index: IntArray
    seg_start: Array
    seg_length: Array
    u_a: Array
    u_b: Array
    constrained: NDArray[np.bool_]
    chord_cells: IntArray
    chord_start_node: IntArray
    chord_end_node: IntArray
    gauss_u: Array
    gauss_w: Array
    s_q: Array
    w_q: Array
    xi_q: Array
    c_q: Array
    C0: Array
    C1: Array
    A0: Array
    A1: Array
    c_start: Array
    c_end: Array
    peak_c: Array
    peak_s: Array
    notch_left_node: IntArray
    notch_right_node: IntArray
    _queries: dict[bytes, Query] = field(default_factory=dict, init=False, compare=False,
                                         repr=False)

    @property
    def constrained_cells(self) -> IntArray:
        """Indices of cells where the tendon follows the offset curve."""
        return np.flatnonzero(self.constrained)

    @property
    def constrained_peak_c(self) -> float:
        """Largest compliance (1/(N m^2)) over cells where the tendon follows the body."""
        cells = self.constrained_cells
        return float(np.max(self.peak_c[cells])) if cells.size else 0.0

    @property
    def n_cells(self) -> int:
        """Number of cells."""
        return int(self.s_nodes.size - 1)

    @property
    def a(self) -> Array:
        """Cell start arc lengths (m)."""
        return self.s_nodes[:-1]

    @property
    def length(self) -> Array:
        """Cell lengths (m)."""
        return np.diff(self.s_nodes)

    def local_sigma(self, cells: IntArray, u: Array) -> Array:
        """Arc length from each cell's segment start (m) at reference coordinate ``u``."""
        w_n = self.design.w_n
        notch = self.is_notch[cells]
        return np.where(notch, self.design.profile.sigma(u, w_n), self.seg_length[cells] * u)

    def jacobian(self, cells: IntArray, u: Array) -> Array:
        """``ds/du`` (m) at ``u`` in each cell's segment."""
        notch = self.is_notch[cells]
        return np.where(notch, self.design.profile.dsigma_du(u, self.design.w_n),
                        self.seg_length[cells] + 0.0 * u)

    def compliance(self, cells: IntArray, u: Array) -> Array:
        """``1/(E I)`` (1/(N m^2)) at reference coordinate ``u`` of each cell's segment."""
        d = self.design
        notch = self.is_notch[cells]
        h1 = d.profile.h1(u, d.w_n, d.w_d)
        inertia = np.where(notch, notched_moment(h1, d.R_outer, d.r_inner), d.tube_second_moment)
        return 1.0 / (d.E * inertia)

    def u_of_s(self, cells: IntArray, s: Array) -> Array:
        """Inverse of :meth:`local_sigma`: reference coordinate of arc length ``s`` (m)."""
        sigma = s - self.seg_start[cells]
        u_lin = sigma / self.seg_length[cells]
        if self.design.profile.name != "circular":
            return u_lin
        ratio = np.clip(1.0 - 2.0 * sigma / self.design.w_n, -1.0, 1.0)
        return np.where(self.is_notch[cells], np.arccos(ratio) / np.pi, u_lin)

    def query(self, s: Array) -> Query:
        """Cells of arc lengths ``s`` (m) and their :meth:`partial_integrals`, kept for the last
        ``QUERY_CACHE_SIZE`` distinct ``s`` (a node asks for the same stations at every input).
        The arrays are shared: callers must not modify them."""
        key = s.tobytes()
        found = self._queries.get(key)
        if found is None:
            cells = np.clip(np.searchsorted(self.s_nodes, s, side="right") - 1, 0,
                            self.n_cells - 1)
            found = (cells, *self.partial_integrals(cells, s))
            if len(self._queries) >= QUERY_CACHE_SIZE:
                del self._queries[next(iter(self._queries))]
            self._queries[key] = found
        return found

    def partial_integrals(self, cells: IntArray, s: Array
                          ) -> tuple[Array, Array, Array, Array, Array]:
        """Integrals from each cell's start ``a`` to a query ``s`` inside it (SI units).

        Returns ``(A0_s, A1_s, A0_r, A1_r, w_r)``: ``A0``/``A1`` at ``s`` (shape (k,)), at the
        Gauss points of ``[a, s]`` (shape (k, Q)), and those points' ds weights (m).
        """
        ua = self.u_a[cells][:, None]
        us = self.u_of_s(cells, s)[:, None]
        u_r = ua + (us - ua) * self.gauss_u[None, :]
        cells_r = np.broadcast_to(cells[:, None], u_r.shape)
        w_r = _exact_length((us - ua) * self.gauss_w[None, :] * self.jacobian(cells_r, u_r),
                            s - self.s_nodes[cells])
        a0_r, a1_r = _nested(self, cells_r, ua, u_r)
        a0_s, a1_s = _nested(self, cells[:, None], ua, us)
        return a0_s[:, 0], a1_s[:, 0], a0_r, a1_r, w_r


def _exact_length(weights: Array, length: Array) -> Array:
    """Scale ds quadrature weights (m) so each row sums to its exact arc length (m): a straight
    cell then integrates to its length exactly, whatever the profile's Jacobian."""
    total = np.sum(weights, axis=-1, keepdims=True)
    return weights * np.where(total > 0.0, length[..., None] / np.where(total > 0, total, 1.0), 0.0)


def _nested(grid: Grid, cells: IntArray, ua: Array, u_end: Array) -> tuple[Array, Array]:
    """``A0``, ``A1`` from reference coordinate ``ua`` to each ``u_end`` of the same cell.

    ``cells`` and ``u_end`` share a shape; ``ua`` broadcasts against them.
    """
    span = u_end - ua
    inner_u = ua[..., None] + span[..., None] * grid.gauss_u
    inner_cells = np.broadcast_to(cells[..., None], inner_u.shape)
    inner_ds = span[..., None] * grid.gauss_w * grid.jacobian(inner_cells, inner_u)
    a_cell = grid.s_nodes[inner_cells]
    length = grid.s_nodes[inner_cells + 1] - a_cell
    s_inner = grid.seg_start[inner_cells] + grid.local_sigma(inner_cells, inner_u)
    xi = (s_inner - a_cell) / length
    c = grid.compliance(inner_cells, inner_u)
    return np.sum(inner_ds * (1.0 - xi) * c, axis=-1), np.sum(inner_ds * xi * c, axis=-1)


def _segments(design: Design) -> list[tuple[bool, int, float, float]]:
    """(is_notch, notch index or -1, start, end) of every non-empty segment, base to tip (m)."""
    left, right = design.notch_bounds()
    segments: list[tuple[bool, int, float, float]] = []
    if design.w_base > 0.0:
        segments.append((False, -1, 0.0, float(left[0])))
    for i in range(design.N):
        segments.append((True, i, float(left[i]), float(right[i])))
        if i < design.N - 1 and design.w_t > 0.0:
            segments.append((False, -1, float(right[i]), float(left[i + 1])))
    if design.w_tip > 0.0:
        segments.append((False, -1, float(right[-1]), design.length))
    return segments


def _check_custom_profile(design: Design) -> None:
    if design.profile.name in ("circular", "rectangular"):
        return
    u = np.linspace(0.0, 1.0, 65)
    try:
        h1 = design.profile.h1(u, design.w_n, design.w_d)
    except Exception as exc:  # a user callable may raise anything: report it as bad input
        raise InvalidDesignError(f"h1(s) raised {exc!r}", parameter="h1(s)", value=None,
                                 allowed="a function of sigma in [0, w_n] m") from exc
    if h1.shape != u.shape or not np.all(np.isfinite(h1)) or np.any(h1 <= 0.0):
        bad = h1[~(np.isfinite(h1) & (h1 > 0.0))] if h1.shape == u.shape else h1
        raise InvalidDesignError(
            f"h1(s) must be finite and > 0 m across the notch, got {np.ravel(bad)[:3]!r}",
            parameter="h1(s)", value=np.ravel(bad)[:3].tolist(), allowed="(0, inf) m")


def _check_rigidity(design: Design) -> None:
    """Raise :class:`InvalidDesignError` unless the flexural rigidity ``E I`` (N m^2) is at least
    the smallest normal double at ``PEAK_SAMPLES`` stations of a notch and in the tubes, so the
    compliance ``1/(E I)`` is finite (a backbone or wall thinner than floating point resolves)."""
    u = np.linspace(0.0, 1.0, PEAK_SAMPLES)
    h1 = design.profile.h1(u, design.w_n, design.w_d)
    rigidity = design.E * np.append(notched_moment(h1, design.R_outer, design.r_inner),
                                    design.tube_second_moment)
    floor = float(np.finfo(float).tiny)
    if not np.all(rigidity >= floor):
        least = float(np.min(rigidity))
        raise InvalidDesignError(
            f"E*I = {least:.3g} N m^2 (E = {design.E:g} Pa, w_d = {design.w_d:g} m, R_outer = "
            f"{design.R_outer:g} m, r_inner = {design.r_inner:g} m) is out of range; allowed: "
            f"[{floor:.3g}, inf) N m^2, so that 1/(E I) is finite",
            parameter="E*I", value=least, allowed=f"[{floor:.3g}, inf) N m^2")


def build_grid(design: Design, settings: SolverSettings) -> Grid:
    """The (cached) grid for ``design`` under ``settings``' routing and discretisation."""
    return _build_grid(design, settings.routing, settings.cells_per_notch,
                       settings.cells_per_tube, settings.quad_order)


@lru_cache(maxsize=512)
def _build_grid(design: Design, routing: str, cells_per_notch: int, cells_per_tube: int,
                quad_order: int) -> Grid:
    _check_custom_profile(design)
    _check_rigidity(design)
    segments = _segments(design)
    is_notch_l: list[bool] = []
    notch_l: list[int] = []
    start_l: list[float] = []
    len_l: list[float] = []
    ua_l: list[float] = []
    ub_l: list[float] = []
    seg_first_cell: list[int] = []
    for notch, index, start, end in segments:
        count = cells_per_notch if notch else cells_per_tube
        seg_first_cell.append(len(ua_l))
        u = np.linspace(0.0, 1.0, count + 1)
        for k in range(count):
            is_notch_l.append(notch)
            notch_l.append(index)
            start_l.append(start)
            len_l.append(end - start)
            ua_l.append(float(u[k]))
            ub_l.append(float(u[k + 1]))
    seg_first_cell.append(len(ua_l))
    is_notch = np.array(is_notch_l)
    n = is_notch.size
    cells = np.arange(n)
    seg_start = np.array(start_l)
    seg_length = np.array(len_l)
    u_a = np.array(ua_l)
    u_b = np.array(ub_l)
    w_n = design.w_n
    sigma_a = np.where(is_notch, design.profile.sigma(u_a, w_n), seg_length * u_a)
    s_a = seg_start + sigma_a
    s_nodes = np.append(s_a, design.length)
    for cell in seg_first_cell[1:-1]:
        s_nodes[cell] = seg_start[cell]

    gauss_x, gauss_wt = np.polynomial.legendre.leggauss(quad_order)
    gauss_u = 0.5 * (gauss_x + 1.0)
    gauss_w = 0.5 * gauss_wt

    partial = Grid(design=design, s_nodes=s_nodes, is_notch=is_notch,
                   notch_index=np.array(notch_l), seg_start=seg_start, seg_length=seg_length,
                   u_a=u_a, u_b=u_b, constrained=np.zeros(n, bool),
                   chord_cells=np.zeros(0, np.int64), chord_start_node=np.zeros(n, np.int64),
                   chord_end_node=np.zeros(n, np.int64), gauss_u=gauss_u, gauss_w=gauss_w,
                   **{k: np.zeros(0) for k in ("s_q", "w_q", "xi_q", "c_q", "C0", "C1", "A0",
                                                "A1", "c_start", "c_end", "peak_c", "peak_s")},
                   notch_left_node=np.zeros(0, np.int64), notch_right_node=np.zeros(0, np.int64))

    span = (u_b - u_a)[:, None]
    uq = u_a[:, None] + span * gauss_u[None, :]
    cq_cells = np.broadcast_to(cells[:, None], uq.shape)
    length = np.diff(s_nodes)
    w_q = _exact_length(span * gauss_w[None, :] * partial.jacobian(cq_cells, uq), length)
    s_q = seg_start[:, None] + partial.local_sigma(cq_cells, uq)
    xi_q = (s_q - s_nodes[:-1, None]) / length[:, None]
    c_q = partial.compliance(cq_cells, uq)
    big_c0 = np.sum(w_q * (1.0 - xi_q) * c_q, axis=1)
    big_c1 = np.sum(w_q * xi_q * c_q, axis=1)
    a0, a1 = _nested(partial, cq_cells, u_a[:, None], uq)

    c_start = partial.compliance(cells, u_a)
    c_end = partial.compliance(cells, u_b)
    probe_u = u_a[:, None] + span * np.linspace(0.0, 1.0, PEAK_SAMPLES)[None, :]
    probe_cells = np.broadcast_to(cells[:, None], probe_u.shape)
    probe_c = partial.compliance(probe_cells, probe_u)
    arg = np.argmax(probe_c, axis=1)
    peak_c = probe_c[cells, arg]
    peak_s = seg_start + partial.local_sigma(cells, probe_u[cells, arg])

    constrained = is_notch if routing == "paper" else ~is_notch
    seg_of_cell = np.repeat(np.arange(len(segments)), np.diff(seg_first_cell))
    first = np.array(seg_first_cell)
    chord_start = first[seg_of_cell]
    chord_end = first[seg_of_cell + 1]
    notch_left = np.array([first[j] for j, seg in enumerate(segments) if seg[0]])
    notch_right = np.array([first[j + 1] for j, seg in enumerate(segments) if seg[0]])

    return Grid(design=design, s_nodes=s_nodes, is_notch=is_notch, notch_index=np.array(notch_l),
                seg_start=seg_start, seg_length=seg_length, u_a=u_a, u_b=u_b,
                constrained=constrained, chord_cells=np.flatnonzero(~constrained),
                chord_start_node=chord_start, chord_end_node=chord_end, gauss_u=gauss_u,
                gauss_w=gauss_w, s_q=s_q, w_q=w_q, xi_q=xi_q, c_q=c_q, C0=big_c0, C1=big_c1,
                A0=a0, A1=a1, c_start=c_start, c_end=c_end, peak_c=peak_c, peak_s=peak_s,
                notch_left_node=notch_left, notch_right_node=notch_right)
