"""Vectorised Algorithm 1: many designs and tensions in one call, same answers as ``solve``.

Designs whose grids share a cell layout (same ``N``, same present segments, same settings)
are stacked: their per-cell integrals ``C0``, ``C1``, ``A0``, ``A1``, ``w_q`` gain a leading
member axis and every member iterates at once. Each member follows exactly the iteration of
:func:`tdcm_ros.model.solve` (closed-form loads, initial moment ``R_c T``, stop when no node
moves more than ``tol``): plain (or, for ``acceleration="relaxation"``, damped) iteration
runs vectorised; a member that ``solve`` would hand to Anderson mixing, relaxation or
continuation (it slowed down, diverged or ran out of budget), and every member under
``loads="literal"``, is solved by ``solve`` itself. The tendon-offset singularity (before
iterating) and notch closure (on the solution) are checked per member with the same
formulas as :mod:`tdcm_ros.model.limits`.

Nothing is raised for a member: each gets a status (``STATUSES``) and a message. Numbers are
returned only for ``ok`` members; the others hold NaN.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import (
    InvalidDesignError,
    InvalidSettingsError,
    ModelError,
    TensionRangeError,
)
from tdcm_ros.model.grid import PEAK_SAMPLES, Grid, build_grid
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.limits import check_closure, check_tendon_singularity, check_tension
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import (
    DEFAULT_SETTINGS,
    DIVERGENCE_GROWTH,
    SLOW_CONTRACTION,
    solve,
)

Array = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

STATUSES = ("ok", "singularity", "closure", "non_convergence", "invalid")
"""Member statuses; ``kink_angle`` can also appear, under ``loads="literal"`` only."""

_STATUS_OF_KIND = {"tendon_singularity": "singularity", "notch_closure": "closure",
                   "non_convergence": "non_convergence", "invalid_design": "invalid",
                   "tension_out_of_range": "invalid"}
CHUNK = 2048
"""Members iterated together (bounds the working set; any size gives the same answers)."""


@dataclass(frozen=True, eq=False)
class BatchResult:
    """Per-member outcome of :func:`solve_batch`; arrays have the shape of ``tensions``.

    ``tip_position`` (..., 3) m in frame ``tdcm_base``; ``tip_angle_rad`` (rad about +y);
    ``tip_deflection_m`` (distance of the tip from +z, m); ``max_bending_strain`` (largest
    ``|kappa| min(h1, R_outer)`` over the notches, dimensionless); ``iterations`` of
    Algorithm 1; ``fallback`` marks members solved by the single ``solve``. ``status`` holds
    names from :data:`STATUSES`, ``message`` the error text (empty when ``ok``).
    """

    tensions: Array
    status: NDArray[np.str_]
    message: NDArray[np.object_]
    tip_position: Array
    tip_angle_rad: Array
    tip_deflection_m: Array
    max_bending_strain: Array
    iterations: NDArray[np.int64]
    fallback: NDArray[np.bool_]

    @property
    def ok(self) -> NDArray[np.bool_]:
        """Members with a converged solution inside every model limit."""
        return self.status == "ok"


@dataclass(frozen=True, eq=False)
class _Stack:
    """Arrays of designs sharing one cell layout, stacked on a leading axis (SI units).

    ``strain0``/``strain1`` (designs, notch cells, samples) give the bending strain at
    ``PEAK_SAMPLES`` points of every notch cell as ``|m_a S0 + m_b S1|``.
    """

    template: Grid
    grids: NDArray[np.object_]
    C0: Array
    C1: Array
    A0: Array
    A1: Array
    w_q: Array
    r_c: Array
    r_outer: Array
    length: Array
    peak_c: Array
    strain0: Array
    strain1: Array

    @classmethod
    def of(cls, grids: Sequence[Grid]) -> _Stack:
        """Stack ``grids`` (all of one layout)."""
        coefficients = [_strain_coefficients(g) for g in grids]
        return cls(
            template=grids[0], grids=_object_array(grids), C0=np.stack([g.C0 for g in grids]),
            C1=np.stack([g.C1 for g in grids]), A0=np.stack([g.A0 for g in grids]),
            A1=np.stack([g.A1 for g in grids]), w_q=np.stack([g.w_q for g in grids]),
            r_c=np.array([g.design.R_c for g in grids]),
            r_outer=np.array([g.design.R_outer for g in grids]),
            length=np.array([g.design.length for g in grids]),
            peak_c=np.array([g.constrained_peak_c for g in grids]),
            strain0=np.stack([c[0] for c in coefficients]),
            strain1=np.stack([c[1] for c in coefficients]))

    def take(self, rows: NDArray[np.int64]) -> _Stack:
        """The stack of designs ``rows`` (repeats allowed): one row per member."""
        if rows.size == self.C0.shape[0] and np.array_equal(rows, np.arange(rows.size)):
            return self
        return _Stack(template=self.template, grids=self.grids[rows], C0=self.C0[rows], C1=self.C1[rows],
                      A0=self.A0[rows], A1=self.A1[rows], w_q=self.w_q[rows],
                      r_c=self.r_c[rows], r_outer=self.r_outer[rows],
                      length=self.length[rows], peak_c=self.peak_c[rows],
                      strain0=self.strain0[rows], strain1=self.strain1[rows])

    def strain(self, m_a: Array, m_b: Array) -> Array:
        """Largest notch bending strain of each row from its cell end moments (N m)."""
        notch = self.template.is_notch
        return np.max(np.abs(m_a[:, notch, None] * self.strain0
                             + m_b[:, notch, None] * self.strain1), axis=(1, 2))


def solve_batch(designs: Sequence[Design], tensions: ArrayLike, *,
                settings: SolverSettings = DEFAULT_SETTINGS) -> BatchResult:
    """Solve every design at its tensions (N); ``tensions`` has shape ``(len(designs), ...)``.

    A 1-D ``tensions`` pairs design ``i`` with tension ``i``; a 2-D one gives each design a
    row of tensions (a design-space grid). Results have the shape of ``tensions``.
    """
    designs = list(designs)
    for i, design in enumerate(designs):
        if not isinstance(design, Design):
            raise InvalidDesignError(
                f"designs[{i}] = {design!r} is not a Design", parameter=f"designs[{i}]",
                value=design, allowed="tdcm_ros.model.Design")
    if not isinstance(settings, SolverSettings):
        raise InvalidSettingsError(f"settings = {settings!r} is not a SolverSettings",
                                   parameter="settings", value=settings,
                                   allowed="tdcm_ros.model.SolverSettings")
    try:
        t_all = np.array(tensions, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TensionRangeError(f"tensions = {tensions!r} are not numbers; allowed: [0, inf) N",
                                parameter="tensions", value=tensions,
                                allowed="array of numbers in [0, inf) N") from exc
    if t_all.ndim == 0 or t_all.shape[0] != len(designs):
        raise TensionRangeError(
            f"tensions of shape {t_all.shape} do not match {len(designs)} designs; allowed: "
            "shape (len(designs), ...)", parameter="tensions", value=t_all.shape,
            allowed=f"shape ({len(designs)}, ...)")
    out = _Outcome(t_all.reshape(len(designs), -1))
    layouts: dict[tuple[bytes, ...], list[tuple[int, Grid]]] = {}
    for d, design in enumerate(designs):
        try:
            grid = build_grid(design, settings)
        except InvalidDesignError as error:
            out.fail(d * out.per_design + np.arange(out.per_design), error)
            continue
        layouts.setdefault(_layout_key(grid), []).append((d, grid))
    for group in layouts.values():
        _solve_group(out, [d for d, _ in group], _Stack.of([g for _, g in group]), settings)
    out.run_fallbacks(designs, settings)
    return out.result(t_all.shape)


class _Outcome:
    """Per-member outputs while a batch runs (flat member index ``d * per_design + k``)."""

    def __init__(self, tensions: Array) -> None:
        self.per_design = tensions.shape[1]
        self.tensions = tensions.ravel()
        size = self.tensions.size
        self.status = np.full(size, "ok", dtype="<U16")
        self.message = np.full(size, "", dtype=object)
        self.tip = np.full((size, 3), np.nan)
        self.angle = np.full(size, np.nan)
        self.strain = np.full(size, np.nan)
        self.iterations = np.zeros(size, np.int64)
        self.fallback = np.zeros(size, bool)
        self.pending: list[tuple[int, _Stack]] = []

    def fail(self, members: NDArray[np.int64], error: ModelError) -> None:
        """Mark ``members`` with the status of ``error`` and its message."""
        self.status[members] = _STATUS_OF_KIND.get(error.kind, error.kind)
        self.message[members] = str(error)

    def store(self, members: NDArray[np.int64], p_tip: ComplexArray, theta_tip: Array,
              strain: Array) -> None:
        """Record converged, feasible members."""
        self.tip[members, 0] = p_tip.imag
        self.tip[members, 1] = 0.0
        self.tip[members, 2] = p_tip.real
        self.angle[members] = theta_tip
        self.strain[members] = strain

    def run_fallbacks(self, designs: list[Design], settings: SolverSettings) -> None:
        """Solve every pending member (with its one-row stack) by the single :func:`solve`."""
        for m, row in self.pending:
            self.fallback[m] = True
            try:
                result = solve(designs[m // self.per_design], float(self.tensions[m]),
                               settings=settings)
            except ModelError as error:
                self.fail(np.array([m]), error)
                self.iterations[m] = settings.max_iter if error.kind == "non_convergence" else 0
                continue
            moments = result.cell_moments
            x, _, z = result.tip_position
            self.store(np.array([m]), np.array([z + 1j * x]), np.array([result.tip_angle_rad]),
                       row.strain(moments[None, :, 0], moments[None, :, 1]))
            self.iterations[m] = result.iterations

    def result(self, shape: tuple[int, ...]) -> BatchResult:
        """The outcome in the caller's shape."""
        deflection = np.hypot(self.tip[:, 0], self.tip[:, 1])
        return BatchResult(
            tensions=self.tensions.reshape(shape), status=self.status.reshape(shape),
            message=self.message.reshape(shape), tip_position=self.tip.reshape(shape + (3,)),
            tip_angle_rad=self.angle.reshape(shape), tip_deflection_m=deflection.reshape(shape),
            max_bending_strain=self.strain.reshape(shape),
            iterations=self.iterations.reshape(shape), fallback=self.fallback.reshape(shape))


