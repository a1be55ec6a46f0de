"""Classic Cosserat-rod boundary-value problem solved by shooting (scipy ``solve_ivp``).

State along ``s`` (m): ``y = (x, z, theta, n_x, n_z, m)`` -- midline position (m), tangent
angle (rad), internal force (N) and bending moment about +y (N m) that the distal part
exerts on the proximal one. Planar static Cosserat equations for an inextensible,
unshearable rod::

    x' = sin theta,  z' = cos theta,  theta' = m / (E I(s)),
    n' = -f,          m' = -(t x n)_y - l,

with the tendon loads of Rucker & Webster's **fully constrained tendon**: the tendon runs on
the offset curve ``p + R_c x_b`` over the whole length (``x_b = (cos theta, -sin theta)``).
Its tangent is then the body's, so the distributed load is ``f = T kappa x_b`` (N/m), applied
on a line through the midline's normal, ``l = 0``; the anchor at the tip gives the boundary
conditions ``n(L) = -T t(L)`` and ``m(L) = R_c T``. This differs from the package's ``paper``
routing (straight chords across tube segments) only in the tubes; the difference is a model
difference (tens of nm at 20 N on the presets), measured separately by the accuracy bench.

The base is clamped (``x = z = theta = 0``); the unknowns ``n(0)``, ``m(0)`` are found by
``scipy.optimize.root`` (hybrid Powell) on the tip conditions, started from the straight
body's loads ``n = (0, -T)``, ``m = R_c T`` (Algorithm 1's initial guess).

Two variants: ``whole`` integrates ``[0, L]`` in one ``solve_ivp`` call, so adaptive steps
cross the jumps of ``E I(s)`` at every ``l_i``, ``r_i`` (and may step over a narrow notch
entirely); ``segmented`` restarts the integrator at every ``l_i`` and ``r_i``.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from time import perf_counter
from typing import Literal, get_args

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp
from scipy.optimize import root

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.baselines.common import node_result, require_centred
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidSettingsError
from tdcm_ros.model.grid import Grid, build_grid
from tdcm_ros.model.limits import check_tendon_singularity, check_tension
from tdcm_ros.model.result import ConvergenceError, SolveResult
from tdcm_ros.model.section import notched_moment
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS

Array = NDArray[np.float64]
OdeMethod = Literal["RK45", "DOP853", "RK23", "LSODA", "Radau", "BDF"]
ODE_METHODS: tuple[OdeMethod, ...] = get_args(OdeMethod)
VARIANTS = ("whole", "segmented")
#: Breakpoints closer than this fraction of the length are one.
SAME_MARK = 1e-12


@dataclass(frozen=True)
class ShootingOptions:
    """Accuracy knobs of the shooting baselines.

    ``rtol``/``atol``: ``solve_ivp`` tolerances (``atol`` absolute, on the SI state);
    ``max_step``: largest ODE step (m), unbounded by default; ``ode_method``: a ``solve_ivp``
    method; ``root_tol``: ``xtol`` of the root finder on the scaled unknowns
    ``(n/T, m/(R_c T))``; ``max_shots``: bound on integrations of the body.
    """

    rtol: float = 1e-6
    atol: float = 1e-12
    max_step: float = math.inf
    ode_method: OdeMethod = "RK45"
    root_tol: float = 1e-10
    max_shots: int = 200

    def __post_init__(self) -> None:
        if self.ode_method not in ODE_METHODS:
            raise out_of_range("ode_method", self.ode_method, " | ".join(ODE_METHODS),
                               error=InvalidSettingsError)
        for name in ("rtol", "atol", "root_tol"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and 0.0 < value < 1.0):
                raise out_of_range(name, value, "(0, 1)", error=InvalidSettingsError)
        if not (isinstance(self.max_step, (int, float)) and self.max_step > 0.0):
            raise out_of_range("max_step", self.max_step, "(0, inf] m", error=InvalidSettingsError)
        if isinstance(self.max_shots, bool) or not isinstance(self.max_shots, int) \
                or not 1 <= self.max_shots <= 100000:
            raise out_of_range("max_shots", self.max_shots, "integer in [1, 100000]",
                               error=InvalidSettingsError)


DEFAULT_OPTIONS = ShootingOptions()


class _Rod:
    """``1/(E I(s))`` (1/(N m^2)) at any ``s`` (m), evaluated pointwise from the profile.

    Built-in profiles use scalar ``math`` (eqs. 12-13 in closed form); custom ones call the
    user's ``h1`` through :func:`notched_moment`.
    """

    def __init__(self, design: Design) -> None:
        self.design = design
        left, right = design.notch_bounds()
        self.left = left.tolist()
        self.right = right.tolist()
        self.w_n = design.per_notch("w_n").tolist()
        self.w_d = design.per_notch("w_d").tolist()
        self.tube_c = 1.0 / (design.E * design.tube_second_moment)
        self.profiles = design.notch_profiles()

    def compliance(self, s: float) -> float:
        """Compliance at ``s``; inside notch ``i`` when ``l_i <= s < r_i``."""
        i = bisect.bisect_right(self.left, s) - 1
        if i < 0 or s >= self.right[i]:
            return self.tube_c
        d = self.design
        sigma = s - self.left[i]
        w_n, w_d, profile = self.w_n[i], self.w_d[i], self.profiles[i]
        if profile.name == "circular":
            h1 = 0.5 * (w_n + w_d) - math.sqrt(max(sigma * (w_n - sigma), 0.0))
        elif profile.name == "rectangular":
            h1 = 0.5 * w_d
        else:
            h1_arr = profile.h1(np.array([sigma / w_n]), w_n, w_d)
            return float(1.0 / (d.E * notched_moment(h1_arr, d.R_outer, d.r_inner)[0]))
        inertia = 4.0 * (_strip(h1, d.R_outer) - _strip(min(h1, d.r_inner), d.r_inner))
        return 1.0 / (d.E * inertia)


def _strip(h: float, radius: float) -> float:
    """``int_0^h y^2 sqrt(radius^2 - y^2) dy`` (m^4), ``h`` clipped to [0, radius]."""
    if radius <= 0.0:
        return 0.0
    h = min(max(h, 0.0), radius)
    root_ = math.sqrt(max(radius * radius - h * h, 0.0))
    return (h / 8.0) * (2.0 * h * h - radius * radius) * root_ + radius**4 / 8.0 * math.asin(
        h / radius)


def _breakpoints(design: Design, variant: str) -> list[float]:
    """Integration intervals' ends (m): ``[0, L]`` or every ``l_i``/``r_i`` in between."""
    if variant == "whole":
        return [0.0, design.length]
    left, right = design.notch_bounds()
    marks = np.unique(np.concatenate([[0.0, design.length], left, right]))
    # a notch right after another (no tube between) may end a rounding error from where the
    # next starts: one mark, not an interval no integrator can step
    marks = marks[np.concatenate([[True], np.diff(marks) > SAME_MARK * design.length])]
    marks[-1] = design.length
    return marks.tolist()


