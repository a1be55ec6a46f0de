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

from tdcm_ros.model.compiled import grid_kernels
from tdcm_ros.model.design import Design, uniform_length
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.profiles import (
    PRISMATIC_PROFILES,
    CircularProfile,
    CustomProfile,
    NotchProfile,
    RectangularProfile,
    SlicedProfile,
)
from tdcm_ros.model.section import notched_moment
from tdcm_ros.model.sections import open_faces

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

PEAK_SAMPLES = 17
#: Most breakpoints inside one notch: where its section's edges ``w_o +- h1`` meet the tube's
#: walls ``+-r_inner``, ``+-R_outer``: two crossings (``u`` and about ``1 - u``) of each of the four
#: levels of ``h1`` (:func:`crossing_levels`), the last two absent for the paper's section.
MAX_CROSSINGS = 8
#: Samples of a custom profile searched for crossings, and bisection steps per crossing.
CROSSING_SAMPLES = 129
BISECTION_STEPS = 60
#: Narrowest piece of a notch in ``u`` that a crossing may cut off (see :func:`resolved`).
MIN_PIECE_U = 1e-6


@dataclass(frozen=True)
class Members:
    """Design parameters of every member (SI units): per member (shape (M,)) the tube, the
    material and the length; per *notch shape* (shape (S,): each member's distinct notches,
    ``(w_n, w_d, w_o, profile)`` in order of first appearance, so a uniform member has one and
    its row is the member's own) ``shape_member``, ``shape_w_n``, ``shape_w_d``, ``shape_w_o``,
    ``profile_of`` (the
    index of its profile in ``profiles``); per member and segment
    *kind* (shape (M, K): the member's base tube, each of its notch shapes, each distinct tube
    between notches, its tip tube, then zero-length padding) ``kind_length``,
    ``kind_is_notch`` and ``kind_shape`` (the notch shape of a notch kind, the member's first
    shape for a tube); per member and slot (shape (M, 2 max N + 1): the base, then notch ``i``
    and the tube after it) ``slot_kind``; per member and notch (M, max N) ``notch_left`` and
    ``notch_right`` (m, padded with the member's length). A uniform member has the kinds BASE,
    NOTCH, TUBE and TIP."""

    designs: tuple[Design, ...]
    profiles: tuple[NotchProfile, ...]
    N: IntArray
    w_base: Array
    w_tip: Array
    R_outer: Array
    r_inner: Array
    R_c: Array
    E: Array
    tube_moment: Array
    length: Array
    shape_member: IntArray
    shape_first: IntArray
    shape_w_n: Array
    shape_w_d: Array
    shape_w_o: Array
    profile_of: IntArray
    kind_length: Array
    kind_is_notch: BoolArray
    kind_shape: IntArray
    slot_kind: IntArray
    notch_left: Array
    notch_right: Array
    notch_open: IntArray
    shape_section: Array

    @property
    def is_tabulated(self) -> BoolArray:
        """Per notch shape: whether its section changes along it, given by slices
        (:class:`~tdcm_ros.model.profiles.SlicedProfile`)."""
        sliced = np.array([isinstance(p, SlicedProfile) for p in self.profiles], dtype=bool)
        return sliced[self.profile_of]

    def tabulated(self, shape: IntArray, u: Array) -> tuple[Array, Array, Array]:
        """``1/(E I)`` (1/(N m^2)), the centroid's offset ``x_bar`` (m) and the farthest
        fibre from it (m) at ``u`` in notch shapes of sliced sections, rows of ``u`` as in
        :meth:`h1`."""
        out = np.empty((3, *u.shape))
        kinds = self.profile_of[shape]
        for k in np.unique(kinds):
            rows = kinds == k
            profile = self.profiles[k]
            assert isinstance(profile, SlicedProfile)  # is_tabulated chose these shapes
            _, x_bar, inertia, low, high = profile.section_at(u[rows])
            modulus = per_row(self.E[self.shape_member[shape[rows]]], u[rows])
            out[:, rows] = (1.0 / (modulus * inertia), x_bar,
                            np.maximum(high - x_bar, x_bar - low))
        return out[0], out[1], out[2]

    @classmethod
    def of(cls, designs: Sequence[Design]) -> Members:
        """Collect and check ``designs`` (every profile finite and positive, ``E I`` finite)."""
        designs = tuple(designs)
        profiles = _ProfileIndex()

        def column(name: str) -> Array:
            return np.array([getattr(d, name) for d in designs], dtype=float)

        n = np.array([d.N for d in designs], np.int64)
        w_base, w_tip = column("w_base"), column("w_tip")
        r_outer, r_inner = column("R_outer"), column("r_inner")
        uniform = all(d.is_uniform for d in designs)
        layout = _uniform_layout(designs, n, w_base, w_tip, profiles) if uniform else \
            _general_layout(designs, n, profiles)
        notch_open = np.zeros((n.size, 2, int(n.max())), np.int64)
        if uniform:  # one notch shape per member: every notch opens alike
            faces = open_faces(layout["shape_w_d"], layout["shape_w_o"], r_outer).T
            notch_open[...] = faces[:, :, None] & (np.arange(notch_open.shape[2]) < n[:, None]
                                                   )[:, None, :]
        else:
            for m, design in enumerate(designs):
                notch_open[m, :, :design.N] = design.open_faces()
        kept = tuple(profiles.profiles)
        owner = layout["shape_member"]
        section = np.zeros((owner.size, 3))
        for row, (k, m) in enumerate(zip(layout["profile_of"], owner, strict=True)):
            if isinstance(kept[k], PRISMATIC_PROFILES):
                got = kept[k].section(float(r_outer[m]))
                section[row] = (got.second_moment, got.centroid_x,
                                max(got.fibre_tendon_side, got.fibre_far_side))
        members = cls(designs=designs, profiles=kept, N=n,
                      w_base=w_base, w_tip=w_tip, R_outer=r_outer, r_inner=r_inner,
                      R_c=column("R_c"), E=column("E"),
                      tube_moment=np.pi / 4.0 * (r_outer**4 - r_inner**4),
                      notch_open=notch_open, shape_section=section, **layout)
        custom = np.array([isinstance(p, CustomProfile) for p in kept], bool)
        for m in np.unique(owner[custom[layout["profile_of"]]]):
            _check_custom_profile(designs[m])
        _check_rigidity(members)
        return members

    def h1(self, shape: IntArray, u: Array) -> Array:
        """Backbone half-width (m) at ``u``; ``shape`` (n,) names the notch shape of each row of u."""
        return self._per_profile(shape, u, lambda p, x, w_n, w_d: p.h1(x, w_n, w_d))

    def sigma(self, shape: IntArray, u: Array) -> Array:
        """Local arc length in a notch (m) at ``u``, rows of ``u`` as in :meth:`h1`."""
        return self._per_profile(shape, u, lambda p, x, w_n, w_d: p.sigma(x, w_n))

    def _per_profile(self, shape: IntArray, u: Array, evaluate: ProfileFunction) -> Array:
        """``evaluate(profile, u, w_n, w_d)`` with each row's notch shape's profile and widths."""
        if len(self.profiles) == 1:
            return evaluate(self.profiles[0], u, per_row(self.shape_w_n[shape], u),
                            per_row(self.shape_w_d[shape], u))
        out = np.empty(u.shape)
        kinds = self.profile_of[shape]
        for k, profile in enumerate(self.profiles):
            rows = kinds == k
            if np.any(rows):
                u_k = u[rows]
                out[rows] = evaluate(profile, u_k, per_row(self.shape_w_n[shape[rows]], u_k),
                                     per_row(self.shape_w_d[shape[rows]], u_k))
        return out