def _object_array(items: Sequence[Any]) -> NDArray[np.object_]:
    """A 1-D object array of ``items`` (never a nested numeric array)."""
    array = np.empty(len(items), dtype=object)
    array[:] = list(items)
    return array


def _layout_key(grid: Grid) -> tuple[bytes, ...]:
    """Grids with equal keys have the same cells, chords and notches, node for node."""
    return (grid.is_notch.tobytes(), grid.constrained.tobytes(),
            grid.chord_start_node.tobytes(), grid.chord_end_node.tobytes(),
            grid.notch_left_node.tobytes(), grid.gauss_u.tobytes())


def _strain_coefficients(grid: Grid) -> tuple[Array, Array]:
    """``S0``, ``S1`` (notch cells, samples): strain ``|m_a S0 + m_b S1|`` at ``PEAK_SAMPLES``
    points of every notch cell, ``S = (1 - xi | xi) * c * min(h1, R_outer)``."""
    d = grid.design
    cells = np.flatnonzero(grid.is_notch)
    u = grid.u_a[cells, None] + (grid.u_b - grid.u_a)[cells, None] * np.linspace(
        0.0, 1.0, PEAK_SAMPLES)[None, :]
    cell_of = np.broadcast_to(cells[:, None], u.shape)
    s = grid.seg_start[cell_of] + grid.local_sigma(cell_of, u)
    xi = (s - grid.s_nodes[cell_of]) / grid.length[cell_of]
    weight = grid.compliance(cell_of, u) * np.minimum(d.profile.h1(u, d.w_n, d.w_d), d.R_outer)
    return (1.0 - xi) * weight, xi * weight


