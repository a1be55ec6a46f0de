"""Where a grid's cells go, for one design or many at once (numpy over the member axis).

A body is a row of segments (base tube, notch, tube, ..., notch, tip tube). A segment is cut
into pieces at its *breakpoints* and each piece into equal steps of the profile's reference
coordinate ``u``. Two kinds of grid:

- ``uniform``: one piece per segment, ``cells_per_notch`` or ``cells_per_tube`` cells;
- ``adaptive``: a notch is also cut where its profile ``h1`` crosses ``r_inner`` or
  ``R_outer``, the kinks of ``I(h1)`` (eq. 12's ``h2 = min(h1, r_inner)`` clip gives ``I`` a
  singular second derivative there, which no Gauss rule across it resolves). A segment where
  the tendon runs as a chord needs no extra cells: the bending moment bows inside it, and the
  grid's chord terms (:mod:`tdcm_ros.model.grid`) carry that.

Lengths in m; ``u`` is dimensionless in [0, 1].
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.profiles import CircularProfile, NotchProfile, RectangularProfile
from tdcm_ros.model.section import notched_moment

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

PEAK_SAMPLES = 17
#: Most breakpoints inside one notch: two crossings each of ``r_inner`` and ``R_outer``.
MAX_CROSSINGS = 4
#: Samples of a custom profile searched for crossings, and bisection steps per crossing.
CROSSING_SAMPLES = 129
BISECTION_STEPS = 60


@dataclass(frozen=True)
class Members:
    """Design parameters of every member, each an array of shape (M,) in SI units."""

    designs: tuple[Design, ...]
    profiles: tuple[NotchProfile, ...]
    profile_of: IntArray
    N: IntArray
    w_base: Array
    w_tip: Array
    w_n: Array
    w_t: Array
    w_d: Array
    R_outer: Array
    r_inner: Array
    R_c: Array
    E: Array
    tube_moment: Array
    length: Array

    @classmethod
    def of(cls, designs: Sequence[Design]) -> Members:
        """Collect and check ``designs`` (every profile finite and positive, ``E I`` finite)."""
        designs = tuple(designs)
        profiles: list[NotchProfile] = []
        index: dict[int, int] = {}
        profile_of = np.empty(len(designs), np.int64)
        for m, design in enumerate(designs):
            key = id(design.profile)
            if key not in index:
                same = next((k for k, p in enumerate(profiles) if p == design.profile), None)
                if same is None:
                    same = len(profiles)
                    profiles.append(design.profile)
                index[key] = same
            profile_of[m] = index[key]

        def column(name: str) -> Array:
            return np.array([getattr(d, name) for d in designs], dtype=float)

        n = np.array([d.N for d in designs], np.int64)
        w_base, w_n, w_t, w_tip = (column(k) for k in ("w_base", "w_n", "w_t", "w_tip"))
        r_outer, r_inner = column("R_outer"), column("r_inner")
        members = cls(designs=designs, profiles=tuple(profiles), profile_of=profile_of, N=n,
                      w_base=w_base, w_tip=w_tip, w_n=w_n, w_t=w_t, w_d=column("w_d"),
                      R_outer=r_outer, r_inner=r_inner, R_c=column("R_c"), E=column("E"),
                      tube_moment=np.pi / 4.0 * (r_outer**4 - r_inner**4),
                      length=w_base + n * w_n + (n - 1) * w_t + w_tip)
        for design in designs:
            if design.profile.name not in ("circular", "rectangular"):
                _check_custom_profile(design)
        _check_rigidity(members)
        return members

    def h1(self, member: IntArray, u: Array) -> Array:
        """Backbone half-width (m) at ``u``; ``member`` (n,) names the member of each row of u."""
        return self._per_profile(member, u, lambda p, x, w_n, w_d: p.h1(x, w_n, w_d))

    def sigma(self, member: IntArray, u: Array) -> Array:
        """Local arc length in a notch (m) at ``u``, rows of ``u`` as in :meth:`h1`."""
        return self._per_profile(member, u, lambda p, x, w_n, w_d: p.sigma(x, w_n))

    def dsigma_du(self, member: IntArray, u: Array) -> Array:
        """``d sigma / du`` in a notch (m) at ``u``, rows of ``u`` as in :meth:`h1`."""
        return self._per_profile(member, u, lambda p, x, w_n, w_d: p.dsigma_du(x, w_n))

    def _per_profile(self, member: IntArray, u: Array, evaluate: ProfileFunction) -> Array:
        """``evaluate(profile, u, w_n, w_d)`` with each row's member's profile and widths."""
        if len(self.profiles) == 1:
            return evaluate(self.profiles[0], u, per_row(self.w_n[member], u),
                            per_row(self.w_d[member], u))
        out = np.empty(u.shape)
        kinds = self.profile_of[member]
        for k, profile in enumerate(self.profiles):
            rows = kinds == k
            if np.any(rows):
                u_k = u[rows]
                out[rows] = evaluate(profile, u_k, per_row(self.w_n[member[rows]], u_k),
                                     per_row(self.w_d[member[rows]], u_k))
        return out


def per_row(values: NDArray[Any], u: Array) -> NDArray[Any]:
    """``values`` shaped to broadcast against ``u``: as is if they share u's shape (one value
    per element), else one value per row of u's first axis."""
    if values.shape == u.shape:
        return values
    return values.reshape((-1,) + (1,) * (u.ndim - 1))


