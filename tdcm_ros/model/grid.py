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
  cell's planar displacement (eq. 2) is one quadrature of ``(sin, cos)`` of it;
- ``strain0``, ``strain1`` (cells, ``PEAK_SAMPLES``): the bending strain at equally spaced
  probes of a notch cell is ``|m_a strain0 + m_b strain1|`` (``(1 - xi | xi) c fibre``, the
  farthest material from the section's centroid, ``min(h1, R_outer)`` for the paper's
  section; zero in tubes);
- where a notch's backbone is off the tube axis (``Design.w_o``), its sections' centroids
  are too: ``xbar_q``, ``xbar_start``, ``xbar_end`` (m, + toward the tendon) at the Gauss
  points and the cell's ends. The moments ``m_a``, ``m_b`` are then taken about the centroid
  (the neutral axis of the section, which bends without stretching), and the body is still
  drawn along the tube axis, which stretches by ``x_bar kappa`` (m/m) there: ``K0``, ``K1``
  (``w_q x_bar c (1 - xi | xi)``) add ``m_a K0 + m_b K1`` to each Gauss point's ds weight.
  Integrating the axis keeps the notch faces, the tendon's offset and every output where
  they are for symmetric sections (all zero there: the paper's model unchanged). Inside a
  cell the moment about the moving centroid is taken linear like any other (exact where
  ``x_bar`` is constant along the notch, e.g. a rectangular one-sided cut);
- on cells the tendon crosses as a chord, ``A0_T``, ``A1_T``, ``C0_T``, ``C1_T``: the same per
  newton of tension for the chord moment's non-linear part (``m'' = -T c m``, see
  :func:`tdcm_ros.model.grid_kernel.cell_integrals`). A kernel that uses them takes ``A0 + T A0_T`` etc. in place of
  ``A0``; they are zero where the tendon follows the body.

Grids depend only on the design and the discretisation settings and are cached. Where the
cells go (``uniform`` or ``adaptive``) is :mod:`tdcm_ros.model.grid_layout`'s job; the
integrals of each segment kind's cells are computed once per design by the compiled
:func:`tdcm_ros.model.grid_kernel.cell_integrals` (:class:`GridParts`) and copied along the
body. :func:`build_grids` builds many designs' grids at once into a :class:`GridStack`;
:func:`build_grid` is the same build with one member. The fields the kernels read are laid out
once, in the kernel's layout (:class:`~tdcm_ros.model.cells.Cells`, :meth:`GridParts.cells`):
a grid's ``C0``, ``A0``, ``constrained`` ... are views of its ``cells``, and the solver, the
batch solver and the limit checks read the same numbers.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, fields
from functools import cached_property, lru_cache
from itertools import pairwise
from typing import Any, Generic, NamedTuple, TypeVar, overload

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model import grid_kernel
from tdcm_ros.model.cells import (
    FC_FIELDS,
    FC_NAMES,
    FC_ROWS,
    FQ_FIELDS,
    FQ_NAMES,
    FQ_ROWS,
    IC_NAMES,
    NOTCH_NAMES,
    W_A_ROW,
    Cells,
)
from tdcm_ros.model.compiled import grid_kernels, kernels
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidDesignError, InvalidSettingsError
from tdcm_ros.model.grid_kernel import (
    CIRCULAR,
    CUSTOM,
    PRISMATIC,
    RECTANGULAR,
    TABULATED,
)
from tdcm_ros.model.grid_layout import (
    PEAK_SAMPLES,
    CellTable,
    Members,
    Prototypes,
    cell_table,
    prototypes,
)
from tdcm_ros.model.profiles import PRISMATIC_PROFILES, SlicedProfile
from tdcm_ros.model.quiet import quiet_fp
from tdcm_ros.model.section import tube_area
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.tendons import TendonLayout, grid_routing, tendon_layout

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
Scalar = TypeVar("Scalar", bound=np.generic)
class Query(NamedTuple):
    """:meth:`Grid.query`'s answer for stations ``s``: each one's cell and the integrals from
    the cell's start to it (:meth:`Grid.partial_integrals`; SI units)."""

    cells: IntArray
    a0_s: Array
    a1_s: Array
    d_s: Array
    a0_r: Array
    a1_r: Array
    d_r: Array
    w_r: Array
    k0_r: Array
    k1_r: Array
    k2_r: Array
    wa_r: Array

NESTED, INTERPOLATED = "nested", "interpolated"
#: Rules for the partial integrals ``A0``, ``A1``, ``D_Q`` from a cell's start to its Gauss
#: points (:func:`tdcm_ros.model.grid_kernel.cell_integrals`): ``nested``, a Gauss rule on each
#: ``[a, s_q]`` (Q * Q more compliance evaluations per cell: :func:`build_grid`, the single
#: solve's grid, and the default of every build), and ``interpolated``, :func:`partial_weights`
#: on the values the cell has at its Gauss points and probes (no further evaluation; a batch
#: opts in with ``solve_batch(..., partials="interpolated")``: its answers then differ from the
#: single solve's within the grid's accuracy, ``bench/grid_accuracy.py``).
PARTIAL_RULES = (NESTED, INTERPOLATED)
#: Nearest a probe may be to a Gauss point (in the cell's ``u`` on [0, 1]) to be a node of the
#: interpolated rule (nearer, the interpolation's weights grow: :func:`partial_weights`).
PARTIAL_NODE_SPACING = 0.005