class _ProfileIndex:
    """The distinct profiles met so far (equal ones once) and each one's index."""

    def __init__(self) -> None:
        self.profiles: list[NotchProfile] = []
        self._by_id: dict[int, int] = {}

    def index(self, profile: NotchProfile) -> int:
        """The index of ``profile`` (added if new)."""
        key = id(profile)
        if key not in self._by_id:
            same = next((k for k, p in enumerate(self.profiles) if p == profile), None)
            if same is None:
                same = len(self.profiles)
                self.profiles.append(profile)
            self._by_id[key] = same
        return self._by_id[key]


def _uniform_layout(designs: tuple[Design, ...], n: IntArray, w_base: Array, w_tip: Array,
                    profiles: _ProfileIndex) -> dict[str, Any]:
    """:class:`Members`' shape, kind and slot arrays and lengths (m) of uniform designs,
    vectorised: one notch shape per member, the kinds BASE, NOTCH, TUBE, TIP."""
    count = n.size
    w_n = np.array([d.w_n for d in designs], dtype=float)
    w_t = np.array([d.w_t for d in designs], dtype=float)
    every = np.arange(count)
    notch_i = np.arange(int(n.max()))
    left = w_base[:, None] + notch_i.astype(float)[None, :] * (w_n + w_t)[:, None]
    slots = 2 * notch_i.size + 1
    slot_kind = np.empty((count, slots), np.int64)
    slot_kind[:, 0] = BASE
    slot_kind[:, 1::2] = NOTCH
    slot_kind[:, 2::2] = np.where(notch_i[None, :] == (n - 1)[:, None], TIP, TUBE)
    return {"shape_member": every, "shape_first": every, "shape_w_n": w_n,
            "shape_w_d": np.array([d.w_d for d in designs], dtype=float),
            "shape_w_o": np.array([d.w_o for d in designs], dtype=float),
            "profile_of": np.array([profiles.index(d.uniform_profile()) for d in designs],
                                   np.int64),
            "kind_length": np.stack([w_base, w_n, np.where(n > 1, w_t, 0.0), w_tip], axis=1),
            "kind_is_notch": np.broadcast_to(np.arange(4) == NOTCH, (count, 4)),
            "kind_shape": np.repeat(every[:, None], 4, axis=1), "slot_kind": slot_kind,
            "notch_left": left, "notch_right": left + w_n[:, None],
            "length": uniform_length(w_base, n, w_n, w_t, w_tip)}


