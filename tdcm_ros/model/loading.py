"""External loads, a tendon tension varying along ``s`` and notch contact for Algorithm 1.

A :class:`Loading` passed to :func:`tdcm_ros.model.solve` adds to the tendon's moment (eq. 11)
the moment of the external loads on the body beyond each cut, in frame ``tdcm_base``:

``m(s) = (p_c(s) - p(s)) x (-T(s) t_c(s)) + M_tip + (p(L) - p(s)) x F_tip
+ integral_s^L (p(xi) - p(s)) x f A(xi) dxi``

(N m about +y; ``(a x F)_y = a_z F_x - a_x F_z``; positive bends toward +x, the tendon side).

- **Tension profile.** ``T(s)`` comes from a :class:`TensionProfile` of the node arc lengths,
  the tendon's cumulative wrap angle from the base and the base tension; it is evaluated
  inside the fixed point because the wrap angle depends on the shape. The closed form stays
  exact with friction: the tendon beyond the cut is held by the tension at the cut, the anchor
  and the channel's normal and friction forces; the channel forces act between tendon and
  body, so for the tendon + distal body they cancel in pairs and the tendon's net action on the
  distal body is its cut force ``-T(s) t_c(s)`` at ``p_c(s)``. A tendon running free on a chord
  feels no channel force, so its tension is constant along the chord (the value just past the
  chord's proximal kink). At a kink the tension may jump; cell end moments are one-sided, so
  each side uses its own value (profile at the wrap angle before / after the kink).
- **Tip force and moment** act at the tip midline ``p(L)``.
- **Body force density** ``f`` (N/m^3, e.g. ``rho g``) acts on the section area ``A(s)``
  (:meth:`tdcm_ros.model.grid.Grid.areas_at`: every section type's own) at the cells' Gauss
  points, placed on each
  cell's mean-curvature arc (to 4th order in the cell's bend angle). Inside a cell the moment is linear between its end values, as for
  the tendon (the quadratic part of a distributed load is a discretisation error that
  shrinks with the cell length).
- **Notch contact** (:class:`NotchContact`): once a notch's bend angle passes its closure angle
  (:func:`tdcm_ros.model.limits.closure_angles`), the extra bend is resisted by
  ``stiffness_factor * E * I0`` instead of the notch's own compliance. The body's statics still
  use the actual moments; the notch's kinematics use them scaled by the per-notch factor
  ``(phi_c + rho (phi - phi_c)) / phi`` (``rho`` = notch compliance ratio closed/open).

Continuation (a solver fall-back) ramps the external loads with the tension.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import InputError, TdcmError, out_of_range
from tdcm_ros.model import loads
from tdcm_ros.model.errors import ModelError
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.limits import check_closure, check_singularity, closure_angles
from tdcm_ros.model.moment_model import PlainRun, Plan, own_moment
from tdcm_ros.model.quiet import quiet_fp
from tdcm_ros.model.settings import SolverSettings

Array = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

MAX_STIFFNESS_FACTOR = 1e6
#: Largest capstan friction coefficient tendon/channel.
MAX_MU = 10.0


class InvalidLoadingError(ModelError, InputError):
    """A :class:`Loading` field, or a tension profile's output, is invalid."""

    kind = "invalid_loading"


class TensionProfile(Protocol):
    """Tendon tension along the body (N).

    ``s``: node arc lengths (m, shape (n+1,)); ``wrap_angle``: cumulative absolute turning of
    the tendon from the base (rad, (n+1,)); ``tension_base``: tension at the base (N). Returns
    the tension at each node (N, (n+1,)), finite and >= 0.

    The solver calls it inside the fixed point, twice per iteration: first with the wrap angle
    just before each node's kink, then just after (a chord takes the value after its proximal
    kink). A successful solve's last call is the "after" call on the converged shape, so a
    stateful profile (e.g. stick-slip friction) can keep the result of its last call.
    """

    def __call__(self, s: Array, wrap_angle: Array, tension_base: float) -> Array: ...