ProfileFunction = Callable[[NotchProfile, Array, Array, Array], Array]


#: Segment kinds: every notch of a design is the same, and so is every tube between notches,
#: so each member's cells are computed once per kind and copied along the body.
BASE, NOTCH, TUBE, TIP = range(4)


@dataclass(frozen=True)
class Prototypes:
    """The cells of each member's four segment kinds, flat, in the segment's own coordinates.

    Per prototype cell (shape (p,)): ``member``, ``is_notch``, ``u_a``/``u_b`` (its ends in
    ``u``), ``a``/``length`` (its start from the segment start and its length, m),
    ``seg_length`` (m) and ``chord`` (the tendon crosses it as a chord); ``seg_start`` is 0.
    ``first`` (M, 4) is each kind's first prototype cell and ``count`` (M, 4) its cell count
    (0 for an absent segment).
    """

    members: Members
    member: IntArray
    is_notch: BoolArray
    chord: BoolArray
    u_a: Array
    u_b: Array
    a: Array
    length: Array
    seg_length: Array
    seg_start: Array
    first: IntArray
    count: IntArray


@dataclass(frozen=True)
class CellTable:
    """Every member's cells, flat (members one after another, base to tip), SI units.

    Per cell (shape (n,)): ``member``, ``prototype`` (its cell in :class:`Prototypes`),
    ``is_notch``, ``notch_index`` (-1 in tubes), ``seg_start``/``seg_length`` of its segment
    (m), ``u_a``/``u_b``, ``a`` (its start along s, m), ``constrained`` (the tendon follows the
    body there) and ``chord_start_node``/``chord_end_node`` (its segment's end nodes, counted
    within the member). Per member (shape (M,)): ``count`` cells from flat index ``first``;
    ``notch_left_node``/``notch_right_node`` (M, max N), padded with the member's tip node.
    """

    prototypes: Prototypes
    member: IntArray
    prototype: IntArray
    count: IntArray
    first: IntArray
    is_notch: BoolArray
    notch_index: IntArray
    seg_start: Array
    seg_length: Array
    u_a: Array
    u_b: Array
    a: Array
    constrained: BoolArray
    chord_start_node: IntArray
    chord_end_node: IntArray
    notch_left_node: IntArray
    notch_right_node: IntArray


