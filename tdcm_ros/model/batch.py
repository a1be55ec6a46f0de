"""Vectorised Algorithm 1: many designs and tensions in one call, same answers as ``solve``.

Every design's grid is built at once (:func:`~tdcm_ros.model.grid.grid_parts`, compiled;
a :class:`~tdcm_ros.model.grid.Grid` object is built only for a member whose limit check
needs its error message); designs of one cell count form a stack, whose members the
compiled iteration reads through per-design index tables into the prototype cells' integrals
(:func:`~tdcm_ros.model.kernel.iterate_prototypes`: each design's cells laid out in cache as it
is iterated, no gathered copy of every design's), and every member
runs the kernels of :func:`tdcm_ros.model.solve` itself (:mod:`tdcm_ros.model.kernel`:
closed-form loads, initial moment ``R_c T``, stop when no node moves more than ``tol``):
plain (or, for ``acceleration="relaxation"``, damped) iteration runs in the kernel; a member that ``solve`` would hand to Anderson mixing, relaxation or
continuation (it slowed down, diverged or ran out of budget), and every member under
``loads="literal"``, is solved by ``solve`` itself. The tendon-offset singularity (before
iterating, the formula of :mod:`tdcm_ros.model.limits`) and notch closure (on the solution,
the kernel's notch gaps) are checked per member.

A design the kernel does not take (tendons other than the paper's one, a material law other
than the linear one, or ``axial="compressible"`` settings) has every member solved by ``solve``
(``fallback`` set): the batch takes any design ``solve`` takes. Designs with ``k`` tendons take a
tension per tendon on a last axis of length ``k`` (every design of a batch lists as many).

Nothing is raised for a member: each gets a status (``STATUSES``) and a message. Numbers are
returned only for ``ok`` members; the others hold NaN.

:func:`prepare_batch` builds the grids once and :meth:`BatchGrids.solve` solves them (or a
subset) at any tensions, as often as needed: a search over designs solves in rounds without
rebuilding grids (the grid build is most of a one-tension batch's cost).
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.model.cells import FC_FIELDS, FQ_FIELDS
from tdcm_ros.model.compiled import kernels
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import (
    InvalidDesignError,
    InvalidSettingsError,
    ModelError,
    TensionRangeError,
)
from tdcm_ros.model.grid import (
    NESTED,
    PEAK_SAMPLES,
    Grid,
    GridParts,
    KernelIndices,
    build_grid,
    grid_parts,
)
from tdcm_ros.model.grid_layout import Members
from tdcm_ros.model.kernel import CONVERGED
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.limits import check_closure, check_tendon_singularity, check_tension
from tdcm_ros.model.moment_model import DIVERGENCE_GROWTH
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS, SLOW_CONTRACTION, solve
from tdcm_ros.model.tendons import is_paper_like

Array = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

STATUSES = ("ok", "singularity", "closure", "non_convergence", "invalid")
"""Member statuses; ``kink_angle`` can also appear, under ``loads="literal"`` only, and
``strain_limit`` for a material's recoverable strain."""

_STATUS_OF_KIND = {"tendon_singularity": "singularity", "notch_closure": "closure",
                   "non_convergence": "non_convergence", "invalid_design": "invalid",
                   "tension_out_of_range": "invalid"}
CHUNK = 256
"""Members iterated together: small enough that the chunk's arrays stay in cache (measured
~1.7x faster than 2048); any size gives the same answers."""
MAX_WORKERS = 64