def _solve_group(out: _Outcome, design_ids: list[int], stack: _Stack,
                 settings: SolverSettings) -> None:
    """Screen, then iterate (closed loads) or queue (literal loads) one layout group."""
    k = out.per_design
    rows = np.repeat(np.arange(len(design_ids)), k)
    members = (np.asarray(design_ids)[:, None] * k + np.arange(k)[None, :]).ravel()
    tension = out.tensions[members]
    bad = ~(np.isfinite(tension) & (tension >= 0.0))
    for m in members[bad]:
        try:
            check_tension(out.tensions[m])
        except TensionRangeError as error:
            out.fail(np.array([m]), error)
    # limits.check_tendon_singularity, evaluated in the same order of operations.
    r_c, peak = stack.r_c[rows], stack.peak_c[rows]
    singular = ~bad & (r_c**2 * tension * peak >= 1.0) & (r_c * (r_c * tension) * peak >= 1.0)
    for m, row in zip(members[singular], rows[singular]):
        try:
            check_tendon_singularity(stack.grids[row], float(out.tensions[m]))
        except ModelError as error:
            out.fail(np.array([m]), error)
    keep = ~(bad | singular)
    members, rows = members[keep], rows[keep]
    if settings.loads != "closed":
        out.pending.extend((int(m), stack.take(np.array([r]))) for m, r in zip(members, rows))
        return
    for start in range(0, members.size, CHUNK):
        chunk = slice(start, start + CHUNK)
        _iterate(out, members[chunk], stack.take(rows[chunk]), settings)