class _Shooter:
    """One design, tension, variant and options; :meth:`shoot` integrates base to tip."""

    def __init__(self, grid: Grid, tension: float, variant: str, options: ShootingOptions):
        self.rod = _Rod(grid.design)
        self.grid = grid
        self.tension = tension
        self.options = options
        self.marks = _breakpoints(grid.design, variant)
        self.shots = 0
        self.history: list[float] = []

    def rhs(self, s: float, y: Array) -> list[float]:
        """Right-hand side of the Cosserat equations with the constrained tendon's load."""
        theta, n_x, n_z, m = y[2], y[3], y[4], y[5]
        sin_t, cos_t = math.sin(theta), math.cos(theta)
        kappa = m * self.rod.compliance(s)
        load = self.tension * kappa
        return [sin_t, cos_t, kappa, -load * cos_t, load * sin_t, -(cos_t * n_x - sin_t * n_z)]

    def shoot(self, n0: Array, m0: float) -> tuple[Array, bool]:
        """Integrate from the clamped base; returns node states (nodes, 6) and success."""
        self.shots += 1
        s_nodes = self.grid.s_nodes
        y = np.array([0.0, 0.0, 0.0, n0[0], n0[1], m0])
        states = np.empty((s_nodes.size, 6))
        states[0] = y
        for a, b in zip(self.marks[:-1], self.marks[1:], strict=True):
            inside = np.flatnonzero((s_nodes > a) & (s_nodes <= b))
            times = s_nodes[inside]
            # the state at b starts the next interval, whether or not a node sits there
            t_eval = times if times.size and times[-1] == b else np.append(times, b)
            sol = solve_ivp(self.rhs, (a, b), y, method=self.options.ode_method,
                            t_eval=t_eval, rtol=self.options.rtol,
                            atol=self.options.atol, max_step=self.options.max_step)
            if sol.status != 0 or sol.y.shape[1] != t_eval.size:
                return states, False
            states[inside] = sol.y.T[:inside.size]
            y = sol.y[:, -1]
        return states, bool(np.all(np.isfinite(states)))

    def residual(self, v: Array) -> Array:
        """Scaled tip-condition mismatch for scaled unknowns ``v = (n/T, m/(R_c T))``."""
        t, rc_t = self.tension, self.grid.r_c * self.tension
        states, ok = self.shoot(v[:2] * t, float(v[2]) * rc_t)
        if not ok:
            self.history.append(math.inf)
            return np.full(3, 1e6)
        tip = states[-1]
        out = np.array([tip[3] / t + math.sin(tip[2]), tip[4] / t + math.cos(tip[2]),
                        tip[5] / rc_t - 1.0])
        self.history.append(float(np.max(np.abs(out))))
        return out