@dataclass(frozen=True, eq=False)
class BatchResult:
    """Per-member outcome of :func:`solve_batch`; arrays have the members' shape: that of
    ``tensions``, less its last (tendon) axis where the designs list several tendons.

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
    """Designs ``rows`` of ``parts``, all of one cell count; per design its tendon offset
    ``r_c`` (m) and largest compliance where the tendon follows the body
    ``constrained_peak_c`` (1/(N m^2)), for the screening before iterating, and what the
    compiled iteration reads besides the prototype cells' integrals (``indices``, built once
    with the stack: :func:`~tdcm_ros.model.kernel.iterate_prototypes` lays each design's
    numbers out in cache as it iterates it)."""

    parts: GridParts
    rows: NDArray[np.int64]
    settings: SolverSettings
    r_c: Array
    constrained_peak_c: Array
    indices: KernelIndices

    @classmethod
    def split(cls, parts: GridParts, settings: SolverSettings
              ) -> list[tuple[NDArray[np.int64], _Stack]]:
        """``(rows of parts, stack)`` for every cell count of ``parts``."""
        counts = parts.table.count
        proto = parts.table.prototypes
        peak = np.zeros(counts.size)
        follows = ~proto.chord
        np.maximum.at(peak, proto.member[follows], parts.arm_weighted_peaks[:-1][follows])
        out = []
        for count in np.unique(counts):
            rows = np.flatnonzero(counts == count)
            out.append((rows, cls(parts=parts, rows=rows, settings=settings,
                                  r_c=parts.members.R_c[rows],
                                  constrained_peak_c=peak[rows],
                                  indices=parts.kernel_indices(rows))))
        return out

    def grid(self, row: int) -> Grid:
        """The :class:`Grid` of design ``row`` (built on demand, for an error message)."""
        return build_grid(self.parts.members.designs[self.rows[row]], self.settings)

    def strain(self, rows: NDArray[np.int64], x: Array) -> Array:
        """Largest notch bending strain of members of design ``rows`` from their cell end
        moments ``x = [m_a, m_b]`` (N m)."""
        indices = self.indices
        build = kernels()
        coefficients = np.empty((rows.size, 2, indices.notch_proto.shape[1], PEAK_SAMPLES))
        build.gather(indices.notch_proto[rows], np.arange(2), self.parts.proto_strain,
                     coefficients)
        out = np.empty(rows.size)
        build.peak_strains(np.arange(rows.size), indices.notch_cells[rows], coefficients[:, 0],
                           coefficients[:, 1], np.ascontiguousarray(x), out)
        return out


def solve_batch(designs: Sequence[Design], tensions: ArrayLike, *,
                settings: SolverSettings = DEFAULT_SETTINGS, workers: int = 1,
                partials: str = NESTED) -> BatchResult:
    """Solve every design at its tensions (N); ``tensions`` has shape ``(len(designs), ...)``,
    with a last axis of one tension per tendon where the designs list ``k > 1`` tendons
    (``(len(designs), ..., k)``).

    A 1-D ``tensions`` pairs design ``i`` with tension ``i``; a 2-D one gives each design a
    row of tensions (a design-space grid). Results have the members' shape (``tensions``'
    less the tendon axis).
    ``workers`` threads build the grids and iterate chunks of members at once (the compiled
    kernels release the GIL); the answers do not depend on it. ``partials`` is the grid's
    rule for its partial integrals (:data:`~tdcm_ros.model.grid.PARTIAL_RULES`): ``nested``
    (the single solve's: the same answers), or ``interpolated`` (no compliance evaluation
    beyond the Gauss points and probes, 25 instead of 61 per notch cell at the default
    quadrature order: tips within ~1e-9 m of the single solve's at the default settings,
    ``bench/grid_accuracy.py``). The same as ``prepare_batch(designs, ...).solve(tensions)``.
    """
    return prepare_batch(designs, settings=settings, workers=workers,
                         partials=partials).solve(tensions)


def prepare_batch(designs: Sequence[Design], *, settings: SolverSettings = DEFAULT_SETTINGS,
                  workers: int = 1, partials: str = NESTED) -> BatchGrids:
    """Build the grids of ``designs`` once (partial integrals by the rule ``partials``, see
    :func:`solve_batch`), for :meth:`BatchGrids.solve` to solve them at any tensions, as often
    as needed (a search that solves the same designs in rounds)."""
    designs = list(designs)
    for i, design in enumerate(designs):
        if not isinstance(design, Design):
            raise InvalidDesignError(
                f"designs[{i}] = {design!r} is not a Design", parameter=f"designs[{i}]",
                value=design, allowed="tdcm_ros.model.Design")
    tendons = _tendon_count(designs)
    if not isinstance(settings, SolverSettings):
        raise InvalidSettingsError(f"settings = {settings!r} is not a SolverSettings",
                                   parameter="settings", value=settings,
                                   allowed="tdcm_ros.model.SolverSettings")
    if isinstance(workers, bool) or not isinstance(workers, int) or \
            not 1 <= workers <= MAX_WORKERS:
        raise InvalidSettingsError(
            f"workers = {workers!r} is out of range; allowed: integer in [1, {MAX_WORKERS}]",
            parameter="workers", value=workers, allowed=f"integer in [1, {MAX_WORKERS}]")
    compiled = np.array([d for d, design in enumerate(designs) if _kernel_takes(design, settings)],
                        np.int64)
    valid, parts, invalid = _grids([designs[d] for d in compiled], settings, workers, partials)
    stacks = [] if parts is None else [(compiled[valid[rows]], stack)
                                       for rows, stack in _Stack.split(parts, settings)]
    single = np.setdiff1d(np.arange(len(designs)), compiled)
    return BatchGrids(tuple(designs), settings, workers,
                      {int(compiled[d]): error for d, error in invalid.items()}, stacks, single,
                      tendons)


def _kernel_takes(design: Design, settings: SolverSettings) -> bool:
    """Whether the compiled iteration solves ``design`` (else ``solve`` does): the paper's one
    tendon, the linear law without a strain limit, a rigid midline."""
    return is_paper_like(design.tendons) and design.material.is_trivial and \
        settings.axial == "rigid"


def _tendon_count(designs: list[Design]) -> int:
    """The number of tendons every design lists (1 for none); raises
    :class:`InvalidDesignError` naming the first design that lists another number."""
    counts = [len(design.tendon_list()) for design in designs]
    for i, count in enumerate(counts):
        if count != counts[0]:
            raise InvalidDesignError(
                f"designs[{i}].tendons: {count} tendon(s) where designs[0] has {counts[0]}; "
                "allowed: as many tendons in every design of a batch (one tension each)",
                parameter=f"designs[{i}].tendons", value=count, allowed=f"{counts[0]} tendons")
    return counts[0] if counts else 1


@dataclass(frozen=True, eq=False)
class BatchGrids:
    """Grids of ``designs`` built once by :func:`prepare_batch`; ``invalid`` maps a design
    whose grid cannot be built to its error, ``stacks`` holds the others as ``(design
    indices, stack)`` per cell count; ``single`` lists the designs ``solve`` solves (the kernel
    does not take them), ``tendons`` the number of tendons of every design."""

    designs: tuple[Design, ...]
    settings: SolverSettings
    workers: int
    invalid: dict[int, InvalidDesignError]
    stacks: list[tuple[NDArray[np.int64], _Stack]]
    single: NDArray[np.int64]
    tendons: int

    def solve(self, tensions: ArrayLike, *, subset: ArrayLike | None = None) -> BatchResult:
        """Solve the designs (or the distinct design indices ``subset``, in its order) at
        ``tensions`` (N) of shape ``(number of designs solved, ...)``, as :func:`solve_batch`;
        the answers do not depend on which other designs are solved with them."""
        chosen = self._subset(subset)
        try:
            t_all = np.array(tensions, dtype=float)
        except (TypeError, ValueError) as exc:
            raise TensionRangeError(
                f"tensions = {tensions!r} are not numbers; allowed: [0, inf) N",
                parameter="tensions", value=tensions,
                allowed="array of numbers in [0, inf) N") from exc
        count = self.tendons
        axis = "" if count == 1 else f", {count}"
        if t_all.ndim < (1 if count == 1 else 2) or t_all.shape[0] != chosen.size or \
                (count > 1 and t_all.shape[-1] != count):
            raise TensionRangeError(
                f"tensions of shape {t_all.shape} do not match {chosen.size} designs of "
                f"{count} tendon(s); allowed: shape (len(designs), ...{axis})",
                parameter="tensions", value=t_all.shape, allowed=f"shape ({chosen.size}, ...{axis})")
        out = _Outcome(t_all.reshape(chosen.size, -1, count))
        k = out.per_design
        position = np.full(len(self.designs), -1, np.int64)
        position[chosen] = np.arange(chosen.size)
        for d, error in self.invalid.items():
            if position[d] >= 0:
                out.fail(position[d] * k + np.arange(k), error)
        for d in self.single[position[self.single] >= 0]:
            out.pending.extend((int(m), None, 0) for m in position[d] * k + np.arange(k))
        chunks: list[tuple[NDArray[np.int64], _Stack, NDArray[np.int64]]] = []
        for design_ids, stack in self.stacks:
            local = np.flatnonzero(position[design_ids] >= 0)
            if local.size:
                chunks += _screen_group(out, position[design_ids[local]], local, stack,
                                        self.settings)
        if self.workers == 1 or len(chunks) == 1:
            for members, stack, rows in chunks:
                _iterate(out, members, stack, rows, self.settings)
        else:
            with ThreadPoolExecutor(self.workers) as pool:
                list(pool.map(lambda c: _iterate(out, c[0], c[1], c[2], self.settings),
                              chunks))
        out.run_fallbacks([self.designs[d] for d in chosen], self.settings)
        return out.result(t_all.shape if count == 1 else t_all.shape[:-1], t_all.shape)

    def _subset(self, subset: ArrayLike | None) -> NDArray[np.int64]:
        """``subset`` checked: distinct indices of designs (all designs when ``None``)."""
        count = len(self.designs)
        if subset is None:
            return np.arange(count)
        chosen = np.asarray(subset)
        if chosen.ndim != 1 or (chosen.size and not np.issubdtype(chosen.dtype, np.integer)) \
                or np.any((chosen < 0) | (chosen >= count)) or \
                np.unique(chosen).size != chosen.size:
            raise InvalidSettingsError(
                f"subset = {subset!r} is out of range; allowed: distinct integers in "
                f"[0, {count})", parameter="subset", value=subset,
                allowed=f"distinct integers in [0, {count})")
        return chosen.astype(np.int64)


class _Outcome:
    """Per-member outputs while a batch runs (flat member index ``d * per_design + k``)."""

    def __init__(self, tensions: Array) -> None:
        """``tensions`` (designs, members per design, tendons), N."""
        self.per_design = tensions.shape[1]
        self.vectors = tensions.reshape(-1, tensions.shape[2])
        self.tensions = self.vectors[:, 0]
        size = self.tensions.size
        self.status = np.full(size, "ok", dtype="<U16")
        self.message = np.full(size, "", dtype=object)
        self.tip = np.full((size, 3), np.nan)
        self.angle = np.full(size, np.nan)
        self.strain = np.full(size, np.nan)
        self.iterations = np.zeros(size, np.int64)
        self.fallback = np.zeros(size, bool)
        self.pending: list[tuple[int, _Stack | None, int]] = []

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
        """Solve every pending member (with its stack and design row; no stack: a design the
        kernel does not take) by the single :func:`solve`."""
        for m, stack, row in self.pending:
            self.fallback[m] = True
            vector = self.vectors[m]
            try:
                result = solve(designs[m // self.per_design],
                               float(vector[0]) if vector.size == 1 else vector.tolist(),
                               settings=settings)
            except ModelError as error:
                self.fail(np.array([m]), error)
                self.iterations[m] = settings.max_iter if error.kind == "non_convergence" else 0
                continue
            x, _, z = result.tip_position
            strain = np.array([result.notch_peak_strains.max(initial=0.0)]) if stack is None \
                else stack.strain(np.array([row]), result.cell_moments.T.reshape(1, -1))
            self.store(np.array([m]), np.array([z + 1j * x]), np.array([result.tip_angle_rad]),
                       strain)
            self.iterations[m] = result.iterations

    def result(self, shape: tuple[int, ...], given: tuple[int, ...]) -> BatchResult:
        """The outcome in the members' ``shape`` (the tensions in their ``given`` one)."""
        deflection = np.hypot(self.tip[:, 0], self.tip[:, 1])
        return BatchResult(
            tensions=self.vectors.reshape(given), status=self.status.reshape(shape),
            message=self.message.reshape(shape), tip_position=self.tip.reshape(shape + (3,)),
            tip_angle_rad=self.angle.reshape(shape), tip_deflection_m=deflection.reshape(shape),
            max_bending_strain=self.strain.reshape(shape),
            iterations=self.iterations.reshape(shape), fallback=self.fallback.reshape(shape))