def _integrate(st: _Stack, m_a: Array, m_b: Array) -> tuple[ComplexArray, Array, ComplexArray]:
    """:func:`kinematics.integrate` for stacked members: nodes ``p``, ``theta``, tangents."""
    phi = m_a[..., None] * st.A0 + m_b[..., None] * st.A1
    local = np.einsum("...q,...q->...", st.w_q, np.cos(phi)) + 1j * np.einsum(
        "...q,...q->...", st.w_q, np.sin(phi))
    theta = _cumsum0(m_a * st.C0 + m_b * st.C1)
    tangent = np.exp(1j * theta)
    p = _cumsum0(tangent[..., :-1] * local)
    return p, theta, tangent


def _cumsum0(values: Any) -> Any:
    """Cumulative sum along the last axis with a leading zero."""
    out = np.zeros(values.shape[:-1] + (values.shape[-1] + 1,), dtype=values.dtype)
    np.cumsum(values, axis=-1, out=out[..., 1:])
    return out


def _closed_form(st: _Stack, p: ComplexArray, tangent: ComplexArray, tension: Array
                 ) -> tuple[Array, Array]:
    """:func:`loads.closed_form` with a per-member tendon offset ``R_c``."""
    grid = st.template
    m_a = np.empty(tension.shape + (grid.n_cells,))
    m_a[...] = (st.r_c * tension)[:, None]
    m_b = m_a.copy()
    cells = grid.chord_cells
    if cells.size == 0:
        return m_a, m_b
    p_c = p + (1j * st.r_c)[:, None] * tangent
    anchor = p_c[:, grid.chord_start_node[cells]]
    chord = p_c[:, grid.chord_end_node[cells]] - anchor
    chord = chord / np.abs(chord)
    t = -tension[:, None]
    m_a[:, cells] = t * (np.conj(anchor - p[:, cells]) * chord).imag
    m_b[:, cells] = t * (np.conj(anchor - p[:, cells + 1]) * chord).imag
    return m_a, m_b