def _solve(design: Design, tension: float, settings: SolverSettings, options: ShootingOptions,
           variant: str, strict: bool) -> SolveResult:
    started = perf_counter()
    t = check_tension(tension)
    name = f"shooting-{variant}"
    require_centred(design, name)
    grid = build_grid(design, settings)
    check_tendon_singularity(grid, t)
    s = grid.s_nodes
    if t == 0.0:
        zeros = np.zeros_like(s)
        return node_result(grid, settings, t, x=zeros, z=s.copy(), theta=zeros,
                           cell_moments=np.zeros((grid.n_cells, 2)), iterations=0,
                           residual_history=(), converged=True, strategy=name,
                           solve_time_s=perf_counter() - started)
    shooter = _Shooter(grid, t, variant, options)
    found = root(  # type: ignore[call-overload]  # scipy-stubs misspell hybr's maxfev (maxffev)
        shooter.residual, np.array([0.0, -1.0, 1.0]), method="hybr",
        options={"xtol": options.root_tol, "maxfev": options.max_shots})
    states, ok = shooter.shoot(found.x[:2] * t, float(found.x[2]) * design.R_c * t)
    converged = bool(found.success) and ok
    if not converged and (strict or not ok):
        raise ConvergenceError(
            f"{name} did not meet the tip conditions at tension {t:g} N "
            f"(rtol = {options.rtol:g}, {shooter.shots} shots): {found.message}")
    m = states[:, 5]
    return node_result(grid, settings, t, x=states[:, 0], z=states[:, 1], theta=states[:, 2],
                       cell_moments=np.stack([m[:-1], m[1:]], axis=1), iterations=shooter.shots,
                       residual_history=tuple(shooter.history), converged=converged,
                       strategy=name, solve_time_s=perf_counter() - started)


def solve_shooting_whole(design: Design, tension: float, *,
                         settings: SolverSettings = DEFAULT_SETTINGS,
                         options: ShootingOptions = DEFAULT_OPTIONS,
                         strict: bool = True) -> SolveResult:
    """Shooting with one ``solve_ivp`` call over ``[0, L]`` per shot (steps cross the jumps).

    ``settings`` only chooses the output nodes (the grid); ``iterations`` counts shots and
    ``residual_history`` holds each shot's largest scaled tip mismatch (dimensionless).
    """
    return _solve(design, tension, settings, options, "whole", strict)


def solve_shooting_segmented(design: Design, tension: float, *,
                             settings: SolverSettings = DEFAULT_SETTINGS,
                             options: ShootingOptions = DEFAULT_OPTIONS,
                             strict: bool = True) -> SolveResult:
    """Shooting with the integrator restarted at every ``l_i`` and ``r_i`` (see module doc)."""
    return _solve(design, tension, settings, options, "segmented", strict)
