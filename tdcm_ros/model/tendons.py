"""Several tendons: where each one runs, and its layout on a grid (SI units).

A :class:`Tendon` runs at a signed ``offset`` from the tube axis in the bending plane (m; + on
the +x side, - on the -x side), follows the body in the notches (``paper`` routing: straight
chords across the tubes) or in the tubes (``free``: chords across the notches), and ends at
``anchor`` (m from the base; a segment boundary, the tip by default). ``guides`` says where
it runs: ``internal`` (through the wall: ``0 < |offset| < R_outer``) or ``external`` (through
guides outside the backbone, such as the disks of a disk-routed robot: any ``|offset|``).

The body's moment is the sum of the tendons' (each tendon's equilibrium beyond a cut gives
its moment there, :mod:`tdcm_ros.model.loads`; zero past its anchor). A design without a
tendon list has the paper's one tendon at ``R_c`` on +x, under the solver's routing, to the tip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.settings import ROUTINGS

GUIDES = ("internal", "external")
#: Farthest offset (m) of a tendon in external guides.
MAX_EXTERNAL_OFFSET_M = 0.5
#: How close (m) an anchor must be to a segment boundary.
ANCHOR_SLACK_M = 1e-9
#: Most tendons a design may have.
MAX_TENDONS = 16

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]


#: Largest tendon stiffness (N/m) and slack (m) a tendon may be given.
MAX_STIFFNESS_N_PER_M = 1e12
MAX_SLACK_M = 1.0


@dataclass(frozen=True)
class Tendon:
    """One tendon: its signed ``offset`` (m, + toward +x), ``routing`` (``paper`` | ``free``;
    None: the solver's), ``anchor`` (m from the base, at a segment boundary; None: the tip),
    ``guides`` (``internal`` | ``external``), ``name`` (its joint and topic name), and for its
    actuator's stroke its own axial ``stiffness`` (N/m, actuator to anchor; None: inextensible)
    and ``slack`` (m the actuator takes up before the tendon pulls)."""

    offset: float
    routing: str | None = None
    anchor: float | None = None
    guides: str = "internal"
    name: str = ""
    stiffness: float | None = None
    slack: float = 0.0

    def actuator_stroke(self, stroke: float, tension: float) -> float:
        """The actuator's travel (m) for the tendon's path ``stroke`` (m) at ``tension`` (N):
        the slack taken up, the path, and the tendon's stretch ``T / stiffness``."""
        stretch = 0.0 if self.stiffness is None else tension / self.stiffness
        return self.slack + stroke + stretch


def is_paper_like(tendons: tuple[Tendon, ...]) -> bool:
    """Whether ``tendons`` pull as the paper's one tendon: none listed, or one on +x to the tip
    (its routing, guides, name, stiffness and slack change no moment)."""
    return not tendons or (len(tendons) == 1 and tendons[0].offset > 0.0
                           and tendons[0].anchor is None)


def check_tendons(tendons: tuple[Tendon, ...], r_outer: float, boundaries: Array
                  ) -> tuple[Tendon, ...]:
    """``tendons`` checked against a body of outer radius ``r_outer`` (m) whose segments end at
    ``boundaries`` (m, base to tip, the tip last), each named ``tendons[k]``, with default names
    ``tendon_1``, ``tendon_2``, ... filled in; raises :class:`InvalidDesignError`."""
    if not isinstance(tendons, tuple) or not 1 <= len(tendons) <= MAX_TENDONS:
        count = len(tendons) if isinstance(tendons, (tuple, list)) else tendons
        raise out_of_range("tendons", count, f"a tuple of 1 to {MAX_TENDONS} Tendon",
                           error=InvalidDesignError)
    out = []
    for k, tendon in enumerate(tendons):
        where = f"tendons[{k}]"
        if not isinstance(tendon, Tendon):
            raise out_of_range(where, tendon, "a Tendon", error=InvalidDesignError)
        if tendon.guides not in GUIDES:
            raise out_of_range(f"{where}.guides", tendon.guides, " | ".join(GUIDES),
                               error=InvalidDesignError)
        if tendon.routing is not None and tendon.routing not in ROUTINGS:
            raise out_of_range(f"{where}.routing", tendon.routing, " | ".join(ROUTINGS),
                               error=InvalidDesignError)
        offset = tendon.offset
        limit = r_outer if tendon.guides == "internal" else MAX_EXTERNAL_OFFSET_M
        if isinstance(offset, bool) or not isinstance(offset, (int, float)) or not (
                math.isfinite(offset) and 0.0 < abs(offset) < limit):
            inside = (f"R_outer = {r_outer:g} m (guides: internal, through the wall; "
                      "external guides allow more)") if tendon.guides == "internal" else \
                f"{MAX_EXTERNAL_OFFSET_M:g} m (guides: external)"
            raise out_of_range(f"{where}.offset", offset, f"0 < |offset| < {inside}",
                               unit="m", error=InvalidDesignError)
        anchor = tendon.anchor
        if anchor is not None:
            nearest = boundaries[int(np.argmin(np.abs(boundaries - anchor)))] if isinstance(
                anchor, (int, float)) and math.isfinite(anchor) else math.nan
            if isinstance(anchor, bool) or not abs(nearest - anchor) <= ANCHOR_SLACK_M:
                shown = ", ".join(f"{b:.6g}" for b in boundaries[:12])
                raise out_of_range(f"{where}.anchor", anchor, "a segment boundary after the "
                                   f"base, m ({shown}{', ...' if boundaries.size > 12 else ''})",
                                   error=InvalidDesignError)
            anchor = float(nearest)
        stiffness = tendon.stiffness
        if stiffness is not None and (isinstance(stiffness, bool) or not isinstance(
                stiffness, (int, float)) or not 0.0 < stiffness <= MAX_STIFFNESS_N_PER_M):
            raise out_of_range(f"{where}.stiffness", stiffness, f"(0, {MAX_STIFFNESS_N_PER_M:g}]"
                               " N/m, or None (inextensible)", error=InvalidDesignError)
        slack = tendon.slack
        if isinstance(slack, bool) or not isinstance(slack, (int, float)) or \
                not 0.0 <= slack <= MAX_SLACK_M:
            raise out_of_range(f"{where}.slack", slack, f"[0, {MAX_SLACK_M:g}] m",
                               error=InvalidDesignError)
        out.append(Tendon(float(offset), tendon.routing, anchor, tendon.guides,
                          tendon.name or f"tendon_{k + 1}",
                          None if stiffness is None else float(stiffness), float(slack)))
    names = [t.name for t in out]
    if len(set(names)) != len(names):
        raise out_of_range("tendons[].name", names, "distinct names", error=InvalidDesignError)
    return tuple(out)


def require_paper_tendon(tendons: tuple[Tendon, ...], what: str,
                         parameter: str = "design.tendons") -> None:
    """Raise :class:`InvalidDesignError` if a design lists ``tendons`` that do not pull as the
    paper's one (:func:`.is_paper_like`), which ``what`` does not take yet (say so, naming
    ``parameter``)."""
    if not is_paper_like(tendons):
        raise InvalidDesignError(
            f"{parameter}: {what} takes the paper's one tendon (on +x, to the tip); this design "
            f"lists {len(tendons)} tendon(s) that do not; allowed: one tendon on +x to the tip "
            "(solve() and tdcm solve take any tendon list)", parameter=parameter, value=len(tendons),
            allowed="the paper's one tendon")


@dataclass(frozen=True, eq=False)
class TendonLayout:
    """The tendons of a design on a grid of ``n`` cells: ``offsets`` (J,) m, ``follows``
    (J, n) whether tendon ``j`` follows the body in each cell (else it crosses it as a chord),
    ``anchors`` (J,) each tendon's anchor node (its cells are ``[0, anchor)``), ``names``; per
    tendon the cells it follows before its anchor (``follow_cells``), their arc length
    (``follow_lengths``, m) and the start and end node of each chord it crosses, base to tip
    (``chord_nodes``, (2, chords))."""

    offsets: Array
    follows: NDArray[np.bool_]
    anchors: IntArray
    names: tuple[str, ...]
    follow_cells: tuple[IntArray, ...]
    follow_lengths: tuple[float, ...]
    chord_nodes: tuple[IntArray, ...]

    @property
    def count(self) -> int:
        """Number of tendons."""
        return int(self.offsets.size)

    def active(self) -> NDArray[np.bool_]:
        """(J, n): whether tendon ``j`` pulls on each cell (before its anchor)."""
        cells = np.arange(self.follows.shape[1])
        return cells[None, :] < self.anchors[:, None]

    def cell_tensions(self, tensions: Array) -> tuple[Array, Array, Array]:
        """For base tensions ``tensions`` (J,) N: each tendon's tension per cell (J, n; 0 past
        its anchor), the chord tension per cell (n,: of the tendons crossing it as a chord)
        and the axial tension per cell (n,: of every tendon pulling on it)."""
        per = tensions[:, None] * self.active()
        return per, np.sum(per * ~self.follows, axis=0), np.sum(per, axis=0)


def tendon_layout(tendons: tuple[Tendon, ...], routing: str, is_notch: NDArray[np.bool_],
                  s_nodes: Array, chord_start_node: IntArray, chord_end_node: IntArray
                  ) -> TendonLayout:
    """The :class:`TendonLayout` of ``tendons`` on a grid's cells (``is_notch``, nodes
    ``s_nodes`` m, each cell's chord's start and end node), a tendon without its own routing
    taking ``routing``."""
    n = is_notch.size
    follows = np.stack([is_notch == ((t.routing or routing) == "paper") for t in tendons])
    anchors = np.array([n if t.anchor is None else int(np.argmin(np.abs(s_nodes - t.anchor)))
                        for t in tendons], np.int64)
    cells = np.arange(n)
    lengths = np.diff(s_nodes)
    follow_cells, follow_lengths, chord_nodes = [], [], []
    for j in range(len(tendons)):
        active = cells < anchors[j]
        along = np.flatnonzero(follows[j] & active)
        follow_cells.append(along)
        follow_lengths.append(float(np.sum(lengths[along])))
        chord = ~follows[j] & active
        starts, ends = chord_start_node[chord], chord_end_node[chord]
        first = np.ones(starts.size, dtype=bool)  # a chord's cells share its two nodes
        first[1:] = (starts[1:] != starts[:-1]) | (ends[1:] != ends[:-1])
        chord_nodes.append(np.stack([starts[first], ends[first]]))
    return TendonLayout(offsets=np.array([t.offset for t in tendons]), follows=follows,
                        anchors=anchors, names=tuple(t.name for t in tendons),
                        follow_cells=tuple(follow_cells), follow_lengths=tuple(follow_lengths),
                        chord_nodes=tuple(chord_nodes))


def grid_routing(tendons: tuple[Tendon, ...], routing: str) -> str:
    """The routing a grid is built for, for ``tendons`` under the solver's ``routing``: the
    tendons' one routing, or ``paper+free`` / ``free+paper`` (the first tendon's first) where
    they differ: then every cell carries the chord terms."""
    used = [t.routing or routing for t in tendons]
    first = used[0]
    return first if all(r == first for r in used) else f"{first}+{'free' if first == 'paper' else 'paper'}"