def _grids(designs: list[Design], settings: SolverSettings, workers: int, partials: str
           ) -> tuple[NDArray[np.int64], GridParts | None, dict[int, InvalidDesignError]]:
    """The designs whose grids build, their grids built at once by ``workers`` threads (partial
    integrals by the rule ``partials``), and the others' errors (each design is checked alone
    only if the whole set is refused)."""
    valid = np.arange(len(designs))
    try:
        return valid, grid_parts(designs, settings, workers, partials) if designs else None, {}
    except InvalidDesignError:
        pass
    kept, invalid = [], {}
    for d, design in enumerate(designs):
        try:
            Members.of([design])
        except InvalidDesignError as error:
            invalid[d] = error
            continue
        kept.append(d)
    valid = np.array(kept, np.int64)
    parts = grid_parts([designs[d] for d in kept], settings, workers, partials) if kept \
        else None
    return valid, parts, invalid


def _screen_group(out: _Outcome, design_ids: NDArray[np.int64], local: NDArray[np.int64],
                  stack: _Stack, settings: SolverSettings
                  ) -> list[tuple[NDArray[np.int64], _Stack, NDArray[np.int64]]]:
    """Screen rows ``local`` of one layout group (design ``design_ids[i]`` of ``out`` is row
    ``local[i]``), queue them for the single solve (literal loads) or return their chunks
    ``(members, stack, design rows)`` to iterate (closed loads)."""
    k = out.per_design
    rows = np.repeat(local, k)
    members = (design_ids[:, None] * k + np.arange(k)[None, :]).ravel()
    tension = out.tensions[members]
    bad = ~(np.isfinite(tension) & (tension >= 0.0))
    for m in members[bad]:
        try:
            check_tension(out.tensions[m])
        except TensionRangeError as error:
            out.fail(np.array([m]), error)
    # limits.check_tendon_singularity, evaluated in the same order of operations.
    r_c, peak = stack.r_c[rows], stack.constrained_peak_c[rows]
    singular = ~bad & (r_c**2 * tension * peak >= 1.0) & (r_c * (r_c * tension) * peak >= 1.0)
    for m, row in zip(members[singular], rows[singular]):
        try:
            check_tendon_singularity(stack.grid(int(row)), float(out.tensions[m]))
        except ModelError as error:
            out.fail(np.array([m]), error)
    keep = ~(bad | singular)
    members, rows = members[keep], rows[keep]
    if settings.loads != "closed":
        out.pending.extend((int(m), stack, int(r)) for m, r in zip(members, rows))
        return []
    return [(members[start:start + CHUNK], stack, rows[start:start + CHUNK])
            for start in range(0, members.size, CHUNK)]