def _min_gap(st: _Stack, p: ComplexArray, tangent: ComplexArray) -> Array:
    """:func:`limits.notch_gaps` per member, reduced to the smallest gap (m)."""
    left, right = st.template.notch_left_node, st.template.notch_right_node
    t_l, t_r = tangent[:, left], tangent[:, right]
    span = p[:, right] - p[:, left]
    gaps = []
    for side in (1.0, -1.0):
        delta = span + (1j * side * st.r_outer)[:, None] * (t_r - t_l)
        gaps.append((np.conj(t_l) * delta).real)
        gaps.append((np.conj(t_r) * delta).real)
    return np.min(np.minimum(np.minimum(gaps[0], gaps[1]), np.minimum(gaps[2], gaps[3])),
                  axis=-1)


def _iterate(out: _Outcome, members: NDArray[np.int64], st: _Stack,
             settings: SolverSettings) -> None:
    """Algorithm 1 on one chunk (row ``i`` of ``st`` is member ``members[i]``).

    Mirrors ``solver._iterate``: plain iteration (damped for ``relaxation``; one plain step
    for ``anderson``); a member ``solve`` would switch to Anderson, or that diverges or
    exhausts the budget, is queued for the single solve.
    """
    mode = settings.acceleration
    budget = 1 if mode == "anderson" else settings.max_iter
    tension = out.tensions[members]
    x_a = np.empty((members.size, st.template.n_cells))
    x_a[...] = (st.r_c * tension)[:, None]
    x_b = x_a.copy()
    p, theta, tangent = _integrate(st, x_a, x_b)
    previous = np.full(members.size, np.inf)
    smallest = np.full(members.size, np.inf)
    for k in range(1, budget + 1):
        g_a, g_b = _closed_form(st, p, tangent, tension)
        if mode == "relaxation":
            g_a = x_a + settings.relaxation * (g_a - x_a)
            g_b = x_b + settings.relaxation * (g_b - x_b)
        new_p, theta, tangent = _integrate(st, g_a, g_b)
        step = np.max(np.abs(new_p - p), axis=-1)
        x_a, x_b, p = g_a, g_b, new_p
        done = step <= settings.tol
        smallest = np.minimum(smallest, step)
        failing = (~np.isfinite(step) | (step > 2.0 * st.length)
                   | ((k > 5) & (step > DIVERGENCE_GROWTH * smallest)))
        if mode == "auto" and k >= 2:
            failing |= step > SLOW_CONTRACTION * previous
        if k == budget:
            failing |= True
        handoff = ~done & failing
        if np.any(done):
            _finish(out, members[done], st.take(np.flatnonzero(done)), x_a[done], x_b[done],
                    p[done], theta[done], tangent[done], k)
        for row in np.flatnonzero(handoff):
            out.pending.append((int(members[row]), st.take(np.array([row]))))
        keep = np.flatnonzero(~(done | handoff))
        if keep.size == 0:
            return
        members, st, tension, previous, smallest = (members[keep], st.take(keep),
                                                    tension[keep], step[keep], smallest[keep])
        x_a, x_b, p, theta, tangent = x_a[keep], x_b[keep], p[keep], theta[keep], tangent[keep]


def _finish(out: _Outcome, members: NDArray[np.int64], st: _Stack, x_a: Array, x_b: Array,
            p: ComplexArray, theta: Array, tangent: ComplexArray, iterations: int) -> None:
    """Check closure (as :func:`limits.check_closure`) on converged members; store the rest."""
    out.iterations[members] = iterations
    closed = _min_gap(st, p, tangent) <= 0.0
    for row in np.flatnonzero(closed):
        m = int(members[row])
        grid = st.grids[row]
        shape = PlanarShape(p=p[row], theta=theta[row], tangent=tangent[row])
        try:
            check_closure(grid, shape, float(out.tensions[m]))
        except ModelError as error:
            out.fail(np.array([m]), error)
    ok = ~closed
    out.store(members[ok], p[ok, -1], theta[ok, -1], st.take(np.flatnonzero(ok)).strain(
        x_a[ok], x_b[ok]))