#: Distinct query station sets a grid keeps (see :meth:`Grid.query`).
QUERY_CACHE_SIZE = 8


class _Packed(Generic[Scalar]):
    """A field of a grid kept in its :class:`~tdcm_ros.model.cells.Cells`: row ``row`` of the
    block ``block`` (``fc``, ``fq``, ``ic``, ``notch``), read through the grid's member axis
    (:meth:`CellArrays.member_view`); ``nonzero`` reads an integer row as booleans."""

    def __init__(self, block: str, row: int | slice, nonzero: bool = False) -> None:
        self.block, self.row, self.nonzero = block, row, nonzero

    @overload
    def __get__(self, grid: None, owner: type) -> _Packed[Scalar]: ...

    @overload
    def __get__(self, grid: CellArrays, owner: type) -> NDArray[Scalar]: ...

    def __get__(self, grid: CellArrays | None, owner: type
                ) -> NDArray[Scalar] | _Packed[Scalar]:
        if grid is None:
            return self
        values = getattr(grid.cells, self.block)[:, self.row]
        return grid.member_view(values != 0 if self.nonzero else values)


@dataclass(frozen=True, eq=False)
class CellArrays:
    """The per-cell, per-node, per-Gauss-point and per-notch arrays of a grid (SI units; the
    module docstring says what each is). :class:`Grid` holds them for one design,
    :class:`GridStack` with a leading member axis. The fields the kernel reads live once, in
    ``cells`` (:class:`~tdcm_ros.model.cells.Cells`, its layout): ``C0``, ``A0``,
    ``constrained`` ... are views of it."""

    s_nodes: Array
    is_notch: NDArray[np.bool_]
    notch_index: IntArray
    shape: IntArray
    seg_start: Array
    seg_length: Array
    u_a: Array
    u_b: Array
    gauss_u: Array
    gauss_w: Array
    s_q: Array
    xi_q: Array
    c_q: Array
    xbar_q: Array
    c_start: Array
    c_end: Array
    peak_c: Array
    peak_s: Array
    strain0: Array
    strain1: Array
    cells: Cells

    C0, C1, C0_T, C1_T, xbar_start, xbar_end, D = (
        _Packed[np.float64]("fc", k) for k in range(len(FC_NAMES)))
    A0, A1, w_q, A0_T, A1_T, K0, K1, D_q, K2, W_A = (
        _Packed[np.float64]("fq", k) for k in range(len(FQ_NAMES)))
    chord_start_node, chord_end_node = (_Packed[np.int64]("ic", k) for k in range(2))
    constrained = _Packed[np.bool_]("ic", IC_NAMES.index("constrained"), nonzero=True)
    notch_left_node, notch_right_node = (_Packed[np.int64]("notch", k) for k in range(2))
    notch_open = _Packed[np.int64]("notch", slice(NOTCH_NAMES.index("notch_open"), None))

    def member_view(self, values: NDArray[Scalar]) -> NDArray[Scalar]:
        """``values`` (members first, as in ``cells``) as this grid holds them: a stack keeps
        the member axis, one grid drops it."""
        return values


