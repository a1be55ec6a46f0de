"""Inverse design: which designs reach a tip target within a tension budget, and their Pareto set.

Candidates are the base design with some fields freed over ranges and sampled
(:mod:`tdcm_ros.model.design_sampling`). For each one the search finds the tension (N) in
``[0, tension_max]`` that puts the tip deflection (m) or tip angle (rad) on the target, and
whether it gets there inside every limit: no tendon singularity, no notch closure, the peak
notch bending strain (:attr:`~tdcm_ros.model.batch.BatchResult.max_bending_strain`) at most
``allowable_strain``, the solver converged. Every solve is the batch solver's
(:func:`~tdcm_ros.model.batch.prepare_batch`: each design's grid built once), so each answer is
the single ``solve``'s, bit for bit.

Tension for the target, per design (the tip and the strain grow with the tension, as
:func:`~tdcm_ros.model.solve_inverse` assumes):

1. a ladder of ``ladder`` tensions ``tension_max k / ladder`` (plus ``T = 0``, where the tip
   is on the axis) brackets the target by the first rung at or past it, or by the first rung
   where a limit is met (the target may lie just below that limit);
2. rounds of one batch solve per bracketed design at an estimate (inverse quadratic
   interpolation through the bracket and the last point replaced, kept inside the bracket;
   extrapolation from below, or bisection, when the upper end is a limit with no tip), until
   the tip is within ``tol`` of the target (m or rad, as ``solve_inverse``'s ``tol``);
3. for a design that meets the target but leaves the limits below the budget's top, the same
   rounds find where it leaves them: the peak strain within ``STRAIN_RTOL`` below the
   allowable, or a closure or singularity bracketed to ``LIMIT_XTOL`` of the budget.

A design with several tendons has its ``tendon`` sought, the others held at ``tensions`` (N),
as :func:`~tdcm_ros.model.solve_inverse`; the batch solves it by ``solve``.

The reported tension is the last solve's: its tip, strain and status are those of ``solve`` at
that tension. It differs from ``solve_inverse``'s by at most about ``2 tol / (dtip/dT)`` (both
stop within ``tol`` of the target).

Outcomes: ``meets`` (reaches the target inside every limit), ``short`` (the tip at the
budget's top, inside every limit, falls short), ``strain`` (the target needs more than the
allowable strain), ``limit`` (a singularity, closure or non-convergence comes first), ``invalid``
(the sampled fields are not a valid design). The Pareto set is that of the ``meets`` designs on
(reach: larger is better, peak strain at the target, tension needed: smaller is better). The
reach is the largest tip of any solve of the design inside every limit: the tip at the
budget's top, or where step 3 found the limit (for a ``meets`` design; for the others, at the
highest rung inside the limits).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.batch import BatchGrids, BatchResult, prepare_batch
from tdcm_ros.model.design import Design
from tdcm_ros.model.design_sampling import (
    FreeRange,
    candidate,
    free_ranges,
    sample_unit,
    scale,
)
from tdcm_ros.model.design_space import DEFAULT_ALLOWABLE_STRAIN, _allowable
from tdcm_ros.model.errors import (
    InvalidDesignError,
    InvalidSettingsError,
    ModelLimitError,
)
from tdcm_ros.model.inverse import (
    DEFAULT_TOL,
    InvalidTargetError,
    one_target,
    sought_tendon,
)
from tdcm_ros.model.pareto import non_dominated
from tdcm_ros.model.progress import Progress, report_progress
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS

Array = NDArray[np.float64]

TARGET_KINDS = ("tip_deflection", "tip_angle")
UNITS = {"tip_deflection": "m", "tip_angle": "rad"}
OUTCOMES = ("meets", "short", "strain", "limit", "invalid")
DEFAULT_DESIGN_SAMPLES = 100_000
DEFAULT_TENSION_BUDGET_N = 20.0
"""The bench's tension range (0-20 N), the budget of issue 18's target."""
DEFAULT_DESIGN_LADDER = 4
"""Rungs of the tension ladder. bench/bench_design.py: 2 rungs ran ~10 % faster and 8 ~25 %
slower (each design's grid, built once, costs more than a rung); 4 keeps rungs a quarter of
the budget apart, so a deflection that rises past the target and falls again between rungs
(past ~2.3 rad of tip angle) is less likely to be missed."""
MAX_LADDER = 1000
MAX_ROUNDS = 60
"""Refinement rounds at most (bisection to a limit needs ~35)."""
LIMIT_XTOL = 1e-10
"""A bracket closed to this fraction of the budget at a limit ends the design's search."""
STRAIN_RTOL = 1e-9
"""A design's reach ends where its peak strain is within this fraction below the allowable."""
BATCH_DESIGNS = 8192
"""Designs searched together: bounds memory; each batch is one progress step."""


class NoDesignMeetsTargetError(ModelLimitError):
    """No candidate design reaches the target within the budget inside every limit; the
    message names the closest one. ``search`` is the whole :class:`DesignSearch`."""

    kind = "no_design_meets_target"

    def __init__(self, message: str, *, search: DesignSearch) -> None:
        super().__init__(message)
        self.search = search


@dataclass(frozen=True, eq=False)
class DesignSearch:
    """The candidates of a search and what each achieves; arrays have one entry per sample.

    ``values`` holds each free field's sampled values (SI units); ``outcome`` names from
    :data:`.OUTCOMES` and ``message`` the limit or error met (empty otherwise).
    ``tension_n`` (N) is the tension that puts the tip on the target, ``tip_value`` the tip
    there (m or rad), ``peak_strain`` the peak notch strain there (NaN where the target is not
    reached: ``short``, ``limit``, ``invalid``, some ``strain``). ``reach`` (m or rad) and
    ``reach_tension_n`` (N): the largest tip of the design's solves inside every limit, and
    the tension of that solve (see the module's docstring). ``pareto``: indices of the Pareto set, by tension needed. ``solves``: members
    solved; ``rounds``: most refinement rounds of any batch.
    """

    base: Design
    target_kind: str
    target: float
    tension_max_n: float
    allowable_strain: float
    tol: float
    ladder: int
    ranges: tuple[FreeRange, ...]
    sampling: str
    seed: int
    values: dict[str, Array]
    outcome: NDArray[np.str_]
    message: NDArray[np.object_]
    tension_n: Array
    tip_value: Array
    peak_strain: Array
    reach: Array
    reach_tension_n: Array
    pareto: NDArray[np.int64]
    solves: int
    rounds: int

    @property
    def unit(self) -> str:
        """Unit of the target, tip values and reach."""
        return UNITS[self.target_kind]

    def design(self, index: int) -> Design:
        """Candidate ``index`` as a :class:`Design`."""
        return candidate(self.base, {name: float(v[index]) for name, v in self.values.items()})

    def counts(self) -> dict[str, int]:
        """Candidates per outcome."""
        return {name: int(np.sum(self.outcome == name)) for name in OUTCOMES}

    def row(self, index: int) -> dict[str, Any]:
        """JSON-ready figures of candidate ``index`` (SI units)."""
        free = {name: (int(v[index]) if span.integer else float(v[index]))
                for span, (name, v) in zip(self.ranges, self.values.items(), strict=True)}
        return {"index": int(index), "free": free, "design": self.design(index).to_dict(),
                "tension_n": float(self.tension_n[index]),
                self.target_kind: float(self.tip_value[index]),
                "peak_strain": float(self.peak_strain[index]),
                "reach": float(self.reach[index]),
                "reach_tension_n": float(self.reach_tension_n[index])}

    def summary(self) -> dict[str, Any]:
        """The JSON-ready summary (``tdcm design --json``): the search, the counts, the Pareto
        set by tension needed."""
        return {"target": {"kind": self.target_kind, "value": self.target, "unit": self.unit},
                "tension_budget_n": [0.0, self.tension_max_n],
                "allowable_strain": self.allowable_strain, "tol": self.tol,
                "ladder": self.ladder, "base_design": self.base.to_dict(),
                "free": {r.name: [r.low, r.high] for r in self.ranges},
                "sampling": self.sampling, "seed": self.seed, "samples": int(self.outcome.size),
                "counts": self.counts(), "solves": self.solves, "rounds": self.rounds,
                "pareto": [self.row(int(i)) for i in self.pareto]}


def search_designs(base: Design, free: Mapping[str, Any], *,
                   tip_deflection: float | None = None, tip_angle: float | None = None,
                   tension_max: float = DEFAULT_TENSION_BUDGET_N,
                   allowable_strain: float = DEFAULT_ALLOWABLE_STRAIN,
                   samples: int = DEFAULT_DESIGN_SAMPLES, sampling: str = "sobol", seed: int = 0,
                   ladder: int = DEFAULT_DESIGN_LADDER, tol: float = DEFAULT_TOL,
                   settings: SolverSettings = DEFAULT_SETTINGS,
                   progress: Progress | None = None, tendon: int | str | None = None,
                   tensions: Sequence[float] | None = None) -> DesignSearch:
    """Sample ``samples`` designs (``base`` with the fields of ``free`` = ``{name: (low,
    high)}`` varied) and find, for each, the tension in ``[0, tension_max]`` N that puts the
    tip on the target (one of ``tip_deflection`` m, ``tip_angle`` rad, within ``tol``) inside
    every limit; return them all with the Pareto set. ``progress("design search", designs
    done, samples)`` after each batch of designs. A base with several tendons names the
    ``tendon`` whose tension is sought, the others held at ``tensions`` (N, one per tendon;
    default 0), as :func:`~tdcm_ros.model.solve_inverse`.

    Raises :class:`InvalidTargetError`, :class:`InvalidDesignError` or
    :class:`InvalidSettingsError` for bad input (naming the parameter, value and range), and
    :class:`NoDesignMeetsTargetError` (exit status 3) when no candidate meets the target.
    """
    if not isinstance(base, Design):
        raise InvalidDesignError(f"base = {base!r} is not a Design", parameter="base",
                                 value=base, allowed="tdcm_ros.model.Design")
    kind, target = _target(tip_deflection, tip_angle)
    sought, held = sought_tendon(base, tendon, tensions)
    budget = _positive("tension_max", tension_max, "N")
    tolerance = _positive("tol", tol, UNITS[kind])
    strain_limit = _allowable(allowable_strain)
    if isinstance(ladder, bool) or not isinstance(ladder, int) or not 1 <= ladder <= MAX_LADDER:
        raise out_of_range("ladder", ladder, f"an integer in [1, {MAX_LADDER}]",
                           error=InvalidSettingsError)
    ranges = free_ranges(base, free)
    values = scale(ranges, sample_unit(len(ranges), samples, sampling, seed))
    problem = _Problem(base, kind, target, budget, strain_limit, tolerance, ladder, settings,
                       sought, held)
    found = _Found(samples)
    report_progress(progress, "design search", 0, samples)
    for start in range(0, samples, BATCH_DESIGNS):
        stop = min(samples, start + BATCH_DESIGNS)
        problem.search(np.arange(start, stop), values, ranges, found)
        report_progress(progress, "design search", stop, samples)
    meets = np.flatnonzero(found.outcome == "meets")
    front = meets[non_dominated(np.column_stack(
        [-found.reach[meets], found.strain[meets], found.tension[meets]]))]
    search = DesignSearch(
        base=base, target_kind=kind, target=target, tension_max_n=budget,
        allowable_strain=strain_limit, tol=tolerance, ladder=ladder, ranges=ranges,
        sampling=sampling, seed=seed, values=values, outcome=found.outcome,
        message=found.message, tension_n=found.tension, tip_value=found.tip,
        peak_strain=found.strain, reach=found.reach, reach_tension_n=found.reach_tension,
        pareto=front[np.argsort(found.tension[front], kind="stable")], solves=found.solves,
        rounds=found.rounds)
    if meets.size == 0:
        raise NoDesignMeetsTargetError(_closest(search), search=search)
    return search


def _target(tip_deflection: float | None, tip_angle: float | None) -> tuple[str, float]:
    """The one target given, ``(kind, value)``, finite and > 0."""
    kind, value = one_target(dict(zip(TARGET_KINDS, (tip_deflection, tip_angle), strict=True)))
    return kind, _positive(kind, value, UNITS[kind])


def _positive(name: str, value: Any, unit: str) -> float:
    """``value`` as a float, finite and > 0, or :class:`InvalidTargetError`."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)) \
            or not (math.isfinite(value) and value > 0.0):
        raise out_of_range(name, value, f"(0, inf) {unit}, finite", error=InvalidTargetError)
    return float(value)


class _Found:
    """Per-sample outputs while the search runs."""

    def __init__(self, samples: int) -> None:
        self.outcome = np.full(samples, "short", dtype="<U8")
        self.message = np.full(samples, "", dtype=object)
        self.tension = np.full(samples, np.nan)
        self.tip = np.full(samples, np.nan)
        self.strain = np.full(samples, np.nan)
        self.reach = np.zeros(samples)
        self.reach_tension = np.zeros(samples)
        self.solves = 0
        self.rounds = 0


@dataclass(frozen=True)
class _Problem:
    """The fixed part of a search: base design, target, budget, limits, ladder, settings."""

    base: Design
    kind: str
    target: float
    budget: float
    strain_limit: float
    tol: float
    ladder: int
    settings: SolverSettings
    sought: int
    held: tuple[float, ...] | None

    def measure(self, result: BatchResult) -> Array:
        """The target's quantity of a batch result (NaN where it did not solve)."""
        return result.tip_deflection_m if self.kind == "tip_deflection" else result.tip_angle_rad

    def search(self, samples: NDArray[np.int64], values: Mapping[str, Array],
               ranges: tuple[FreeRange, ...], found: _Found) -> None:
        """Search samples ``samples``, writing into ``found``."""
        designs, kept = [], []
        for i in samples:
            try:
                designs.append(candidate(self.base, {r.name: float(values[r.name][i])
                                                     for r in ranges}))
            except InvalidDesignError as error:
                found.outcome[i], found.message[i] = "invalid", str(error)
                continue
            kept.append(i)
        if not designs:
            return
        grids = _Driven(prepare_batch(designs, settings=self.settings), self.sought, self.held)
        ids = np.asarray(kept, np.int64)
        rungs = self.budget * np.arange(1, self.ladder + 1) / self.ladder
        result = grids.solve(np.broadcast_to(rungs, (len(designs), self.ladder)))
        found.solves += result.status.size
        feasible = (result.status == "ok") & (result.max_bending_strain <= self.strain_limit)
        prefix = np.cumprod(feasible, axis=1).astype(bool)
        target = _Rounds(grids, ids, self.budget, self.measure,
                         lambda q: np.abs(q - self.target) <= self.tol)
        rounds = target.run(self._ladder(result, rungs, prefix, ids, found), self.target,
                            lambda where, t, r, q, hit: self._met(where, t, r, q, hit, found))
        for where, message in target.left:
            found.outcome[where], found.message[where] = "limit", message
        boundary = _Rounds(grids, ids, self.budget, lambda r: r.max_bending_strain,
                           lambda q: (q >= (1.0 - STRAIN_RTOL) * self.strain_limit)
                           & (q <= self.strain_limit))
        rounds += boundary.run(self._boundary(result, rungs, prefix, ids, found),
                               self.strain_limit,
                               lambda where, t, r, q, hit: self._inside(where, t, r, found))
        found.rounds = max(found.rounds, rounds)
        found.solves += target.solves + boundary.solves

    def _ladder(self, result: BatchResult, rungs: Array, prefix: NDArray[np.bool_],
                ids: NDArray[np.int64], found: _Found) -> _Bracket:
        """Classify by the ladder (``prefix``: rungs below the first outside a limit); the
        bracket of each design the refinement continues."""
        tip = self.measure(result)
        solved = result.status == "ok"
        within = np.where(prefix, tip, 0.0)  # a deflection falls again past ~2.3 rad: the max
        top = np.argmax(within, axis=1)
        rows = np.arange(ids.size)
        found.reach[ids] = within[rows, top]
        found.reach_tension[ids] = np.where(prefix[rows, top], rungs[top], 0.0)
        stop = ~solved | (tip >= self.target)
        stops = stop.any(axis=1)
        first = np.where(stops, np.argmax(stop, axis=1), self.ladder)
        over_below = (~prefix & solved & (np.arange(self.ladder) < first[:, None])).any(axis=1)
        found.outcome[ids[~stops]] = "short"
        over = stops & over_below
        found.outcome[ids[over]] = "strain"
        go = np.flatnonzero(stops & ~over_below)
        j = first[go]
        padded_t = np.concatenate([[0.0], rungs])
        padded_m = np.column_stack([np.zeros(ids.size), tip])
        below = np.where(j >= 1, j - 1, -1)  # the rung below a's (-1: none)
        status_b = result.status[go, j]
        return _Bracket(
            rows=go, a_t=padded_t[j], a_m=padded_m[go, j], b_t=rungs[j],
            b_m=np.where(status_b == "ok", tip[go, j], np.nan),
            b_message=result.message[go, j],
            c_t=np.where(below >= 0, padded_t[np.maximum(below, 0)], np.nan),
            c_m=np.where(below >= 0, padded_m[go, np.maximum(below, 0)], np.nan))

    def _met(self, where: NDArray[np.int64], tension: Array, result: BatchResult, tip: Array,
             hit: NDArray[np.bool_], found: _Found) -> None:
        """Record the designs ``where`` whose tip ``hit`` the target at ``tension``."""
        where, tension, tip = where[hit], tension[hit], tip[hit]
        strain = result.max_bending_strain[hit]
        found.tension[where], found.tip[where], found.strain[where] = tension, tip, strain
        inside = strain <= self.strain_limit
        found.outcome[where] = np.where(inside, "meets", "strain")
        better = inside & (tip > found.reach[where])
        found.reach[where[better]] = tip[better]
        found.reach_tension[where[better]] = tension[better]

    def _boundary(self, result: BatchResult, rungs: Array, prefix: NDArray[np.bool_],
                  ids: NDArray[np.int64], found: _Found) -> _Bracket:
        """Brackets of the strain, closure or singularity limit of each design that meets
        the target but not every rung: from its highest point inside the limits (the rung
        below or the target's tension) to the first rung outside them."""
        count = prefix.sum(axis=1)
        go = np.flatnonzero((found.outcome[ids] == "meets") & (count < self.ladder))
        f = count[go]
        strain = result.max_bending_strain
        below_t = np.where(f >= 1, rungs[np.maximum(f - 1, 0)], 0.0)
        below_s = np.where(f >= 1, strain[go, np.maximum(f - 1, 0)], 0.0)
        at_target = found.tension[ids[go]] > below_t
        nan = np.full(go.size, np.nan)
        return _Bracket(
            rows=go, a_t=np.where(at_target, found.tension[ids[go]], below_t),
            a_m=np.where(at_target, found.strain[ids[go]], below_s), b_t=rungs[f],
            b_m=np.where(result.status[go, f] == "ok", strain[go, f], np.nan),
            b_message=result.message[go, f], c_t=nan, c_m=nan)

    def _inside(self, where: NDArray[np.int64], tension: Array, result: BatchResult,
                found: _Found) -> None:
        """Raise the reach of the designs ``where`` by their solves at ``tension`` that are
        inside every limit."""
        tip = self.measure(result)
        inside = (result.status == "ok") & (result.max_bending_strain <= self.strain_limit)
        better = inside & (tip > found.reach[where])
        found.reach[where[better]] = tip[better]
        found.reach_tension[where[better]] = tension[better]


Record = Callable[[NDArray[np.int64], Array, BatchResult, Array, NDArray[np.bool_]], None]


@dataclass(frozen=True)
class _Driven:
    """Batch solves at the sought tendon's tensions (N), the others at ``held`` (None: the
    paper's one tendon)."""

    grids: BatchGrids
    sought: int
    held: tuple[float, ...] | None

    def solve(self, tensions: Array, *, subset: NDArray[np.int64] | None = None) -> BatchResult:
        """:meth:`BatchGrids.solve` with ``tensions`` (N) the sought tendon's."""
        if self.held is None:
            return self.grids.solve(tensions, subset=subset)
        vectors = np.empty(np.shape(tensions) + (len(self.held),))
        vectors[...] = self.held
        vectors[..., self.sought] = tensions
        return self.grids.solve(vectors, subset=subset)


class _Rounds:
    """Rounds of one batch solve per bracketed design (``ids``: sample of each batch row) at
    :meth:`_Bracket.estimate`, until ``quantity`` of the solve satisfies ``hit``; a bracket
    closed at a limit (``LIMIT_XTOL`` of the budget) or still open after ``MAX_ROUNDS`` ends
    that design's search, listed in ``left`` with the reason."""

    def __init__(self, grids: _Driven, ids: NDArray[np.int64], budget: float,
                 quantity: Callable[[BatchResult], Array],
                 hit: Callable[[Array], NDArray[np.bool_]]) -> None:
        self.grids, self.ids, self.budget = grids, ids, budget
        self.quantity, self.hit = quantity, hit
        self.left: list[tuple[NDArray[np.int64], Any]] = []
        self.solves = 0

    def run(self, bracket: _Bracket, level: float, record: Record) -> int:
        """Refine ``bracket`` toward ``quantity = level``; ``record(samples, tensions, result,
        quantity, hit)`` sees every round's solves. Returns the rounds run."""
        b, rounds = bracket, 0
        while b.rows.size and rounds < MAX_ROUNDS:
            rounds += 1
            estimate = b.estimate(level)
            result = self.grids.solve(estimate, subset=b.rows)
            self.solves += b.rows.size
            solved = result.status == "ok"
            value = np.where(solved, self.quantity(result), np.nan)
            hit = solved & self.hit(value)
            record(self.ids[b.rows], estimate, result, value, hit)
            b = b.update(estimate, value, result.message, level).drop(hit)
            closed = b.b_t - b.a_t <= LIMIT_XTOL * self.budget
            if closed.any():
                self.left.append((self.ids[b.rows[closed]], b.b_message[closed]))
                b = b.drop(closed)
        if b.rows.size:
            self.left.append((self.ids[b.rows],
                              f"the search did not settle within {MAX_ROUNDS} rounds"))
        return rounds


@dataclass(frozen=True)
class _Bracket:
    """Per bracketed design (``rows`` of the batch): the lower end ``a`` (tip below the
    target), the upper end ``b`` (tip at or past it, or NaN where a limit was met there, with
    its message) and the last point replaced ``c`` (NaN: none), as tension (N) and tip."""

    rows: NDArray[np.int64]
    a_t: Array
    a_m: Array
    b_t: Array
    b_m: Array
    b_message: NDArray[np.object_]
    c_t: Array
    c_m: Array

    def estimate(self, target: float) -> Array:
        """The next tension of each design: inverse quadratic interpolation through a, b, c;
        else the secant of a and b; with no tip at b, the secant of c and a extrapolated; a
        bisection when the estimate leaves the bracket."""
        with np.errstate(divide="ignore", invalid="ignore"):
            ya, yb, yc = self.a_m - target, self.b_m - target, self.c_m - target
            quadratic = (self.a_t * yb * yc / ((ya - yb) * (ya - yc))
                         + self.b_t * ya * yc / ((yb - ya) * (yb - yc))
                         + self.c_t * ya * yb / ((yc - ya) * (yc - yb)))
            secant = self.a_t - ya * (self.b_t - self.a_t) / (yb - ya)
            low_t = np.where(np.isnan(self.c_t), 0.0, self.c_t)
            low_m = np.where(np.isnan(self.c_m), 0.0, self.c_m)
            extrapolated = self.a_t - ya * (self.a_t - low_t) / (self.a_m - low_m)
        guess = np.where(np.isfinite(quadratic), quadratic, secant)
        guess = np.where(np.isnan(self.b_m), extrapolated, guess)
        inside = np.isfinite(guess) & (guess > self.a_t) & (guess < self.b_t)
        return np.where(inside, guess, 0.5 * (self.a_t + self.b_t))

    def update(self, tension: Array, tip: Array, message: NDArray[np.object_],
               target: float) -> _Bracket:
        """The brackets after solving at ``tension``: tip below the target moves ``a``, at or
        past it (or no tip: a limit) moves ``b``; the end replaced becomes ``c``."""
        low = np.isfinite(tip) & (tip < target)
        high = ~low
        return _Bracket(
            rows=self.rows,
            a_t=np.where(low, tension, self.a_t), a_m=np.where(low, tip, self.a_m),
            b_t=np.where(high, tension, self.b_t), b_m=np.where(high, tip, self.b_m),
            b_message=np.where(high, message, self.b_message),
            c_t=np.where(low, self.a_t, self.b_t), c_m=np.where(low, self.a_m, self.b_m))

    def drop(self, done: NDArray[np.bool_]) -> _Bracket:
        """The brackets without the designs ``done``."""
        keep = ~done
        return _Bracket(self.rows[keep], self.a_t[keep], self.a_m[keep], self.b_t[keep],
                        self.b_m[keep], self.b_message[keep], self.c_t[keep], self.c_m[keep])


def _closest(search: DesignSearch) -> str:
    """Why no design meets the target, naming the closest candidate."""
    counts = search.counts()
    shown = f"{search.target_kind} = {search.target:g} {search.unit}"
    head = (f"no design reaches {shown} within 0-{search.tension_max_n:g} N inside the limits "
            f"({', '.join(f'{v} {k}' for k, v in counts.items() if v)})")
    strained = np.flatnonzero((search.outcome == "strain") & np.isfinite(search.peak_strain))
    if strained.size:
        best = int(strained[np.argmin(search.peak_strain[strained])])
        return (f"{head}; the closest reaches it at {search.tension_n[best]:.6g} N with peak "
                f"strain {search.peak_strain[best]:.4g} > allowable "
                f"{search.allowable_strain:g}: {_fields(search, best)}")
    valid = np.flatnonzero(search.outcome != "invalid")
    if valid.size == 0:
        return f"{head}; no sampled combination is a valid design: {search.message[0]}"
    if counts["strain"]:
        head += (f"; {counts['strain']} reach it only past the allowable strain "
                 f"{search.allowable_strain:g}")
    best = int(valid[np.argmax(search.reach[valid])])
    return (f"{head}; the closest reaches {search.reach[best]:.6g} {search.unit} at "
            f"{search.reach_tension_n[best]:.6g} N inside the limits: {_fields(search, best)}")


def _fields(search: DesignSearch, index: int) -> str:
    """The free fields of candidate ``index`` as text."""
    return ", ".join(f"{r.name} = {search.values[r.name][index]:.6g}" for r in search.ranges)