def _general_layout(designs: tuple[Design, ...], n: IntArray, profiles: _ProfileIndex
                    ) -> dict[str, Any]:
    """:class:`Members`' shape, kind and slot arrays and lengths (m) of any designs (see
    :class:`Members`)."""
    count, n_max = n.size, int(n.max())
    shapes: list[tuple[int, float, float, float, int]] = []
    kinds: list[list[tuple[float, bool, int]]] = []
    slot_kind = np.zeros((count, 2 * n_max + 1), np.int64)
    left_all = np.empty((count, n_max))
    right_all = np.empty((count, n_max))
    first = np.empty(count, np.int64)
    for m, design in enumerate(designs):
        first[m] = len(shapes)
        pairs = list(zip(design.per_notch("w_n").tolist(), design.per_notch("w_d").tolist(),
                         design.per_notch("w_o").tolist(),
                         (profiles.index(p) for p in design.notch_profiles()), strict=True))
        distinct = list(dict.fromkeys(pairs))
        shapes += [(m, *notch) for notch in distinct]
        gaps = design.per_notch("w_t").tolist()
        distinct_gaps = list(dict.fromkeys(g for g in gaps if g > 0.0))
        own: list[tuple[float, bool, int]] = [(design.w_base, False, int(first[m]))]
        own += [(w_n, True, int(first[m]) + k) for k, (w_n, *_) in enumerate(distinct)]
        own += [(g, False, int(first[m])) for g in distinct_gaps]
        own.append((design.w_tip, False, int(first[m])))
        tip_kind = len(own) - 1
        zero_kind = len(own)
        own.append((0.0, False, int(first[m])))
        kinds.append(own)
        slot_kind[m, 1::2] = zero_kind
        slot_kind[m, 2::2] = zero_kind
        for i, pair in enumerate(pairs):
            slot_kind[m, 2 * i + 1] = 1 + distinct.index(pair)
            after = tip_kind if i == design.N - 1 else (
                1 + len(distinct) + distinct_gaps.index(gaps[i]) if gaps[i] > 0.0 else zero_kind)
            slot_kind[m, 2 * i + 2] = after
        left, right = design.notch_bounds()
        left_all[m] = np.concatenate([left, np.full(n_max - left.size, design.length)])
        right_all[m] = np.concatenate([right, np.full(n_max - right.size, design.length)])
    k_max = max(len(k) for k in kinds)
    padded = [k + [k[-1]] * (k_max - len(k)) for k in kinds]
    return {"shape_member": np.array([s[0] for s in shapes], np.int64), "shape_first": first,
            "shape_w_n": np.array([s[1] for s in shapes], dtype=float),
            "shape_w_d": np.array([s[2] for s in shapes], dtype=float),
            "shape_w_o": np.array([s[3] for s in shapes], dtype=float),
            "profile_of": np.array([s[4] for s in shapes], np.int64),
            "kind_length": np.array([[k[0] for k in row] for row in padded], dtype=float),
            "kind_is_notch": np.array([[k[1] for k in row] for row in padded], dtype=bool),
            "kind_shape": np.array([[k[2] for k in row] for row in padded], np.int64),
            "slot_kind": slot_kind, "notch_left": left_all, "notch_right": right_all,
            "length": np.array([d.length for d in designs], dtype=float)}