@dataclass(frozen=True, eq=False)
class Grid(CellArrays):
    """Cells of one design under one discretisation (see module docstring); SI units."""

    design: Design
    chord_cells: IntArray
    _queries: dict[bytes, Query] = field(default_factory=dict, init=False, compare=False,
                                         repr=False)
    _layouts: dict[str, TendonLayout] = field(default_factory=dict, init=False, compare=False,
                                              repr=False)

    def member_view(self, values: NDArray[Scalar]) -> NDArray[Scalar]:
        """``values`` of the one member."""
        return values[0]

    @cached_property
    def constrained_cells(self) -> IntArray:
        """Indices of cells where the tendon follows the offset curve."""
        return np.flatnonzero(self.constrained)

    @cached_property
    def compressible(self) -> bool:
        """Whether the midline shortens under the axial load (``W_A`` not zero)."""
        return bool(np.any(self.W_A))

    def areas_at(self, cells: IntArray, u: Array) -> Array:
        """Section area (m^2) of cells ``cells`` at reference coordinates ``u`` (rows as
        ``cells``): the tube's in tubes; in a notch its section's (a band's from eq. 12's
        strips, on or off the axis: :func:`~tdcm_ros.model.grid_kernel.offset_section`; a
        section given whole, its own; a mesh's slice at ``u``)."""
        design, members = self.design, self.members
        out = np.full(u.shape, tube_area(design.R_outer, design.r_inner))
        notch = self.is_notch[cells]
        shape = self.shape[cells]
        kinds = members.profile_of[shape]
        for k, profile in enumerate(members.profiles):
            rows = notch & (kinds == k)
            if not np.any(rows):
                continue
            if isinstance(profile, SlicedProfile):
                out[rows] = profile.section_at(u[rows])[0]
            elif isinstance(profile, PRISMATIC_PROFILES):
                out[rows] = float(profile.section(design.R_outer).area)
            else:
                h1 = members.h1(shape[rows], u[rows])
                offset = np.broadcast_to(members.shape_w_o[shape[rows]][:, None], h1.shape)
                section = grid_kernels().offset_section
                out[rows] = np.reshape([section(float(h), float(o), design.R_outer,
                                                design.r_inner)[0]
                                        for h, o in zip(h1.ravel(), offset.ravel(), strict=True)],
                                       h1.shape)
        return out

    def tendons(self, routing: str) -> TendonLayout:
        """The design's tendons on this grid (:class:`~tdcm_ros.model.tendons.TendonLayout`),
        a tendon without its own routing taking the solver's ``routing`` (kept per routing)."""
        found = self._layouts.get(routing)
        if found is None:
            found = self._layouts[routing] = tendon_layout(
                self.design.tendon_list(), routing, self.is_notch, self.s_nodes,
                self.chord_start_node, self.chord_end_node)
        return found

    @property
    def r_c(self) -> float:
        """The tendon's offset from the tube axis (m)."""
        return float(self.cells.r_c[0])

    @property
    def constrained_peak_c(self) -> float:
        """Largest compliance (1/(N m^2)) over cells where the tendon follows the body, each
        scaled by its squared arm (:func:`arm_weighted`)."""
        return float(self.cells.constrained_peak_c[0])

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

    @cached_property
    def off_axis(self) -> bool:
        """Whether any notch's centroid is off the tube axis (``Design.w_o``)."""
        return bool(np.any(self.xbar_q))

    @cached_property
    def members(self) -> Members:
        """The design as a one-member :class:`.Members`."""
        return Members.of([self.design])

    def u_of_s(self, cells: IntArray, s: Array) -> Array:
        """Reference coordinate ``u`` of each cell's segment where it reaches arc length ``s``
        (m): the inverse of its profile's ``sigma(u)``."""
        sigma = s - self.seg_start[cells]
        u_lin = sigma / self.seg_length[cells]
        members = self.members
        circular = np.array([p.name == "circular" for p in members.profiles])
        shape = self.shape[cells]
        arc = self.is_notch[cells] & circular[members.profile_of[shape]]
        if not np.any(arc):
            return u_lin
        ratio = np.clip(1.0 - 2.0 * sigma / members.shape_w_n[shape], -1.0, 1.0)
        return np.where(arc, np.arccos(ratio) / np.pi, u_lin)

    def query(self, s: Array) -> Query:
        """Cells of arc lengths ``s`` (m) and their :meth:`partial_integrals`, kept for the last
        ``QUERY_CACHE_SIZE`` distinct ``s`` (a node asks for the same stations at every input).
        The arrays are shared: callers must not modify them."""
        key = s.tobytes()
        found = self._queries.get(key)
        if found is None:
            cells = np.clip(np.searchsorted(self.s_nodes, s, side="right") - 1, 0,
                            self.n_cells - 1)
            found = Query(cells, *self.partial_integrals(cells, s))
            if len(self._queries) >= QUERY_CACHE_SIZE:
                del self._queries[next(iter(self._queries))]
            self._queries[key] = found
        return found

    def partial_integrals(self, cells: IntArray, s: Array
                          ) -> tuple[Array, Array, Array, Array, Array, Array, Array, Array,
                                     Array, Array, Array]:
        """Integrals from each cell's start ``a`` to a query ``s`` inside it (SI units), by the
        kernel that integrated the cells (:func:`tdcm_ros.model.grid_kernel.cell_integrals`)
        on the part ``[a, s]`` of each, with the whole cell's ``xi`` and end centroids.

        Returns ``(A0_s, A1_s, D_s, A0_r, A1_r, D_r, w_r, K0_r, K1_r, K2_r, W_A_r)``: ``A0``,
        ``A1``, ``D`` at ``s`` (shape (k,)) and at the Gauss points of ``[a, s]`` (shape (k, Q)),
        those points' ds weights (m), their tube-axis stretch terms ``K0``, ``K1``, ``K2``
        (module docstring; ``D`` and ``K`` are 0 where the centroid is on the axis) and their
        shortening per newton ``W_A`` (m/N; 0 on a rigid midline).
        """
        start = self.s_nodes[cells] - self.seg_start[cells]
        cell = _cell_rows(is_notch=self.is_notch[cells], chord=np.zeros(cells.size),
                          u_a=self.u_a[cells], u_b=self.u_of_s(cells, s), start=start,
                          length=self.length[cells], seg_length=self.seg_length[cells],
                          u_end=self.u_b[cells], span=s - self.s_nodes[cells])
        fc, fq, _ = _integrals(self.members, self.shape[cells], cell, self.gauss_u.size,
                               NESTED)
        fc, fq = fc[:-1], fq[:-1]
        k = grid_kernel
        w_r = fq[:, k.W_Q]
        w_a = np.zeros_like(w_r) if not self.compressible else w_r / (
            self.design.E * self.areas_at(cells, cell[:, k.U_A, None] + (
                cell[:, k.U_B] - cell[:, k.U_A])[:, None] * self.gauss_u))
        return (fc[:, k.C0], fc[:, k.C1], fc[:, k.D_CELL], fq[:, k.A0], fq[:, k.A1],
                fq[:, k.D_Q], w_r, fq[:, k.K0], fq[:, k.K1], fq[:, k.K2], w_a)