@dataclass(frozen=True)
class Capstan:
    """Capstan friction ``T = T_base exp(-mu wrap)`` (pulling, tension lost toward the tip);
    with ``unloading=True`` the friction reverses: ``T = T_base exp(+mu wrap)``."""

    mu: float
    unloading: bool = False

    def __post_init__(self) -> None:
        if not _is_real(self.mu) or not 0.0 <= self.mu <= MAX_MU:
            raise out_of_range("mu", self.mu, f"[0, {MAX_MU:g}]", error=InvalidLoadingError)

    def __call__(self, s: Array, wrap_angle: Array, tension_base: float) -> Array:
        sign = 1.0 if self.unloading else -1.0
        return tension_base * np.exp(sign * self.mu * wrap_angle)


@dataclass(frozen=True)
class NotchContact:
    """Closed notches stiffen: past the closure angle a notch bends with
    ``stiffness_factor * E * I0`` (``I0`` the uncut tube's second moment)."""

    stiffness_factor: float = 1.0

    def __post_init__(self) -> None:
        value = self.stiffness_factor
        if not _is_real(value) or not 0.0 < value <= MAX_STIFFNESS_FACTOR:
            raise out_of_range("notch_contact.stiffness_factor", value,
                               f"(0, {MAX_STIFFNESS_FACTOR:g}] (finite)",
                               error=InvalidLoadingError)