def per_row(values: NDArray[Any], u: Array) -> NDArray[Any]:
    """``values`` shaped to broadcast against ``u``: as is if they share u's shape (one value
    per element), else one value per row of u's first axis."""
    if values.shape == u.shape:
        return values
    return values.reshape((-1,) + (1,) * (u.ndim - 1))


ProfileFunction = Callable[[NotchProfile, Array, Array, Array], Array]


#: Segment kinds of a uniform member: every notch of it is the same, and so is every tube
#: between notches, so each member's cells are computed once per kind and copied along the body.
BASE, NOTCH, TUBE, TIP = range(4)


@dataclass(frozen=True)
class Prototypes:
    """The cells of each member's segment kinds (:class:`Members`), flat, in the segment's own
    coordinates.

    Per prototype cell (shape (p,)): ``member``, ``shape`` (its notch shape, the member's first
    for a tube: the row of the compliance kernel's parameters), ``is_notch``, ``u_a``/``u_b``
    (its ends in ``u``), ``a``/``length`` (its start from the segment start and its length, m),
    ``seg_length`` (m) and ``chord`` (the tendon crosses it as a chord); ``seg_start`` is 0.
    ``first`` (M, K) is each kind's first prototype cell and ``count`` (M, K) its cell count
    (0 for an absent segment).
    """

    members: Members
    member: IntArray
    shape: IntArray
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
    ``shape`` (its notch shape counted within the member, 0 in tubes), ``is_notch``,
    ``notch_index`` (-1 in tubes), ``seg_start``/``seg_length`` of its segment (m),
    ``u_a``/``u_b``, ``a`` (its start along s, m), ``constrained`` (the tendon follows the body
    there) and ``chord_start_node``/``chord_end_node`` (its segment's end nodes, counted within
    the member). Per member (shape (M,)): ``count`` cells from flat index ``first``;
    ``notch_left_node``/``notch_right_node`` (M, max N), padded with the member's tip node.
    """

    prototypes: Prototypes
    member: IntArray
    prototype: IntArray
    shape: IntArray
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
    """Cut each member's segment kinds into cells (see the module docstring)."""
    m_count, k_count = members.kind_length.shape
    is_notch_kind = members.kind_is_notch
    per_kind = np.where(is_notch_kind, cells_per_notch, cells_per_tube)
    seg_length = members.kind_length
    present = seg_length > 0.0
    inner = resolved(crossings(members)) if kind == "adaptive" else np.zeros(
        (members.shape_member.size, 0))
    pieces = inner.shape[1] + 1
    breaks = np.zeros((m_count, k_count, pieces + 1))
    breaks[..., -1] = 1.0
    notch_kind = np.nonzero(is_notch_kind)
    breaks[notch_kind[0], notch_kind[1], 1:-1] = np.sort(inner[members.kind_shape[notch_kind]],
                                                         axis=1)
    width = np.diff(breaks, axis=-1)
    counts = np.where(width > 0.0, np.maximum(1, np.rint(per_kind[..., None] * width)), 0)
    counts = (counts * present[..., None]).astype(np.int64)

    flat_counts = counts.ravel()
    piece = np.repeat(np.arange(flat_counts.size), flat_counts)
    member = piece // (k_count * pieces)
    seg_kind = (piece // pieces) % k_count
    j = (np.arange(piece.size) - (np.cumsum(flat_counts) - flat_counts)[piece]).astype(float)
    n_piece = flat_counts[piece]
    step = 1.0 / n_piece
    u0 = breaks[..., :-1].ravel()[piece]
    u1 = breaks[..., 1:].ravel()[piece]
    u_a = u0 + (u1 - u0) * (j * step)
    u_b = np.where(j + 1.0 == n_piece, u1, u0 + (u1 - u0) * ((j + 1.0) * step))
    is_notch = is_notch_kind[member, seg_kind]
    shape = members.kind_shape[member, seg_kind]
    length_of_segment = seg_length[member, seg_kind]
    a = np.where(is_notch, members.sigma(shape, u_a), length_of_segment * u_a)
    b = np.where(is_notch, members.sigma(shape, u_b), length_of_segment * u_b)
    b = np.where(u_b == 1.0, length_of_segment, b)
    kind_counts = counts.sum(axis=-1)
    return Prototypes(members=members, member=member, shape=shape, is_notch=is_notch,
                      chord=(is_notch != _tendon_follows_notches(routing)) | ("+" in routing),
                      u_a=u_a, u_b=u_b, a=a,
                      length=b - a, seg_length=length_of_segment, seg_start=np.zeros(a.size),
                      first=(np.cumsum(kind_counts.ravel()) - kind_counts.ravel()
                             ).reshape(m_count, k_count),
                      count=kind_counts)


def cell_table(proto: Prototypes, routing: str) -> CellTable:
    """Lay every member's segments end to end, each a copy of its kind's prototype cells (the
    compiled :func:`~tdcm_ros.model.grid_kernel.lay_cells`)."""
    members = proto.members
    m_count = members.N.size
    n_max = int(members.N.max())
    slots = 2 * n_max + 1  # base, then (notch i, tube after notch i) for every i
    notch_i = np.arange(n_max)
    has = notch_i[None, :] < members.N[:, None]
    start = np.empty((m_count, slots))
    start[:, 0] = 0.0
    start[:, 1::2] = members.notch_left
    start[:, 2::2] = members.notch_right
    slot_kind = members.slot_kind
    seg_counts = proto.count[np.arange(m_count)[:, None], slot_kind]
    seg_counts[:, 1:] *= np.repeat(has, 2, axis=1)
    count = seg_counts.sum(axis=1)
    total = int(count.sum())
    ints = np.empty((6, total), np.int64)
    floats = np.empty((5, total))
    flags = np.empty((2, total), bool)
    grid_kernels().lay_cells(seg_counts, slot_kind, proto.first, members.kind_is_notch, start,
                             members.shape_first, proto.shape, proto.a, proto.seg_length,
                             proto.u_a, proto.u_b, _tendon_follows_notches(routing), ints,
                             floats, flags)
    seg_first = np.cumsum(seg_counts, axis=1) - seg_counts
    tip = count[:, None]
    member, prototype, shape, notch_index, chord_start, chord_end = ints
    seg_start, seg_length, u_a, u_b, a = floats
    return CellTable(
        prototypes=proto, member=member, prototype=prototype, shape=shape, count=count,
        first=np.cumsum(count) - count, is_notch=flags[0], notch_index=notch_index,
        seg_start=seg_start, seg_length=seg_length, u_a=u_a, u_b=u_b, a=a,
        constrained=flags[1], chord_start_node=chord_start, chord_end_node=chord_end,
        notch_left_node=np.where(has, seg_first[:, 1::2], tip),
        notch_right_node=np.where(has, seg_first[:, 1::2] + seg_counts[:, 1::2], tip))


def _tendon_follows_notches(routing: str) -> bool:
    """Whether the (first) tendon follows the body in notches (``paper``) or in tubes
    (``free``); ``paper+free`` and ``free+paper`` (tendons of both routings, every cell with
    the chord terms: :func:`tdcm_ros.model.tendons.grid_routing`) as their first."""
    return routing.split("+")[0] == "paper"


def crossing_levels(members: Members) -> Array:
    """The values of ``h1`` (m) at which an edge ``w_o +- h1`` of each notch shape's section
    meets a wall ``+-r_inner`` or ``+-R_outer``, shape (S, 4): ``|r_inner - |w_o||``,
    ``R_outer - |w_o|``, then ``r_inner + |w_o|``, ``R_outer + |w_o|`` (0, none, where
    ``w_o = 0``: both edges meet the walls at the first two)."""
    owner = members.shape_member
    offset = np.abs(members.shape_w_o)
    r_inner, r_outer = members.r_inner[owner], members.R_outer[owner]
    centred = offset == 0.0
    return np.stack([np.abs(r_inner - offset), r_outer - offset,
                     np.where(centred, 0.0, r_inner + offset),
                     np.where(centred, 0.0, r_outer + offset)], axis=1)


def crossings(members: Members) -> Array:
    """Where each notch shape's profile meets its :func:`crossing_levels`, as ``u`` in (0, 1),
    and the inner bounds of the slabs of a sliced section (where its section's derivatives
    jump); shape (S, max(MAX_CROSSINGS, most slab bounds)), 0 where none."""
    slab_bounds = [p.breaks() if isinstance(p, SlicedProfile) else np.zeros(0)
                   for p in members.profiles]
    out = np.zeros((members.shape_member.size,
                    max(MAX_CROSSINGS, *(b.size for b in slab_bounds))))
    levels = crossing_levels(members)
    shape_profile = members.profile_of
    for k, profile in enumerate(members.profiles):
        rows = np.flatnonzero(shape_profile == k)
        if isinstance(profile, SlicedProfile):
            out[rows, :slab_bounds[k].size] = slab_bounds[k]
            continue
        if isinstance(profile, (RectangularProfile, *PRISMATIC_PROFILES)):
            continue  # h1 is constant along the notch: it crosses no level
        for c in range(levels.shape[1]):
            level = levels[rows, c]
            if not np.any(level > 0.0):
                continue
            if isinstance(profile, CircularProfile):
                lo, hi = _circular_crossings(members.shape_w_n[rows], members.shape_w_d[rows],
                                             level)
            else:
                lo, hi = _searched_crossings(members, rows, level)
            present = level > 0.0
            out[rows, 2 * c] = np.where(present, lo, 0.0)
            out[rows, 2 * c + 1] = np.where(present, hi, 0.0)
    return out


def resolved(found: Array) -> Array:
    """``found`` (:func:`crossings`) without the crossings no cell can resolve: one within
    ``MIN_PIECE_U`` of a notch end (its piece would have no length in s: ``h1`` meets the level
    at the notch's edge, a rounding error from it) and a pair closer than that to each other
    (the profile touches the level); 0 marks them absent."""
    out = np.where((found > MIN_PIECE_U) & (found < 1.0 - MIN_PIECE_U), found, 0.0)
    for first in range(0, MAX_CROSSINGS, 2):  # the pairs of each level
        lo, hi = out[:, first], out[:, first + 1]
        touching = (lo > 0.0) & (hi > 0.0) & (hi - lo < MIN_PIECE_U)
        out[touching, first:first + 2] = 0.0
    return out


def _circular_crossings(w_n: Array, w_d: Array, level: Array) -> tuple[Array, Array]:
    """Eq. 13: ``h1 = (w_n + w_d)/2 - (w_n/2) sin(pi u) = level`` at ``u`` and ``1 - u``."""
    y = (w_n + w_d - 2.0 * level) / w_n
    inside = (y > 0.0) & (y < 1.0)
    u = np.arcsin(np.where(inside, y, 0.0)) / np.pi
    return np.where(inside, u, 0.0), np.where(inside, 1.0 - u, 0.0)


def _searched_crossings(members: Members, rows: IntArray, level: Array) -> tuple[Array, Array]:
    """First and last sign change of ``h1 - level`` on ``CROSSING_SAMPLES`` samples, bisected;
    ``rows`` are notch shapes."""
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
    notches = zip(design.per_notch("w_n").tolist(), design.per_notch("w_d").tolist(),
                  design.notch_profiles(), strict=True)
    for w_n, w_d, profile in dict.fromkeys(notches):
        try:
            h1 = profile.h1(u, w_n, w_d)
        except Exception as exc:  # a user callable may raise anything: report it as bad input
            raise InvalidDesignError(f"h1(s) raised {exc!r}", parameter="h1(s)", value=None,
                                     allowed="a function of sigma in [0, w_n] m") from exc
        if h1.shape != u.shape or not np.all(np.isfinite(h1)) or np.any(h1 <= 0.0):
            bad = h1[~(np.isfinite(h1) & (h1 > 0.0))] if h1.shape == u.shape else h1
            raise InvalidDesignError(
                f"h1(s) must be finite and > 0 m across the notch, got {np.ravel(bad)[:3]!r}",
                parameter="h1(s)", value=np.ravel(bad)[:3].tolist(), allowed="(0, inf) m")


def _check_rigidity(members: Members) -> None:
    """Raise :class:`InvalidDesignError` unless every notch shape's flexural rigidity ``E I``
    (N m^2) is at least the smallest normal double at ``PEAK_SAMPLES`` stations of the notch
    and in the tubes, so the compliance ``1/(E I)`` is finite (a backbone or wall thinner than
    floating point resolves)."""
    every = np.arange(members.shape_member.size)
    owner = members.shape_member
    u = np.broadcast_to(np.linspace(0.0, 1.0, PEAK_SAMPLES), (every.size, PEAK_SAMPLES))
    h1 = members.h1(every, np.ascontiguousarray(u))
    inertia = notched_moment(h1, members.R_outer[owner, None], members.r_inner[owner, None])
    rigidity = members.E[owner, None] * np.concatenate(
        [inertia, members.tube_moment[owner, None]], axis=1)
    floor = float(np.finfo(float).tiny)
    ok = np.all(rigidity >= floor, axis=1)
    if not np.all(ok):
        shape = int(np.argmin(ok))
        design = members.designs[int(owner[shape])]
        least = float(np.min(rigidity[shape]))
        raise InvalidDesignError(
            f"E*I = {least:.3g} N m^2 (E = {design.E:g} Pa, w_d = "
            f"{members.shape_w_d[shape]:g} m, R_outer = "
            f"{design.R_outer:g} m, r_inner = {design.r_inner:g} m) is out of range; allowed: "
            f"[{floor:.3g}, inf) N m^2, so that 1/(E I) is finite",
            parameter="E*I", value=least, allowed=f"[{floor:.3g}, inf) N m^2")