def arm_weighted(peak_c: Array, xbar_start: Array, xbar_end: Array, r_c: Array | float
                 ) -> Array:
    """Each cell's peak compliance ``c`` (1/(N m^2)) times ``((R_c - x_bar) / R_c)^2``, with
    the centroid's offset ``x_bar`` (m) farther from the tendon of the cell's two ends: then
    ``R_c^2 T`` times it is ``(R_c - x_bar) kappa`` under the tendon's own moment
    ``(R_c - x_bar) T``, where the tendon's path cusps at 1 (``c`` itself where the centroid
    is on the axis)."""
    arm = r_c - np.minimum(xbar_start, xbar_end)
    return peak_c * (arm / r_c) ** 2


def build_grid(design: Design, settings: SolverSettings) -> Grid:
    """The (cached) grid for ``design`` under ``settings``' routing and discretisation: the
    many-design build (:func:`build_grids`) with one member."""
    key = (settings.routing if design.tendons == () else grid_routing(design.tendons,
                                                                       settings.routing),
           settings.grid, settings.cells_per_notch, settings.cells_per_tube, settings.quad_order,
           settings.axial == "compressible")
    last = _last_grid.get("grid")
    if last is not None and last[0] is design and last[1] == key:
        return last[2]
    grid = _build_grid(design, *key)
    _last_grid["grid"] = (design, key, grid)
    return grid


_last_grid: dict[str, tuple[Design, tuple[str, str, int, int, int, bool], Grid]] = {}
"""The last grid :func:`build_grid` returned, by the identity of its design: a node or a loop
solves one ``Design`` object again and again, and the grid cache's lookup hashes it and, for
an equal design that is not the cached one (e.g. read from a body file), compares it field by
field (~1 us each, of a ~55 us solve)."""


def clear_grid_cache() -> None:
    """Forget every cached grid, so the next :func:`build_grid` builds (tests, benchmarks),
    and what :func:`on_clear` registered that holds one."""
    _last_grid.clear()
    _build_grid.cache_clear()
    for forget in _on_clear:
        forget()


def on_clear(forget: Callable[[], None]) -> None:
    """Have :func:`clear_grid_cache` call ``forget`` too (a cache holding grids elsewhere)."""
    _on_clear.append(forget)


_on_clear: list[Callable[[], None]] = []


@lru_cache(maxsize=512)
@quiet_fp
def _build_grid(design: Design, routing: str, kind: str, cells_per_notch: int,
                cells_per_tube: int, quad_order: int, compressible: bool) -> Grid:
    parts = GridParts.of(Members.of([design]), routing, kind, cells_per_notch,
                         cells_per_tube, quad_order, NESTED)
    grid = parts.stack(np.zeros(1, np.int64)).grid(0)
    if compressible:  # each Gauss point's shortening per newton: w_q / (E A)
        cells = np.arange(grid.n_cells)
        grid.cells.fq[0, W_A_ROW] = grid.w_q / (design.E * grid.areas_at(
            cells, grid.u_a[:, None] + (grid.u_b - grid.u_a)[:, None] * grid.gauss_u))
    return grid