def prototypes(members: Members, routing: str, kind: str, cells_per_notch: int,
               cells_per_tube: int) -> Prototypes:
    """Cut each member's base, notch, tube and tip into cells (see the module docstring)."""
    m_count = members.N.size
    is_notch_kind = np.arange(4) == NOTCH
    constrained_kind = _constrained_kinds(routing)
    per_kind = np.where(is_notch_kind, cells_per_notch, cells_per_tube)
    seg_length = np.stack([members.w_base, members.w_n, members.w_t, members.w_tip], axis=1)
    present = seg_length > 0.0
    present[:, TUBE] &= members.N > 1
    breaks = np.zeros((m_count, 4, MAX_CROSSINGS + 2))
    breaks[..., -1] = 1.0
    if kind == "adaptive":
        breaks[:, NOTCH, 1:-1] = np.sort(crossings(members), axis=1)
    width = np.diff(breaks, axis=-1)
    counts = np.where(width > 0.0, np.maximum(1, np.rint(per_kind[None, :, None] * width)), 0)
    counts = (counts * present[..., None]).astype(np.int64)

    flat_counts = counts.ravel()
    piece = np.repeat(np.arange(flat_counts.size), flat_counts)
    member = piece // (4 * (MAX_CROSSINGS + 1))
    seg_kind = (piece // (MAX_CROSSINGS + 1)) % 4
    j = (np.arange(piece.size) - (np.cumsum(flat_counts) - flat_counts)[piece]).astype(float)
    n_piece = flat_counts[piece]
    step = 1.0 / n_piece
    u0 = breaks[..., :-1].ravel()[piece]
    u1 = breaks[..., 1:].ravel()[piece]
    u_a = u0 + (u1 - u0) * (j * step)
    u_b = np.where(j + 1.0 == n_piece, u1, u0 + (u1 - u0) * ((j + 1.0) * step))
    is_notch = is_notch_kind[seg_kind]
    length_of_segment = seg_length[member, seg_kind]
    a = np.where(is_notch, members.sigma(member, u_a), length_of_segment * u_a)
    b = np.where(is_notch, members.sigma(member, u_b), length_of_segment * u_b)
    b = np.where(u_b == 1.0, length_of_segment, b)
    kind_counts = counts.sum(axis=-1)
    return Prototypes(members=members, member=member, is_notch=is_notch,
                      chord=~constrained_kind[seg_kind], u_a=u_a, u_b=u_b, a=a,
                      length=b - a, seg_length=length_of_segment, seg_start=np.zeros(a.size),
                      first=(np.cumsum(kind_counts.ravel()) - kind_counts.ravel()
                             ).reshape(m_count, 4),
                      count=kind_counts)


def cell_table(proto: Prototypes, routing: str) -> CellTable:
    """Lay every member's segments end to end, each a copy of its kind's prototype cells."""
    members = proto.members
    m_count = members.N.size
    n_max = int(members.N.max())
    slots = 2 * n_max + 1  # base, then (notch i, tube after notch i) for every i
    notch_i = np.arange(n_max)
    left = members.w_base[:, None] + notch_i.astype(float)[None, :] * (
        members.w_n + members.w_t)[:, None]
    right = left + members.w_n[:, None]
    has = notch_i[None, :] < members.N[:, None]
    last = notch_i[None, :] == (members.N - 1)[:, None]
    start = np.empty((m_count, slots))
    start[:, 0] = 0.0
    start[:, 1::2] = left
    start[:, 2::2] = right
    slot_kind = np.empty((m_count, slots), np.int64)
    slot_kind[:, 0] = BASE
    slot_kind[:, 1::2] = NOTCH
    slot_kind[:, 2::2] = np.where(last, TIP, TUBE)
    rows = np.arange(m_count)[:, None]
    seg_counts = proto.count[rows, slot_kind]
    seg_counts[:, 1:] *= np.repeat(has, 2, axis=1)

    flat = seg_counts.ravel()
    segment = np.repeat(np.arange(flat.size), flat)
    member = segment // slots
    slot = segment % slots
    j = np.arange(segment.size) - (np.cumsum(flat) - flat)[segment]
    kind = slot_kind[member, slot]
    prototype = proto.first[member, kind] + j
    count = seg_counts.sum(axis=1)
    seg_first = np.cumsum(seg_counts, axis=1) - seg_counts
    is_notch = kind == NOTCH
    seg_start = start[member, slot]
    chord_start = seg_first[member, slot]
    tip = count[:, None]
    return CellTable(
        prototypes=proto, member=member, prototype=prototype, count=count,
        first=np.cumsum(count) - count, is_notch=is_notch,
        notch_index=np.where(is_notch, (slot - 1) // 2, -1), seg_start=seg_start,
        seg_length=proto.seg_length[prototype], u_a=proto.u_a[prototype],
        u_b=proto.u_b[prototype], a=np.where(j == 0, seg_start, seg_start + proto.a[prototype]),
        constrained=_constrained_kinds(routing)[kind], chord_start_node=chord_start,
        chord_end_node=chord_start + seg_counts[member, slot],
        notch_left_node=np.where(has, seg_first[:, 1::2], tip),
        notch_right_node=np.where(has, seg_first[:, 1::2] + seg_counts[:, 1::2], tip))


def _constrained_kinds(routing: str) -> BoolArray:
    """Which segment kinds the tendon follows (``paper``: notches; ``free``: tubes)."""
    notch = np.arange(4) == NOTCH
    return notch if routing == "paper" else ~notch


def crossings(members: Members) -> Array:
    """Where each member's notch profile crosses ``r_inner`` and ``R_outer``, as ``u`` in (0, 1);
    shape (M, MAX_CROSSINGS), 0 where a crossing does not exist."""
    out = np.zeros((members.N.size, MAX_CROSSINGS))
    for k, profile in enumerate(members.profiles):
        rows = np.flatnonzero(members.profile_of == k)
        if isinstance(profile, RectangularProfile):
            continue
        for c, level in enumerate((members.r_inner[rows], members.R_outer[rows])):
            if isinstance(profile, CircularProfile):
                lo, hi = _circular_crossings(members.w_n[rows], members.w_d[rows], level)
            else:
                lo, hi = _searched_crossings(members, rows, level)
            out[rows, 2 * c] = lo
            out[rows, 2 * c + 1] = hi
    return out


def _circular_crossings(w_n: Array, w_d: Array, level: Array) -> tuple[Array, Array]:
    """Eq. 13: ``h1 = (w_n + w_d)/2 - (w_n/2) sin(pi u) = level`` at ``u`` and ``1 - u``."""
    y = (w_n + w_d - 2.0 * level) / w_n
    inside = (y > 0.0) & (y < 1.0)
    u = np.arcsin(np.where(inside, y, 0.0)) / np.pi
    return np.where(inside, u, 0.0), np.where(inside, 1.0 - u, 0.0)


def _searched_crossings(members: Members, rows: IntArray, level: Array) -> tuple[Array, Array]:
    """First and last sign change of ``h1 - level`` on ``CROSSING_SAMPLES`` samples, bisected."""
    u = np.broadcast_to(np.linspace(0.0, 1.0, CROSSING_SAMPLES), (rows.size, CROSSING_SAMPLES))
    above = members.h1(rows, np.ascontiguousarray(u)) > level[:, None]
    change = above[:, 1:] != above[:, :-1]
    found = np.any(change, axis=1)
    first = np.argmax(change, axis=1)
    final = change.shape[1] - 1 - np.argmax(change[:, ::-1], axis=1)
    ends = []
    for k in (first, final):
        lo = u[0, k]
        hi = u[0, k + 1]
        lo_above = above[np.arange(rows.size), k]
        for _ in range(BISECTION_STEPS):
            mid = 0.5 * (lo + hi)
            mid_above = members.h1(rows, mid[:, None])[:, 0] > level
            same = mid_above == lo_above
            lo = np.where(same, mid, lo)
            hi = np.where(same, hi, mid)
        ends.append(np.where(found, 0.5 * (lo + hi), 0.0))
    lo_u, hi_u = ends
    return lo_u, np.where(hi_u > lo_u, hi_u, 0.0)


def _check_custom_profile(design: Design) -> None:
    """Raise :class:`InvalidDesignError` unless a user profile gives finite ``h1 > 0`` (m)."""
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


def _check_rigidity(members: Members) -> None:
    """Raise :class:`InvalidDesignError` unless every member's flexural rigidity ``E I``
    (N m^2) is at least the smallest normal double at ``PEAK_SAMPLES`` stations of a notch and
    in the tubes, so the compliance ``1/(E I)`` is finite (a backbone or wall thinner than
    floating point resolves)."""
    every = np.arange(members.N.size)
    u = np.broadcast_to(np.linspace(0.0, 1.0, PEAK_SAMPLES), (every.size, PEAK_SAMPLES))
    h1 = members.h1(every, np.ascontiguousarray(u))
    inertia = notched_moment(h1, members.R_outer[:, None], members.r_inner[:, None])
    rigidity = members.E[:, None] * np.concatenate([inertia, members.tube_moment[:, None]],
                                                   axis=1)
    floor = float(np.finfo(float).tiny)
    ok = np.all(rigidity >= floor, axis=1)
    if not np.all(ok):
        m = int(np.argmin(ok))
        design = members.designs[m]
        least = float(np.min(rigidity[m]))
        raise InvalidDesignError(
            f"E*I = {least:.3g} N m^2 (E = {design.E:g} Pa, w_d = {design.w_d:g} m, R_outer = "
            f"{design.R_outer:g} m, r_inner = {design.r_inner:g} m) is out of range; allowed: "
            f"[{floor:.3g}, inf) N m^2, so that 1/(E I) is finite",
            parameter="E*I", value=least, allowed=f"[{floor:.3g}, inf) N m^2")