def _iterate(out: _Outcome, members: NDArray[np.int64], st: _Stack, rows: NDArray[np.int64],
             settings: SolverSettings) -> None:
    """Algorithm 1 on one chunk (member ``members[i]`` is design row ``rows[i]`` of ``st``).

    The kernel's plain iteration, as in ``solver._iterate`` (damped for ``relaxation``; one
    plain step for ``anderson``); a member ``solve`` would switch to Anderson, or that
    diverges, turns non-finite or exhausts the budget, is queued for the single solve. The
    kernel also returns each converged member's peak notch strain (no separate pass).
    """
    mode = settings.acceleration
    budget = 1 if mode == "anderson" else settings.max_iter
    indices, parts = st.indices, st.parts
    n = indices.cell_proto.shape[1]
    tension = out.tensions[members]
    x = np.empty((members.size, 2 * n))
    x[...] = (st.r_c[rows] * tension)[:, None]
    p = np.empty((members.size, n + 1), np.complex128)
    theta = np.empty((members.size, n + 1))
    tangent = np.empty((members.size, n + 1), np.complex128)
    info = np.empty((members.size, 3 + budget))
    strain = np.empty(members.size)
    kernels().iterate_prototypes(
        parts.proto_fc[..., None], parts.proto_fq, parts.proto_strain, FC_FIELDS, FQ_FIELDS,
        indices.cell_proto, indices.ic, indices.notch, indices.scal, indices.notch_cells,
        indices.notch_proto, rows, tension, x, p, theta, tangent, settings.tol,
        settings.relaxation if mode == "relaxation" else 1.0,
        SLOW_CONTRACTION if mode == "auto" else 0.0, DIVERGENCE_GROWTH, info, strain)
    done = info[:, 1] == CONVERGED
    out.pending.extend((int(members[i]), st, int(rows[i])) for i in np.flatnonzero(~done))
    out.iterations[members[done]] = info[done, 0].astype(np.int64)
    closed = done & (info[:, 2] <= 0.0)
    for i in np.flatnonzero(closed):
        m = int(members[i])
        shape = PlanarShape(p=p[i], theta=theta[i], tangent=tangent[i])
        try:
            check_closure(st.grid(int(rows[i])), shape, float(out.tensions[m]))
        except ModelError as error:
            out.fail(np.array([m]), error)
    ok = done & ~closed
    out.store(members[ok], p[ok, -1], theta[ok, -1], strain[ok])
