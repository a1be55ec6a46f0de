"""The inverse model: the tendon tension (N) that puts the tip at a target.

A target is a tip deflection (m, distance from the +z axis), a tip angle (rad, from +z toward
+x), a tip point ``(x, z)`` in ``tdcm_base`` (m) or a tendon stroke (m, how far the tendon's
actuator has pulled it in: the path's stroke plus the tendon's slack and stretch where the
design gives them, :attr:`~tdcm_ros.model.result.SolveResult.actuator_strokes_m`). The
tension is sought within bounds
``[tension_min, tension_max]`` (N; default ``[0, DEFAULT_TENSION_MAX_N]``), each trial a
forward :func:`~tdcm_ros.model.solver.solve` warm-started from the nearest earlier one.

- Deflection, angle and stroke: a root of ``measure(T) - target`` bracketed by the bounds,
  found with Brent's method (``scipy.optimize.brentq``, imported only here). All grow
  monotonically with the tension while the tip angle stays below about 2.3 rad (a circular
  arc's deflection peaks there; the stroke grows as long as the body bends further); the
  reachable range is the measure at the bounds. Past that peak (bounds far above
  the default) a target only reached on the curled branch is reported unreachable.
- Point: least squares over the tension (the closest tip point on the tension's path): each
  step minimises the distance to the target along a quadratic through three solves near the
  best (Newton with the path's curvature), until the tip would move less than ``tol / 10``;
  the result carries the residual (m). A point whose closest tip lies at a bound, farther
  than ``tol``, is unreachable.

Physical limits: the tendon singularity and notch closure grow with the tension. If the solve
at ``tension_max`` meets one, the upper end of the reachable range is the largest tension that
solves (bisected to ``LIMIT_RTOL``, ~40 more solves), and an unreachable target's error
names that limit. A ``tension_min`` past a limit raises that limit's own error.

Sensitivity ``d(tip)/dT``: a finite difference of two warm-started solves at ``T +- h`` with
``h = SENSITIVITY_STEP * (upper - lower)``, central inside the bounds, one-sided at them. Its
error is the truncation ``h**2 |tip'''| / 6`` (one-sided: ``h |tip''| / 2``) plus the solves'
noise ``~ tol_solve / h``; ``bench/bench_inverse.py`` measures it against a tight reference
(3.6e-8 relative on paper-experiment). The implicit-function derivative would need the fixed
point's Jacobian, which the solver does not expose.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import InputError
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import ModelError, ModelLimitError
from tdcm_ros.model.limits import check_tensions
from tdcm_ros.model.result import ConvergenceError, SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS, solve
from tdcm_ros.model.tendons import is_paper_like

Array = NDArray[np.float64]

#: Default upper tension bound (N): over twice the paper's 0-20 N experiment, so the bench's
#: whole setpoint range is covered, while every preset stays far from its tendon singularity
#: and notch closure and below 1 rad of tip angle (deflection still monotone).
DEFAULT_TENSION_MAX_N = 50.0
#: Default tolerance on the target: m for a deflection or point, rad for an angle.
DEFAULT_TOL = 1e-9
#: Finite-difference step of the sensitivity, as a fraction of the tension bounds' span.
SENSITIVITY_STEP = 1e-3
#: Relative tolerance (of the bounds' span) on the limit tension when ``tension_max`` is past one.
LIMIT_RTOL = 1e-9
#: Largest number of model steps (solves) for a point target beyond the first three.
MAX_POINT_STEPS = 40
#: Largest number of safeguarded Newton steps per root of the point target's cubic.
CUBIC_STEPS = 200

TARGET_KINDS = ("tip_deflection", "tip_angle", "tip_point", "tendon_stroke")


class InvalidTargetError(ModelError, InputError):
    """A target or tension bound is missing, not finite, or outside its allowed range."""

    kind = "invalid_target"


class UnreachableTargetError(ModelLimitError):
    """The target lies outside what the tip reaches within the tension bounds.

    ``reachable`` is the tip (the target's kind and unit) at the lower and upper end of the
    reachable tension range ``tension_range`` (N); ``limit`` names the physical limit that ends
    the range below ``tension_max``, if one does.
    """

    kind = "unreachable_target"

    def __init__(self, message: str, *, target: Any, reachable: tuple[Any, Any],
                 tension_range: tuple[float, float], limit: str | None = None) -> None:
        super().__init__(message)
        self.target = target
        self.reachable = reachable
        self.tension_range = tension_range
        self.limit = limit


@dataclass(frozen=True)
class Sensitivity:
    """``d(tip)/dT`` at the returned tension: of the tip point ``(x, z)`` (m/N), the tip angle
    (rad/N) and the tip deflection (m/N), by ``method`` (``central``, ``forward`` or
    ``backward`` finite difference of warm-started solves) with step ``step_n`` (N)."""

    tip_point_m_per_n: tuple[float, float]
    tip_angle_rad_per_n: float
    tip_deflection_m_per_n: float
    method: str
    step_n: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields."""
        return {"tip_point_m_per_n": list(self.tip_point_m_per_n),
                "tip_angle_rad_per_n": self.tip_angle_rad_per_n,
                "tip_deflection_m_per_n": self.tip_deflection_m_per_n,
                "method": self.method, "step_n": self.step_n}


@dataclass(frozen=True)
class InverseResult:
    """The tension for a target and what it achieves.

    ``tension_n`` (N) is the answer (the sought ``tendon``'s, an index); ``result`` its forward
    solve (so ``result.tip_position``
    is the achieved tip); ``residual`` the distance from the achieved tip to the target (m for a
    deflection or point, rad for an angle); ``forward_solves`` how many solves the call made,
    the sensitivity's included.
    """

    target_kind: str
    target: Any
    tension_n: float
    result: SolveResult = field(repr=False)
    residual: float
    sensitivity: Sensitivity
    forward_solves: int
    tension_bounds: tuple[float, float]
    tendon: int = 0

    @property
    def tip_point_m(self) -> tuple[float, float]:
        """Achieved tip ``(x, z)`` (m, ``tdcm_base``)."""
        return _point(self.result)

    def summary(self) -> dict[str, Any]:
        """The JSON-ready summary used by ``tdcm inverse --json`` (SI units)."""
        return {
            "target": {"kind": self.target_kind,
                       "value": list(self.target) if self.target_kind == "tip_point"
                       else self.target},
            "tension_n": self.tension_n,
            "tip_point_m": list(self.tip_point_m),
            "tip_angle_rad": self.result.tip_angle_rad,
            "tip_deflection_m": self.result.tip_deflection_m,
            "tendon": self.result.tendons.names[self.tendon],
            "tensions_n": list(self.result.tensions_n),
            "tendon_stroke_m": float(self.result.tendon_strokes_m[self.tendon]),
            "actuator_stroke_m": float(self.result.actuator_strokes_m[self.tendon]),
            "residual": self.residual,
            "residual_unit": "rad" if self.target_kind == "tip_angle" else "m",
            "sensitivity": self.sensitivity.to_dict(),
            "forward_solves": self.forward_solves,
            "tension_bounds_n": list(self.tension_bounds),
        }


def _point(result: SolveResult) -> tuple[float, float]:
    """Tip ``(x, z)`` (m) of a solve."""
    return float(result.positions[-1, 0]), float(result.positions[-1, 2])


class _Forward:
    """Forward solves of one design at the sought tendon's tension (the others at ``held``,
    N, one per listed tendon; None: the paper's one tendon), each warm-started from the
    nearest earlier one; counted."""

    def __init__(self, design: Design, settings: SolverSettings,
                 warm_start: SolveResult | None, sought: int = 0,
                 held: tuple[float, ...] | None = None) -> None:
        self.design = design
        self.settings = settings
        self.solved: dict[float, SolveResult] = {}
        self.warm = warm_start
        self.sought = sought
        self.held = held
        self.count = 0

    def __call__(self, tension: float) -> SolveResult:
        if tension in self.solved:
            return self.solved[tension]
        nearest = min(self.solved, key=lambda t: abs(t - tension), default=None)
        warm = self.warm if nearest is None else self.solved[nearest]
        self.count += 1
        given: float | list[float] = tension
        if self.held is not None:
            given = list(self.held)
            given[self.sought] = tension
        result = solve(self.design, given, settings=self.settings, warm_start=warm)
        self.solved[tension] = result
        return result


def solve_inverse(design: Design, *, tip_deflection: float | None = None,
                  tip_angle: float | None = None,
                  tip_point: tuple[float, float] | None = None,
                  tendon_stroke: float | None = None,
                  tension_min: float = 0.0, tension_max: float = DEFAULT_TENSION_MAX_N,
                  settings: SolverSettings = DEFAULT_SETTINGS,
                  warm_start: SolveResult | None = None,
                  tol: float = DEFAULT_TOL, tendon: int | str | None = None,
                  tensions: Sequence[float] | None = None) -> InverseResult:
    """The tension (N) in ``[tension_min, tension_max]`` that puts the tip of ``design`` at
    exactly one target: ``tip_deflection`` (m), ``tip_angle`` (rad), ``tip_point`` ``(x, z)``
    (m, least squares) or ``tendon_stroke`` (m, the tendon's actuator travel: the path's
    stroke, its slack and stretch). ``tol`` is the tolerance on the target (m, or rad for an
    angle);
    ``warm_start`` seeds the first forward solve (a result of the same design and settings).
    A design with several tendons (``Design.tendons``) names the ``tendon`` whose tension is
    sought (its name or index; its stroke is the stroke target's), the others held at
    ``tensions`` (N, one per tendon, the sought one's entry unused; default 0: a preload held
    constant).

    Raises :class:`InvalidTargetError` for a bad target, bounds or ``tol``;
    :class:`UnreachableTargetError` (naming the reachable range) when the target is out of
    reach; a forward solve's own errors pass through.
    """
    sought, held = sought_tendon(design, tendon, tensions)
    kind, target = _check_target(tip_deflection, tip_angle, tip_point, tendon_stroke)
    lower, upper = _check_bounds(tension_min, tension_max)
    tolerance = _real(tol)
    if tolerance is None or not math.isfinite(tolerance) or tolerance <= 0.0:
        raise InvalidTargetError(f"tol = {tol!r} is out of range; allowed: (0, inf) m or rad",
                                 parameter="tol", value=tol, allowed="(0, inf)")
    forward = _Forward(design, settings, warm_start, sought, held)
    top, limit = _reachable_top(forward, lower, upper)
    if kind == "tip_point":
        tension, residual = _point_tension(forward, target, lower, top, limit, tolerance)
    else:
        measure = _measure(kind, sought)
        tension = _scalar_tension(forward, measure, kind, target, lower, top, limit, tolerance)
        residual = abs(measure(forward(tension)) - target)
    sensitivity = _sensitivity(forward, tension, lower, top)
    return InverseResult(kind, target, tension, forward(tension), residual, sensitivity,
                         forward.count, (lower, upper), sought)


def _measure(kind: str, sought: int) -> Callable[[SolveResult], float]:
    """The scalar a target of ``kind`` is compared with (the stroke: the sought tendon's
    actuator travel, m)."""
    if kind == "tendon_stroke":
        return lambda r: float(r.actuator_strokes_m[sought])
    return _MEASURES[kind]


_MEASURES: dict[str, Callable[[SolveResult], float]] = {
    "tip_deflection": lambda r: r.tip_deflection_m,
    "tip_angle": lambda r: r.tip_angle_rad,
}


def sought_tendon(design: Design, tendon: int | str | None,
                   tensions: Sequence[float] | None) -> tuple[int, tuple[float, ...] | None]:
    """The sought tendon's index and the held tensions (N; None for the paper's one tendon),
    checked: :class:`InvalidTargetError` naming ``tendon`` or ``tensions``."""
    names = [t.name for t in design.tendon_list()]
    if tendon is None:
        if len(names) > 1:
            raise InvalidTargetError(
                f"tendon is missing: this design has {len(names)} tendons; allowed: one of "
                f"{', '.join(names)} (or its index)", parameter="tendon", value=None,
                allowed=" | ".join(names))
        sought = 0
    elif isinstance(tendon, str) and tendon in names:
        sought = names.index(tendon)
    elif isinstance(tendon, int) and not isinstance(tendon, bool) and 0 <= tendon < len(names):
        sought = tendon
    else:
        raise InvalidTargetError(f"tendon = {tendon!r} is not one of this design's tendons; "
                                 f"allowed: {', '.join(names)} or 0..{len(names) - 1}",
                                 parameter="tendon", value=tendon, allowed=" | ".join(names))
    if is_paper_like(design.tendons):
        if tensions is not None:
            raise InvalidTargetError("tensions go with a design of several tendons; allowed: "
                                     "none", parameter="tensions", value=list(tensions),
                                     allowed="none")
        return sought, None
    held = check_tensions([0.0] * len(names) if tensions is None else tensions, len(names))
    return sought, held
_UNITS = {"tip_deflection": "m", "tip_angle": "rad", "tip_point": "m", "tendon_stroke": "m"}


def one_target(targets: dict[str, Any]) -> tuple[str, Any]:
    """The one target of ``targets`` (kind -> value, ``None`` where not given) that is given,
    as ``(kind, value)``; :class:`InvalidTargetError` unless exactly one is."""
    given = {name: value for name, value in targets.items() if value is not None}
    if len(given) != 1:
        raise InvalidTargetError(
            f"give exactly one target, got {sorted(given) or 'none'}; allowed: one of "
            f"{', '.join(targets)}", parameter="target", value=sorted(given),
            allowed=" | ".join(targets))
    (kind, value), = given.items()
    return kind, value


def _check_target(tip_deflection: float | None, tip_angle: float | None,
                  tip_point: tuple[float, float] | None, tendon_stroke: float | None
                  ) -> tuple[str, Any]:
    """The one target given, checked: ``(kind, value)``."""
    kind, value = one_target(dict(zip(
        TARGET_KINDS, (tip_deflection, tip_angle, tip_point, tendon_stroke), strict=True)))
    if kind == "tip_point":
        values = np.asarray(value, dtype=float) if _is_pair(value) else None
        if values is None or not np.all(np.isfinite(values)):
            raise InvalidTargetError(
                f"tip_point = {value!r} is out of range; allowed: two finite numbers (x, z) m",
                parameter="tip_point", value=value, allowed="(x, z), finite, m")
        return kind, (float(values[0]), float(values[1]))
    number = _real(value)
    low = -math.inf if kind == "tip_angle" else 0.0
    if number is None or not math.isfinite(number) or number < low:
        allowed = "finite rad" if kind == "tip_angle" else "[0, inf) m, finite"
        raise InvalidTargetError(f"{kind} = {value!r} is out of range; allowed: {allowed}",
                                 parameter=kind, value=value, allowed=allowed)
    return kind, number


def _is_pair(value: Any) -> bool:
    """Whether ``value`` is a sequence of exactly two real numbers."""
    try:
        return len(value) == 2 and all(_real(v) is not None for v in value)
    except TypeError:
        return False


def _real(value: Any) -> float | None:
    """``value`` as a float if it is a real number (not a bool), else None."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        return None
    return float(value)


def _check_bounds(tension_min: Any, tension_max: Any) -> tuple[float, float]:
    """The tension bounds (N), finite with ``0 <= tension_min < tension_max``."""
    low, high = _real(tension_min), _real(tension_max)
    if low is None or not math.isfinite(low) or low < 0.0:
        raise InvalidTargetError(
            f"tension_min = {tension_min!r} N is out of range; allowed: finite, >= 0 N",
            parameter="tension_min", value=tension_min, allowed="[0, tension_max) N")
    if high is None or not math.isfinite(high) or high <= low:
        raise InvalidTargetError(
            f"tension_max = {tension_max!r} N is out of range; allowed: finite, > tension_min "
            f"= {low:g} N", parameter="tension_max", value=tension_max,
            allowed=f"({low:g}, inf) N")
    return low, high


def _reachable_top(forward: _Forward, lower: float, upper: float) -> tuple[float, str | None]:
    """The largest tension (N) of the bounds that solves, and the limit that sets it (None if
    ``upper`` solves). Solves at both bounds; bisects the limit only if ``upper`` meets one."""
    forward(lower)
    try:
        forward(upper)
        return upper, None
    except ModelLimitError as error:
        limit = error.kind
    good, bad = lower, upper
    while bad - good > LIMIT_RTOL * (upper - lower):
        middle = 0.5 * (good + bad)
        try:
            forward(middle)
            good = middle
        except ModelLimitError as error:
            bad, limit = middle, error.kind
    return good, limit


def _unreachable(kind: str, target: Any, shown: tuple[str, str], lower: float, top: float,
                 limit: str | None, reachable: tuple[Any, Any]) -> UnreachableTargetError:
    """The error for a target out of reach, naming the reachable range."""
    unit = _UNITS[kind]
    end = f" (upper end set by {limit.replace('_', ' ')} at {top:.6g} N)" if limit else ""
    shown_target = (f"({target[0]:.9g}, {target[1]:.9g})" if kind == "tip_point"
                    else f"{target:.9g}")
    return UnreachableTargetError(
        f"{kind} = {shown_target} {unit} is unreachable: within tension [{lower:g}, {top:.6g}] N "
        f"the {kind.replace('_', ' ')} spans {shown[0]} to {shown[1]} {unit}{end}",
        target=target, reachable=reachable, tension_range=(lower, top), limit=limit)


def _scalar_tension(forward: _Forward, measure: Callable[[SolveResult], float], kind: str,
                    target: float, lower: float, top: float, limit: str | None,
                    tol: float) -> float:
    """Brent's root of ``measure(T) - target`` on ``[lower, top]`` (N)."""
    at_low, at_top = measure(forward(lower)), measure(forward(top))
    if not min(at_low, at_top) - tol <= target <= max(at_low, at_top) + tol:
        raise _unreachable(kind, target, (f"{at_low:.9g}", f"{at_top:.9g}"), lower, top, limit,
                           (at_low, at_top))
    if abs(at_low - target) <= tol:
        return lower
    if abs(at_top - target) <= tol:
        return top
    from scipy.optimize import brentq  # lazily: `tdcm solve` never loads scipy

    slope = abs(at_top - at_low) / (top - lower)
    tension = brentq(lambda t: measure(forward(t)) - target, lower, top,
                     xtol=0.01 * tol / slope, rtol=4.0 * np.finfo(float).eps, maxiter=100)
    return float(tension)


def _point_tension(forward: _Forward, target: tuple[float, float], lower: float, top: float,
                   limit: str | None, tol: float) -> tuple[float, float]:
    """Least-squares tension (N) on ``[lower, top]`` for a tip point and its residual (m).

    The tip's path is modelled by the quadratic through the best solved tension so far, its
    nearest solved neighbour and the nearest one at least ``SENSITIVITY_STEP`` of the span
    away, so the curvature is not drawn from solves closer than their noise (first: the
    bounds and their middle); the next tension minimises the model's distance to the target
    over the bounds (the real roots of a cubic). This is Newton on the distance with the
    path's curvature included, so it converges fast also when the target is off the path,
    where Gauss-Newton crawls.
    """
    tips = {t: _point(forward(t)) for t in (lower, 0.5 * (lower + top), top)}

    def miss(tension: float) -> float:
        x, z = tips[tension]
        return math.hypot(x - target[0], z - target[1])

    baseline = SENSITIVITY_STEP * (top - lower)
    for _ in range(MAX_POINT_STEPS):
        best = min(tips, key=miss)
        others = sorted((t for t in tips if t != best), key=lambda t: abs(t - best))
        far = next(t for t in others if abs(t - best) >= baseline)  # the bounds are that far
        near = (others[0], far if far != others[0] else others[1])
        path = _Quadratic.through(best, tips[best], *((t, tips[t]) for t in near))
        step = path.closest_step(target, lower - best, top - best)
        if abs(step) * math.hypot(*path.slope) <= 0.1 * tol or best + step in tips:
            break
        tips[best + step] = _point(forward(best + step))
    else:
        raise ConvergenceError(
            f"tip_point = {target}: the least-squares tension did not settle in "
            f"{MAX_POINT_STEPS} solves")
    tension = min(tips, key=miss)
    residual = miss(tension)
    if tension in (lower, top) and residual > tol:
        ends = (tips[lower], tips[top])
        raise _unreachable("tip_point", target, tuple(  # type: ignore[arg-type]
            f"({x:.9g}, {z:.9g})" for x, z in ends), lower, top, limit, ends)
    return tension, residual


Point = tuple[float, float]


@dataclass(frozen=True)
class _Quadratic:
    """The tip path ``q(s) = at + slope s + bend s^2`` (m, per coordinate ``(x, z)``) in
    ``s = T - center`` (N)."""

    at: Point
    slope: Point
    bend: Point

    @classmethod
    def through(cls, center: float, tip: Point, first: tuple[float, Point],
                second: tuple[float, Point]) -> _Quadratic:
        """The quadratic through ``(center, tip)`` and two more ``(tension, tip)`` pairs
        (Newton's divided differences)."""
        (t1, p1), (t2, p2) = first, second
        s1, s2 = t1 - center, t2 - center
        slope, bend = [], []
        for k in range(2):
            d1, d2 = (p1[k] - tip[k]) / s1, (p2[k] - tip[k]) / s2
            curve = (d2 - d1) / (s2 - s1)
            bend.append(curve)
            slope.append(d1 - curve * s1)
        return cls(tip, (slope[0], slope[1]), (bend[0], bend[1]))

    def miss(self, s: float, aim: Point) -> float:
        """Distance (m) from ``q(s)`` to ``aim``."""
        return math.hypot(*(self.at[k] + (self.slope[k] + self.bend[k] * s) * s - aim[k]
                            for k in range(2)))

    def closest_step(self, aim: Point, low: float, high: float) -> float:
        """The ``s`` in ``[low, high]`` minimising :meth:`miss`: a bound or a real root of
        ``d/ds |q - aim|^2 / 2 = (d + b s + c s^2) . (b + 2 c s)``."""
        d = [self.at[k] - aim[k] for k in range(2)]
        b, c = self.slope, self.bend

        def dot(u: Any, v: Any) -> float:
            return float(u[0] * v[0] + u[1] * v[1])

        cubic = (2.0 * dot(c, c), 3.0 * dot(b, c), dot(b, b) + 2.0 * dot(d, c), dot(d, b))
        return min([low, high, *_cubic_roots(cubic, low, high)], key=lambda s: self.miss(s, aim))


def _cubic_roots(cubic: tuple[float, float, float, float], low: float,
                 high: float) -> list[float]:
    """Real roots in ``(low, high)`` of ``a s^3 + b s^2 + c s + d`` (``cubic = (a, b, c, d)``):
    the cubic's turning points cut the interval into monotone pieces; each piece whose ends
    differ in sign holds one root, found by Newton kept inside the piece's bracket (bisection
    when a step would leave it)."""
    a, b, c, d = cubic

    def value(s: float) -> float:
        return ((a * s + b) * s + c) * s + d

    def slope(s: float) -> float:
        return (3.0 * a * s + 2.0 * b) * s + c

    cuts = [low, high]
    if a != 0.0:
        disc = b * b - 3.0 * a * c  # turning points: roots of 3 a s^2 + 2 b s + c
        if disc > 0.0:  # in the form that does not cancel
            q = -(b + math.copysign(math.sqrt(disc), b))
            cuts += [q / (3.0 * a), c / q] if q != 0.0 else [0.0]
    elif b != 0.0:
        cuts.append(-c / (2.0 * b))
    cuts = sorted(s for s in cuts if low <= s <= high)
    roots = [s for s in cuts if low < s < high and value(s) == 0.0]  # a root at a turning point
    for left, right in itertools.pairwise(cuts):
        f_left, f_right = value(left), value(right)
        if f_left == 0.0 or f_right == 0.0 or (f_left < 0.0) == (f_right < 0.0):
            continue  # signs compared, not multiplied: a product of tiny values underflows to 0
        s = 0.5 * (left + right)
        for _ in range(CUBIC_STEPS):
            f = value(s)
            if f == 0.0:
                break
            if (f < 0.0) == (f_left < 0.0):
                left = s
            else:
                right = s
            gradient = slope(s)
            newton = s - f / gradient if gradient != 0.0 else left - 1.0
            step_to = newton if left < newton < right else 0.5 * (left + right)
            if abs(step_to - s) <= 1e-15 * (1.0 + abs(s)):
                s = step_to
                break
            s = step_to
        if low < s < high:
            roots.append(s)
    return roots


def _sensitivity(forward: _Forward, tension: float, lower: float, top: float) -> Sensitivity:
    """``d(tip)/dT`` at ``tension`` (N) from two warm-started solves ``h`` apart."""
    step = SENSITIVITY_STEP * (top - lower)
    below, above = tension - step, tension + step
    if below >= 0.0 and above <= top:
        method, (t_low, t_high) = "central", (below, above)
    elif above <= top:
        method, (t_low, t_high) = "forward", (tension, above)
    else:
        method, (t_low, t_high) = "backward", (below, tension)
    low, high = forward(t_low), forward(t_high)
    span = t_high - t_low  # the sought tendon's tensions (a result's tension_n is the largest)
    d_point = (np.array(_point(high)) - np.array(_point(low))) / span
    return Sensitivity(
        (float(d_point[0]), float(d_point[1])),
        (high.tip_angle_rad - low.tip_angle_rad) / span,
        (high.tip_deflection_m - low.tip_deflection_m) / span, method, step)