@dataclass(frozen=True, eq=False)
class GridParts:
    """Many designs' cells before they are laid out member by member: where every cell goes
    (``table``, :mod:`tdcm_ros.model.grid_layout`) and the integrals of every prototype cell
    (:func:`tdcm_ros.model.grid_kernel.cell_integrals`), SI units.

    ``proto_fc`` (P + 1, 11) and ``proto_fq`` (P + 1, 13, Q) hold the kernel's per-cell and
    per-Gauss-point outputs (columns and rows named in :mod:`tdcm_ros.model.grid_kernel`),
    ``proto_strain`` (P + 1, 2, ``PEAK_SAMPLES``) its strain coefficients; their last row is
    zero, the integrals of a padding cell.
    """

    members: Members
    table: CellTable
    proto_fc: Array
    proto_fq: Array
    proto_strain: Array
    gauss_u: Array
    gauss_w: Array

    @classmethod
    def of(cls, members: Members, routing: str, kind: str, cells_per_notch: int,
           cells_per_tube: int, quad_order: int, partials: str, workers: int = 1
           ) -> GridParts:
        """Lay out and integrate every member's cells (``members`` already checked) with
        ``workers`` threads, the partial integrals by the rule ``partials``
        (:data:`PARTIAL_RULES`)."""
        table = cell_table(prototypes(members, routing, kind, cells_per_notch, cells_per_tube),
                           routing)
        fc, fq, strain = _prototype_integrals(table.prototypes, quad_order, partials, workers)
        return cls(members=members, table=table, proto_fc=fc, proto_fq=fq,
                   proto_strain=strain, gauss_u=gauss_legendre(quad_order)[0],
                   gauss_w=gauss_legendre(quad_order)[1])

    def cells_of(self, rows: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
        """For members ``rows``, padded to the most cells among them (m, W): each slot's cell
        of ``table`` (0 in padding), its prototype cell (the zero row P in padding) and
        whether it is a cell (not padding)."""
        table = self.table
        count = table.count[rows]
        slot = np.arange(int(count.max()))
        valid = slot[None, :] < count[:, None]
        cell = np.where(valid, table.first[rows][:, None] + slot[None, :], 0)
        pad = self.proto_fc.shape[0] - 1
        return cell, np.where(valid, table.prototype[cell], pad), valid

    def stack(self, rows: IntArray) -> GridStack:
        """The :class:`GridStack` of members ``rows``."""
        table, members = self.table, self.members
        cell, proto, valid = self.cells_of(rows)
        count = table.count[rows]
        tip = members.length[rows][:, None]

        def laid(values: NDArray[Scalar], pad: float | bool | Array | IntArray
                 ) -> NDArray[Scalar]:
            return np.where(valid, values[cell], pad).astype(values.dtype, copy=False)

        seg_start = laid(table.seg_start, tip)
        fq = {name: self.proto_fq[proto, k] for name, k in (
            ("s_q", grid_kernel.S_Q), ("xi_q", grid_kernel.XI_Q), ("c_q", grid_kernel.C_Q),
            ("xbar_q", grid_kernel.XB_Q))}
        fc = {name: self.proto_fc[proto, k] for name, k in (
            ("c_start", grid_kernel.C_START), ("c_end", grid_kernel.C_END),
            ("peak_c", grid_kernel.PEAK_C), ("peak_s", grid_kernel.PEAK_S))}
        fq["s_q"] += seg_start[..., None]
        fc["peak_s"] += seg_start
        strain = {"strain0": self.proto_strain[proto, 0], "strain1": self.proto_strain[proto, 1]}
        return GridStack(
            designs=tuple(members.designs[r] for r in rows), n_cells=count,
            s_nodes=np.concatenate([laid(table.a, tip), tip], axis=1),
            is_notch=laid(table.is_notch, False), notch_index=laid(table.notch_index, -1),
            shape=laid(table.shape, 0),
            seg_start=seg_start, seg_length=laid(table.seg_length, 0.0),
            u_a=laid(table.u_a, 0.0), u_b=laid(table.u_b, 0.0),
            gauss_u=self.gauss_u, gauss_w=self.gauss_w, **fq, **fc, **strain,
            cells=self.cells(rows))

    def cells(self, rows: IntArray) -> Cells:
        """The kernel's arrays of members ``rows``, laid out straight from their prototype
        cells (:meth:`stack` holds the same, with its other arrays)."""
        indices = self.kernel_indices(rows)
        build = kernels()
        fc = np.empty((rows.size, FC_ROWS, indices.cell_proto.shape[1], 1))
        build.gather(indices.cell_proto, FC_FIELDS, self.proto_fc[..., None], fc)
        fq = np.empty((rows.size, FQ_ROWS, indices.cell_proto.shape[1], self.gauss_u.size))
        build.gather(indices.cell_proto, FQ_FIELDS, self.proto_fq, fq)
        fq[:, W_A_ROW] = 0.0  # a rigid midline (see _build_grid)
        return Cells(fc=fc[..., 0], fq=fq, ic=indices.ic, notch=indices.notch,
                     scal=indices.scal)

    def kernel_indices(self, rows: IntArray) -> KernelIndices:
        """The :class:`KernelIndices` of members ``rows``, padded to the most cells and
        notches among them (the compiled :func:`~tdcm_ros.model.grid_kernel.member_cells`)."""
        table, members = self.table, self.members
        width = int(table.count[rows].max())
        pad = self.proto_fc.shape[0] - 1
        cell_proto = np.empty((rows.size, width), np.int64)
        ic = np.empty((rows.size, 3, width), np.int64)
        notch_width = int(self.notch_cell_counts[rows].max(initial=0))
        notch_cells = np.empty((rows.size, notch_width), np.int64)
        notch_proto = np.empty((rows.size, notch_width), np.int64)
        grid_kernels().member_cells(rows, table.first, table.count, table.prototype,
                                    table.is_notch, table.constrained, table.chord_start_node,
                                    table.chord_end_node, pad, cell_proto, ic, notch_cells,
                                    notch_proto)
        peak = np.where(ic[:, 2] != 0, self.arm_weighted_peaks[cell_proto], 0.0)
        scal = np.stack([members.R_c[rows], members.R_outer[rows], members.length[rows],
                         np.max(peak, axis=1, initial=0.0)], axis=1)
        notches = int(members.N[rows].max())
        notch = np.concatenate([np.stack([table.notch_left_node[rows, :notches],
                                          table.notch_right_node[rows, :notches]], axis=1),
                                members.notch_open[rows][:, :, :notches]], axis=1)
        return KernelIndices(cell_proto, ic, notch, scal, notch_cells, notch_proto)

    @cached_property
    def notch_cell_counts(self) -> IntArray:
        """Notch cells per member."""
        table = self.table
        return np.bincount(table.member[table.is_notch], minlength=table.count.size)

    @cached_property
    def arm_weighted_peaks(self) -> Array:
        """Per prototype cell its peak compliance weighted by its arm (:func:`arm_weighted`,
        1/(N m^2), with its member's ``R_c``), 0 in the padding row."""
        fc, member = self.proto_fc, self.table.prototypes.member
        out = np.zeros(fc.shape[0])
        out[:-1] = arm_weighted(fc[:-1, grid_kernel.PEAK_C], fc[:-1, grid_kernel.XB_START],
                                fc[:-1, grid_kernel.XB_END], self.members.R_c[member])
        return out


class KernelIndices(NamedTuple):
    """What a kernel reads of members of :class:`GridParts` besides the prototype cells'
    integrals, padded to ``W`` cells and ``K`` notches: per member each cell's prototype cell
    ``cell_proto`` (M, W; the zero row in padding), :class:`~tdcm_ros.model.cells.Cells`'
    ``ic``, ``notch``, ``scal``, and its notch cells ``notch_cells`` (M, notch cells; -1 in
    padding) with their prototype cells ``notch_proto``."""

    cell_proto: IntArray
    ic: IntArray
    notch: IntArray
    scal: Array
    notch_cells: IntArray
    notch_proto: IntArray


def _prototype_integrals(table: Prototypes, quad_order: int, partials: str, workers: int = 1
                         ) -> tuple[Array, Array, Array]:
    """:class:`GridParts`' ``proto_fc``, ``proto_fq``, ``proto_strain`` of every prototype cell
    of ``table`` (``s_q``, ``peak_s`` from its segment's start), and the zero padding row, the
    partial integrals by the rule ``partials``; ``workers`` threads share the cells (the
    compiled kernel releases the GIL)."""
    cell = _cell_rows(is_notch=table.is_notch, chord=table.chord, u_a=table.u_a, u_b=table.u_b,
                      start=table.a, length=table.length, seg_length=table.seg_length,
                      u_end=table.u_b, span=table.length)
    return _integrals(table.members, table.shape, cell, quad_order, partials, workers)


def _cell_rows(**columns: NDArray[Any]) -> Array:
    """The kernel's ``cell`` input (cells, 9) from its columns by name (``is_notch``, ``chord``,
    ``u_a``, ``u_b``, ``start``, ``length``, ``seg_length``, ``u_end``, ``span``: the module
    docstring of :mod:`tdcm_ros.model.grid_kernel`), in the kernel's column order."""
    order = ("is_notch", "chord", "u_a", "u_b", "start", "length", "seg_length", "u_end", "span")
    return np.stack([columns[name] for name in order], axis=1).astype(float)


def _integrals(members: Members, shape: IntArray, cell: Array, quad_order: int,
               partials: str, workers: int = 1) -> tuple[Array, Array, Array]:
    """:func:`tdcm_ros.model.grid_kernel.cell_integrals` of the cells ``cell`` (its columns)
    of notch shapes ``shape`` (rows of ``members``), followed by a zero row: ``fc``, ``fq``,
    ``strain``, the partial integrals by the rule ``partials`` (:data:`PARTIAL_RULES`);
    ``workers`` threads share the cells (the compiled kernel releases the GIL)."""
    gauss_u, gauss_w = gauss_legendre(quad_order)
    nested = partials == NESTED
    weights, nodes = (np.zeros((quad_order, 0)), np.zeros(0, np.int64)) if nested else \
        partial_weights(quad_order)
    kinds = np.array([_PROFILE_KIND.get(p.name, CUSTOM) for p in members.profiles], float)
    owner = members.shape_member
    design = np.concatenate([np.stack(
        [kinds[members.profile_of], members.shape_w_n, members.shape_w_d,
         members.R_outer[owner], members.r_inner[owner], members.E[owner],
         members.tube_moment[owner], members.shape_w_o], axis=1), members.shape_section], axis=1)
    build = grid_kernels()
    probe = np.linspace(0.0, 1.0, PEAK_SAMPLES)
    custom_row, custom_table = _custom_table(members, shape, build, cell, design, gauss_u,
                                             probe, nested)
    count = shape.size
    fc = np.zeros((count + 1, 11))
    fq = np.zeros((count + 1, 13, quad_order))
    strain = np.zeros((count + 1, 2, PEAK_SAMPLES))
    matrix = _integration_matrix(quad_order)

    def integrate(part: slice) -> None:
        build.cell_integrals(shape[part], cell[part], design, custom_row[part],
                             custom_table, gauss_u, gauss_w, matrix, weights, nodes, probe,
                             fc[part], fq[part], strain[part])

    ends = np.linspace(0, count, workers + 1).astype(int)
    parts = [slice(int(a), int(b)) for a, b in pairwise(ends)]
    if workers == 1:
        integrate(parts[0])
    else:
        with ThreadPoolExecutor(workers) as pool:
            list(pool.map(integrate, parts))
    return fc, fq, strain


_PROFILE_KIND = {"circular": CIRCULAR, "rectangular": RECTANGULAR, "polygon": PRISMATIC,
                 "section": PRISMATIC, "sliced": TABULATED}


def _custom_table(members: Members, shape: IntArray, build: Any, cell: Array, design: Array,
                  gauss_u: Array, probe: Array, nested: bool) -> tuple[IntArray, Array]:
    """For cells ``cell`` (of notch shapes ``shape``) in notches of user profiles
    (:data:`CUSTOM`) and of sections changing along the notch (:data:`TABULATED`): a row each
    of the custom table (-1 for the others) holding, at every evaluation point of
    :func:`tdcm_ros.model.grid_kernel.points`, ``h1`` (m; then two zeros), or ``1/(E I)``
    (1/(N m^2)), ``x_bar`` (m) and the farthest fibre (m); the nested points only for the
    ``nested`` rule."""
    kind = design[shape, 0]
    is_notch = cell[:, grid_kernel.IS_NOTCH] != 0.0
    chosen = np.flatnonzero(((kind == CUSTOM) | (kind == TABULATED)) & is_notch)
    rows = np.full(shape.size, -1, np.int64)
    size = gauss_u.size * ((gauss_u.size if nested else 0) + 1) + probe.size + 2
    out = np.zeros((chosen.size, size, 3))
    if chosen.size:
        rows[chosen] = np.arange(chosen.size)
        u = np.empty((chosen.size, size))
        build.points(np.ascontiguousarray(cell[chosen]), gauss_u, probe, nested, u)
        chosen_shape = shape[chosen]
        custom = kind[chosen] == CUSTOM
        if np.any(custom):
            out[custom, :, 0] = members.h1(chosen_shape[custom], u[custom])
        tabulated = ~custom
        if np.any(tabulated):
            out[tabulated] = np.stack(members.tabulated(chosen_shape[tabulated], u[tabulated]),
                                      axis=-1)
    return rows, out


@lru_cache(maxsize=32)
def gauss_legendre(quad_order: int) -> tuple[Array, Array]:
    """Gauss-Legendre points and weights of order ``quad_order`` on [0, 1]."""
    gauss_x, gauss_wt = np.polynomial.legendre.leggauss(quad_order)
    return 0.5 * (gauss_x + 1.0), 0.5 * gauss_wt


@lru_cache(maxsize=32)
def _integration_matrix(quad_order: int) -> Array:
    """``S[q, k] = int_0^{u_q} l_k(u) du`` on [0, 1] for the Lagrange basis ``l_k`` of the
    ``quad_order`` Gauss-Legendre points ``u_q``: partial integrals exact for polynomials of
    degree ``quad_order - 1``."""
    legendre = np.polynomial.legendre
    x, _ = legendre.leggauss(quad_order)
    basis = np.linalg.inv(legendre.legvander(x, quad_order - 1))
    matrix = np.asarray(0.5 * legendre.legval(x, legendre.legint(basis, lbnd=-1.0)).T,
                        dtype=np.float64)
    matrix.setflags(write=False)
    return matrix


@lru_cache(maxsize=32)
def partial_weights(quad_order: int) -> tuple[Array, IntArray]:
    """The interpolated rule: weights ``W`` (Q, K) on [0, 1] and its nodes (K,), numbered as
    the cell's Gauss points (0 to Q - 1) then probes (Q on): ``int_0^{u_q} f du = sum_k
    W[q, k] f(x_k)`` for every polynomial ``f`` of degree below K. The nodes are the ``Q``
    Gauss-Legendre points ``u_q`` and the even-numbered probes (every other of the
    ``PEAK_SAMPLES`` equally spaced ones, 9 of 17) at least ``PARTIAL_NODE_SPACING`` from every
    Gauss point: for ``Q = 6`` 15 nodes, exact to degree 14 where the nested rule is to degree
    11, with no evaluation beyond the Gauss points and probes the cell needs anyway. Solved in
    the Legendre basis; ``sum_k |W[q, k]|`` stays below 8 for every ``Q`` in 1-32 (rounding is
    not amplified)."""
    gauss_u, _ = gauss_legendre(quad_order)
    probe = np.linspace(0.0, 1.0, PEAK_SAMPLES)
    near = np.min(np.abs(probe[:, None] - gauss_u[None, :]), axis=1) < PARTIAL_NODE_SPACING
    used = (np.arange(PEAK_SAMPLES) % 2 == 0) & ~near
    nodes = np.concatenate([gauss_u, probe[used]])
    legendre = np.polynomial.legendre
    basis = np.linalg.solve(legendre.legvander(2.0 * nodes - 1.0, nodes.size - 1),
                            np.eye(nodes.size))
    on_nodes = np.ascontiguousarray(0.5 * legendre.legval(2.0 * gauss_u - 1.0,
                                                          legendre.legint(basis, lbnd=-1.0)).T)
    index = np.concatenate([np.arange(quad_order), quad_order + np.flatnonzero(used)])
    on_nodes.setflags(write=False)
    index.setflags(write=False)
    return on_nodes, index


@dataclass(frozen=True, eq=False)
class GridStack(CellArrays):
    """The grids of M designs with a leading member axis, padded to ``C`` cells (SI units).

    Fields have :class:`Grid`'s names and meanings with a leading axis of length M: per cell
    (M, C), per node (M, C + 1), per Gauss point (M, C, Q), per notch (M, max N); ``gauss_u``,
    ``gauss_w`` (Q,) are shared. Member ``m`` owns its first ``n_cells[m]`` cells, equal bit
    for bit to ``build_grid(designs[m], settings)``'s. The padding cells past them have zero
    length at the member's tip (``s_nodes = L``) and carry nothing: ``C0 = C1 = A0 = A1 =
    w_q = 0``, zero compliance, ``is_notch`` false, ``constrained`` true (no chord),
    ``notch_index`` -1, chord nodes = the tip node; padding notches (``N < max N``) have both
    nodes at the tip node. ``chord_cells`` is not stacked: use ``~constrained``.
    """

    designs: tuple[Design, ...]
    n_cells: IntArray

    @property
    def length(self) -> Array:
        """Cell lengths (m), shape (M, C); 0 in the padding."""
        return np.diff(self.s_nodes, axis=-1)

    def grid(self, m: int) -> Grid:
        """Member ``m`` as a :class:`Grid` (its arrays are views of the stack's, unpadded)."""
        n = int(self.n_cells[m])
        design = self.designs[m]
        shared = ("s_nodes", "gauss_u", "gauss_w", "cells")
        per_cell = {f.name: getattr(self, f.name)[m, :n] for f in fields(CellArrays)
                    if f.name not in shared}
        block = self.cells
        cells = Cells(fc=np.ascontiguousarray(block.fc[m:m + 1, :, :n]),
                      fq=np.ascontiguousarray(block.fq[m:m + 1, :, :n]),
                      ic=np.ascontiguousarray(block.ic[m:m + 1, :, :n]),
                      notch=np.ascontiguousarray(block.notch[m:m + 1, :, :design.N]),
                      scal=block.scal[m:m + 1])
        return Grid(design=design, chord_cells=np.flatnonzero(cells.ic[0, 2] == 0),
                    s_nodes=self.s_nodes[m, :n + 1], gauss_u=self.gauss_u,
                    gauss_w=self.gauss_w, cells=cells, **per_cell)


def build_grids(designs: Sequence[Design], settings: SolverSettings,
                partials: str = NESTED) -> GridStack:
    """Grids of many designs at once (:class:`GridParts`), the partial integrals by the rule
    ``partials`` (:data:`PARTIAL_RULES`; ``nested``, the default, gives :func:`build_grid`'s
    bits); see :class:`GridStack`."""
    return grid_parts(designs, settings, partials=partials).stack(np.arange(len(designs)))


def grid_parts(designs: Sequence[Design], settings: SolverSettings, workers: int = 1,
               partials: str = NESTED) -> GridParts:
    """The :class:`GridParts` of ``designs`` under ``settings``' grid (at least one design),
    integrated by ``workers`` threads (the same values for any count), the partial integrals
    by the rule ``partials`` (:data:`PARTIAL_RULES`)."""
    if len(designs) == 0:
        raise out_of_range("number of designs", 0, "[1, inf)", error=InvalidDesignError)
    if partials not in PARTIAL_RULES:
        raise out_of_range("partials", partials, " or ".join(PARTIAL_RULES),
                           error=InvalidSettingsError)
    return GridParts.of(Members.of(designs), settings.routing, settings.grid,
                        settings.cells_per_notch, settings.cells_per_tube, settings.quad_order,
                        partials, workers)