@dataclass(frozen=True)
class Loading:
    """What acts on the body besides a constant tendon tension (SI units, frame ``tdcm_base``).

    - ``tension_profile``: tension along ``s``; None keeps the paper's constant tension.
    - ``tip_force``: ``(F_x, F_z)`` (N) at the tip midline.
    - ``tip_moment``: (N m) about +y.
    - ``body_force_density``: ``(f_x, f_z)`` (N/m^3), e.g. ``rho * g``, times the area ``A(s)``.
    - ``notch_contact``: None raises :class:`NotchClosureError` when a notch closes.
    """

    tension_profile: TensionProfile | None = None
    tip_force: tuple[float, float] = (0.0, 0.0)
    tip_moment: float = 0.0
    body_force_density: tuple[float, float] = (0.0, 0.0)
    notch_contact: NotchContact | None = None

    def __post_init__(self) -> None:
        if self.tension_profile is not None and not callable(self.tension_profile):
            raise InvalidLoadingError(
                f"tension_profile = {self.tension_profile!r} is not callable; allowed: None or "
                "f(s, wrap_angle, tension_base) -> tensions", parameter="tension_profile",
                value=self.tension_profile, allowed="None | callable")
        object.__setattr__(self, "tip_force", _pair("tip_force", self.tip_force, "N"))
        object.__setattr__(self, "body_force_density",
                           _pair("body_force_density", self.body_force_density, "N/m^3"))
        if not _is_real(self.tip_moment) or not math.isfinite(self.tip_moment):
            raise out_of_range("tip_moment", self.tip_moment, "finite N m",
                               error=InvalidLoadingError)
        object.__setattr__(self, "tip_moment", float(self.tip_moment))
        if self.notch_contact is not None and not isinstance(self.notch_contact, NotchContact):
            raise InvalidLoadingError(
                f"notch_contact = {self.notch_contact!r} is not a NotchContact; allowed: None or "
                "NotchContact(stiffness_factor)", parameter="notch_contact",
                value=self.notch_contact, allowed="None | NotchContact")

    @property
    def is_trivial(self) -> bool:
        """True when nothing differs from the paper's base model."""
        return (self.tension_profile is None and self.notch_contact is None
                and self.tip_force == (0.0, 0.0) and self.tip_moment == 0.0
                and self.body_force_density == (0.0, 0.0))

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description (the profile by its repr)."""
        return {"tension_profile": None if self.tension_profile is None
                else repr(self.tension_profile),
                "tip_force_n": list(self.tip_force), "tip_moment_nm": self.tip_moment,
                "body_force_density_n_m3": list(self.body_force_density),
                "notch_contact": None if self.notch_contact is None
                else {"stiffness_factor": self.notch_contact.stiffness_factor}}


def _is_real(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


def _pair(name: str, value: Any, unit: str) -> tuple[float, float]:
    allowed = f"two finite numbers (x, z) {unit}"
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)) or \
            len(value) != 2 or not all(_is_real(v) and math.isfinite(v) for v in value):
        raise out_of_range(name, value, allowed, error=InvalidLoadingError)
    return float(value[0]), float(value[1])


@dataclass(frozen=True, eq=False)
class _BodyCells:
    """Per-grid constants of the body force: per cell, the moments ``S_j = sum w A sigma^j``
    (m^(3+j)) of the ``A ds`` weights at the Gauss points about the cell start (``S_0`` is the
    cell's volume), and ``1 / length`` (1/m)."""

    moments: Array
    inverse_length: Array


@lru_cache(maxsize=64)
def _body_cells(grid: Grid) -> _BodyCells:
    span = (grid.u_b - grid.u_a)[:, None]
    u_q = grid.u_a[:, None] + span * grid.gauss_u[None, :]
    area = grid.areas_at(np.arange(grid.n_cells), u_q)
    weights = grid.w_q * area
    sigma = grid.s_q - grid.s_nodes[:-1, None]
    moments = np.stack([np.sum(weights * sigma**j, axis=1) for j in range(5)])
    return _BodyCells(moments=moments, inverse_length=1.0 / grid.length)


@dataclass(frozen=True, eq=False)
class _Contact:
    """Per-grid constants of notch contact: per notch (base to tip) the closure angle (rad)
    and the closed-to-open compliance ratio; the notch cells and their notch indices."""

    angle: Array
    ratio: Array
    cells: NDArray[np.int64]
    notch: NDArray[np.int64]


def _contact(grid: Grid, contact: NotchContact) -> _Contact:
    d = grid.design
    cells = np.flatnonzero(grid.is_notch)
    notch = grid.notch_index[cells]
    w_n = d.per_notch("w_n")
    if d.is_uniform:  # every notch alike: their mean, as computed before per-notch designs
        open_compliance = np.full(d.N, float(np.sum(grid.C0[cells] + grid.C1[cells])) / d.N)
    else:
        open_compliance = np.bincount(notch, grid.C0[cells] + grid.C1[cells], minlength=d.N)
    closed_compliance = w_n / (contact.stiffness_factor * d.E * d.tube_second_moment)
    ratio = closed_compliance / open_compliance
    if np.any(ratio > 1.0):
        least = float(np.max(w_n / (open_compliance * d.E * d.tube_second_moment)))
        raise out_of_range("notch_contact.stiffness_factor", contact.stiffness_factor,
                           f"[{least:.3g}, {MAX_STIFFNESS_FACTOR:g}] for this design (a closed "
                           "notch must not be softer than an open one)",
                           error=InvalidLoadingError)
    return _Contact(angle=closure_angles(grid), ratio=ratio, cells=cells, notch=notch)


class LoadedModel:
    """A :class:`Loading` on one grid: the moment map and the contact law for the solver (a
    :class:`~tdcm_ros.model.moment_model.MomentModel`).

    Its moments are known only on a solution, so the singularity is checked after iterating;
    closure raises unless notch contact is on. Strategies: plain iteration (cheapest for small
    loads) hands over to Anderson restarted from the initial iterate as soon as it slows,
    within a quarter of ``max_iter``; continuation (adaptive steps, external loads ramped with
    the tension) comes next and relaxation last, which on a scan of hard loadings rescued more
    solves than the paper model's order.
    """

    @quiet_fp
    def __init__(self, grid: Grid, loading: Loading, tension_base: float) -> None:
        self.grid = grid
        self.loading = loading
        self.tension_base = tension_base
        fx, fz = loading.tip_force
        self._tip = complex(fz, fx)
        bx, bz = loading.body_force_density
        self._body = complex(bz, bx)
        self._body_cells = _body_cells(grid) if self._body != 0 else None
        self._contact = (None if loading.notch_contact is None
                         else _contact(grid, loading.notch_contact))
        self._chord_tensions: tuple[float, Array] | None = None

    @property
    def has_contact(self) -> bool:
        """Whether the notch contact law is active."""
        return self._contact is not None

    def check_before(self, tension: float) -> None:
        """Nothing is known before iterating."""

    @quiet_fp
    def check_after(self, x: Array, shape: PlanarShape, tension: float,
                    min_gap: float | None = None) -> None:
        """Singularity on the bending moments; closure unless notch contact is on."""
        n = self.grid.n_cells
        bend = self.bend_moments(x)
        check_singularity(self.grid, bend[:n], bend[n:])
        if self._contact is None:
            check_closure(self.grid, shape, tension)

    def plans(self, settings: SolverSettings) -> list[Plan]:
        """Strategies in order (see the class docstring)."""
        budget = settings.max_iter
        if settings.acceleration != "auto":
            mode = "picard" if settings.acceleration == "none" else settings.acceleration
            return [Plan(settings.acceleration, mode, budget)]
        plans = [Plan("picard+anderson", "auto", max(budget // 4, 1), restart=True)]
        if settings.continuation_steps > 0:
            plans.append(Plan("continuation", "continuation", budget, adaptive=True))
        return [*plans, Plan("relaxation", "relaxation", budget)]

    def warm_scale(self, previous: float, tension: float) -> float | None:
        """The tension ratio; unscaled from a zero-tension result (external loads alone)."""
        return tension / previous if previous > 0.0 else 1.0

    @quiet_fp
    def extras(self, x: Array, shape: PlanarShape, tension: float
               ) -> tuple[Array | None, Array | None]:
        """Per-cell contact scale (with contact) and node tensions (with a profile)."""
        scale = self.contact_scale(x) if self._contact is not None else None
        tensions = (self.node_tensions(shape, tension)[1]
                    if self.loading.tension_profile is not None else None)
        return scale, tensions

    def plain(self, x: Array, level: float, budget: int, tol: float, relaxation: float,
              slow: float) -> PlainRun | None:
        """Not compiled: the solver iterates the moment map itself."""
        return None

    def contact_scale(self, x: Array) -> Array:
        """Per-cell factor (<= 1) from actual to bending moments; ones without contact."""
        n = self.grid.n_cells
        scale = np.ones(n)
        contact = self._contact
        if contact is None or not np.any(np.isfinite(contact.angle)):
            return scale
        cells = contact.cells
        cell_angle = x[cells] * self.grid.C0[cells] + x[n + cells] * self.grid.C1[cells]
        angle = np.abs(np.bincount(contact.notch, cell_angle, minlength=self.grid.design.N))
        closed = angle > contact.angle
        factor = np.ones_like(angle)
        stop = contact.angle[closed]
        factor[closed] = (stop + contact.ratio[closed] * (angle[closed] - stop)) / angle[closed]
        scale[cells] = factor[contact.notch]
        return scale

    def chord_tension(self, level: float) -> float | Array:
        """Tension (N) on the chords for the shape integration's chord terms (the moment on a
        chord, external loads included, bows as ``m'' = -T c m``; the loads' own curvature of
        their moment is carried by no cell, as on the rest of the body). Under a tension
        profile the chord tensions depend on the shape: those of the last shape whose moments
        were taken at this ``level``, per cell (the base tension before any)."""
        last = self._chord_tensions
        if self.loading.tension_profile is None or last is None or last[0] != level:
            return level
        return last[1]

    def axis_tension(self, level: float) -> float | Array:
        """Tension (N) pulling on each cell: the chord tension (one tendon)."""
        return self.chord_tension(level)

    def start(self, level: float) -> Array:
        """The tendon's own moment ``R_c T`` (N m) everywhere at tension ``level`` (N)."""
        return own_moment(self.grid, level)

    def bend_moments(self, x: Array) -> Array:
        """Moments (N m) that set the curvature: ``x`` with contact scaling applied."""
        if self._contact is None:
            return x
        scale = self.contact_scale(x)
        return x * np.concatenate([scale, scale])

    def node_tensions(self, shape: PlanarShape, level: float) -> tuple[Array, Array]:
        """Tendon tension (N) just before and just after every node's kink."""
        profile = self.loading.tension_profile
        s = self.grid.s_nodes
        if profile is None:
            constant = np.full(s.shape, level)
            return constant, constant
        before, after = loads.tendon_wrap(self.grid, shape)
        return (_evaluate(profile, s, before, level), _evaluate(profile, s, after, level))

    def cell_tensions(self, shape: PlanarShape, level: float) -> tuple[Array, Array]:
        """Tension (N) at each cell's start and end; one value per chord."""
        grid = self.grid
        before, after = self.node_tensions(shape, level)
        t_a = after[:-1].copy()
        t_b = before[1:].copy()
        cells = grid.chord_cells
        t_a[cells] = after[grid.chord_start_node[cells]]
        t_b[cells] = t_a[cells]
        return t_a, t_b

    def moments(self, shape: PlanarShape, x: Array, level: float, factor: float) -> Array:
        """New cell end moments ``[m_a, m_b]`` (N m) for the current shape; the tension is
        ``level`` (N) and the external loads are scaled by ``factor`` (continuation)."""
        grid = self.grid
        if self.loading.tension_profile is None:
            m_a, m_b = loads.closed_form(grid, shape, np.float64(level))
        else:
            t_a, t_b = self.cell_tensions(shape, level)
            self._chord_tensions = (level, t_a)
            m_a, m_b = loads.closed_form_cells(grid, shape, t_a, t_b)
        external = self._external(shape, factor)
        if external is not None:
            m_a = m_a + external[:-1]
            m_b = m_b + external[1:]
        return np.concatenate([m_a, m_b])

    def _external(self, shape: PlanarShape, factor: float) -> Array | None:
        """Moment (N m) of the external loads beyond each node, or None without any."""
        tip, moment, body = self._tip, self.loading.tip_moment, self._body
        if tip == 0 and moment == 0.0 and body == 0:
            return None
        p = shape.p
        out = np.full(p.shape, factor * moment)
        if tip != 0:
            out += factor * (np.conj(p[-1] - p) * tip).imag
        cells = self._body_cells
        if cells is not None:
            # Each cell's first moment of A ds about its start, its points placed on the
            # cell's mean-curvature arc: along = sin(k s)/k, across = (1 - cos(k s))/k,
            # to 4th order in the cell's bend angle k s.
            s0, s1, s2, s3, s4 = cells.moments
            k = np.diff(shape.theta) * cells.inverse_length
            k2 = k * k
            local = (s1 - k2 * s3 / 6.0) + 1j * k * (0.5 * s2 - k2 * s4 / 24.0)
            first = s0 * p[:-1] + shape.tangent[:-1] * local
            beyond_first = np.zeros_like(p)
            beyond_first[:-1] = np.cumsum(first[::-1])[::-1]
            beyond_volume = np.zeros(p.shape)
            beyond_volume[:-1] = np.cumsum(s0[::-1])[::-1]
            out += factor * (np.conj(beyond_first - beyond_volume * p) * body).imag
        return out


def _evaluate(profile: TensionProfile, s: Array, wrap: Array, level: float) -> Array:
    """Call a tension profile and check its output (InvalidLoadingError otherwise)."""
    allowed = "finite tensions >= 0 N, one per node"
    try:
        values = np.asarray(profile(s.copy(), wrap, float(level)), dtype=float)
    except TdcmError:
        raise
    except Exception as exc:  # a user callable may raise anything: report it as bad input
        raise InvalidLoadingError(f"tension_profile raised {exc!r}", parameter="tension_profile",
                                  value=None, allowed=allowed) from exc
    if values.shape != s.shape:
        raise InvalidLoadingError(
            f"tension_profile returned shape {values.shape}, expected {s.shape}; allowed: "
            f"{allowed}", parameter="tension_profile", value=values.shape, allowed=allowed)
    bad = ~(np.isfinite(values) & (values >= 0.0))
    if np.any(bad):
        k = int(np.argmax(bad))
        raise InvalidLoadingError(
            f"tension_profile = {values[k]!r} N at s = {s[k] * 1e3:.3f} mm is out of range; "
            f"allowed: {allowed}", parameter="tension_profile", value=float(values[k]),
            allowed=allowed)
    return values
