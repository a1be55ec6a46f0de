"""Shape targets and design limits: how far a solved shape is from what a designer asked for.

Every target gives residuals scaled by its tolerance, so that a residual in ``[-1, 1]`` meets
it; a search minimises the sum of their squares. A lower bound (``value >= bound``) gives
``max(0, (bound - value) / tol + 1)``: at most 1 exactly when the bound holds, 0 once it holds
with ``tol`` to spare, so a search leaves a margin.

- :class:`TipTarget`: the tip's position ``x``, ``z`` (m, frame ``tdcm_base``) and/or angle
  (rad from +z toward +x), each optional, with ``position_tol`` (m) and ``angle_tol`` (rad).
- :class:`CurveTarget`: points ``(x, z)`` (m) the midline should pass through; residual: each
  point's distance to the midline polyline over ``tol`` (m). :meth:`CurveTarget.arc` gives
  the constant-curvature arc of a length and a tip angle.
- :class:`NotchAngleTarget`: the bend of each notch (rad, base to tip): ``equal`` (each within
  ``tol`` of their mean, relative), ``tip_first`` (each at least its proximal neighbour and the
  last at least ``ratio`` times the first; ``tol`` relative) or ``angles`` (given, ``tol`` in rad).
- :class:`StopAngleTarget`: the body's hard stop, the sum of the notches' closure angles (rad,
  :func:`~tdcm_ros.model.limits.closure_angles`), at ``angle`` within ``tol``.

:class:`Limits` are hard: a design past one is infeasible whatever its shape: the peak notch
bending strain at most ``max_strain``, every notch at least ``stop_margin`` (rad) from closing,
and the fabrication minima (m): the tube wall ``R_outer - r_inner``, the backbone ``w_d`` of
every notch, the web of tube ``w_t`` between adjacent notches.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.design import Design
from tdcm_ros.model.inverse import InvalidTargetError
from tdcm_ros.model.result import SolveResult

Array = NDArray[np.float64]

NOTCH_ANGLE_KINDS = ("equal", "tip_first", "angles")
#: Default tolerances: 0.1 mm, 0.5 degree, 2 % (relative).
DEFAULT_POSITION_TOL_M = 1e-4
DEFAULT_ANGLE_TOL_RAD = math.radians(0.5)
DEFAULT_RELATIVE_TOL = 0.02


def _finite(name: str, value: Any, low: float = -math.inf, *, positive: bool = False,
            unit: str = "") -> float:
    """``value`` as a finite float at least ``low`` (above 0 with ``positive``)."""
    ok = not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
    if not ok or value < low or (positive and value <= 0.0):
        allowed = "(0, inf)" if positive else f"[{low:g}, inf)" if low > -math.inf else \
            "a finite number"
        raise out_of_range(name, value, allowed, unit=unit, error=InvalidTargetError)
    return float(value)


def lower_bound(value: Array | float, bound: float, tol: float) -> Array:
    """Residual of ``value >= bound`` with tolerance ``tol`` (see the module docstring)."""
    return np.maximum(0.0, (bound - np.asarray(value, dtype=float)) / tol + 1.0)


@dataclass(frozen=True)
class TipTarget:
    """The tip at ``x``, ``z`` (m) and/or ``angle`` (rad); None leaves one free."""

    x: float | None = None
    z: float | None = None
    angle: float | None = None
    position_tol: float = DEFAULT_POSITION_TOL_M
    angle_tol: float = DEFAULT_ANGLE_TOL_RAD

    def __post_init__(self) -> None:
        if self.x is None and self.z is None and self.angle is None:
            raise InvalidTargetError("targets.tip names none of x, z, angle; allowed: one or "
                                     "more", parameter="targets.tip", value={},
                                     allowed="x, z (m), angle (rad)")
        for name in ("x", "z", "angle"):
            if getattr(self, name) is not None:
                _finite(f"targets.tip.{name}", getattr(self, name))
        _finite("targets.tip.position_tol", self.position_tol, positive=True, unit="m")
        _finite("targets.tip.angle_tol", self.angle_tol, positive=True, unit="rad")

    def residuals(self, result: SolveResult) -> Array:
        return self.tip_residuals(result.tip_position, np.asarray(result.tip_angle_rad))

    def tip_residuals(self, tip: Array, angle: Array) -> Array:
        """Residuals of tips ``tip`` (..., 3) (m) at angles ``angle`` (...) (rad): shape
        (..., k), ``k`` the target's given quantities (x, z, angle in that order)."""
        out = []
        if self.x is not None:
            out.append((tip[..., 0] - self.x) / self.position_tol)
        if self.z is not None:
            out.append((tip[..., 2] - self.z) / self.position_tol)
        if self.angle is not None:
            out.append((angle - self.angle) / self.angle_tol)
        return np.stack(out, axis=-1)

    def achieved(self, result: SolveResult) -> dict[str, float]:
        tip = result.tip_position
        return {"x": float(tip[0]), "z": float(tip[2]), "angle": result.tip_angle_rad}


@dataclass(frozen=True, eq=False)
class CurveTarget:
    """The midline through ``points`` ((K, 2): ``x``, ``z``, m) within ``tol`` (m)."""

    points: Array
    tol: float = DEFAULT_POSITION_TOL_M

    def __post_init__(self) -> None:
        points = np.asarray(self.points, dtype=float)
        if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 1 or \
                not np.all(np.isfinite(points)):
            raise out_of_range("targets.curve.points", self.points,
                               "a list of [x, z] pairs (m), finite", error=InvalidTargetError)
        object.__setattr__(self, "points", points)
        _finite("targets.curve.tol", self.tol, positive=True, unit="m")

    @classmethod
    def arc(cls, length: float, angle: float, points: int = 16,
            tol: float = DEFAULT_POSITION_TOL_M) -> CurveTarget:
        """The constant-curvature arc from the base along +z, of ``length`` (m) turning by
        ``angle`` (rad) toward +x, as ``points`` points evenly spaced along it (base excluded)."""
        _finite("targets.curve.arc.length", length, positive=True, unit="m")
        _finite("targets.curve.arc.angle", angle)
        s = np.linspace(0.0, length, points + 1)[1:]
        if abs(angle) < 1e-12:
            return cls(np.c_[np.zeros_like(s), s], tol)
        radius = length / angle
        phase = s / radius
        return cls(np.c_[radius * (1.0 - np.cos(phase)), radius * np.sin(phase)], tol)

    def distances(self, result: SolveResult) -> Array:
        """Each point's distance (m) to the midline polyline."""
        line = result.positions[:, [0, 2]]
        start, step = line[:-1], np.diff(line, axis=0)
        rel = self.points[:, None, :] - start[None]
        length2 = np.maximum(np.sum(step**2, axis=1), 1e-300)
        t = np.clip(np.sum(rel * step[None], axis=2) / length2, 0.0, 1.0)
        gap = rel - t[..., None] * step[None]
        return np.asarray(np.sqrt(np.min(np.sum(gap**2, axis=2), axis=1)))

    def residuals(self, result: SolveResult) -> Array:
        return self.distances(result) / self.tol

    def achieved(self, result: SolveResult) -> dict[str, float]:
        distance = self.distances(result)
        return {"max_distance": float(np.max(distance)),
                "rms_distance": float(np.sqrt(np.mean(distance**2)))}


@dataclass(frozen=True)
class NotchAngleTarget:
    """The distribution of the notches' bends (see the module docstring)."""

    kind: str
    tol: float = DEFAULT_RELATIVE_TOL
    ratio: float = 1.0
    angles: tuple[float, ...] = field(default=())

    def __post_init__(self) -> None:
        if self.kind not in NOTCH_ANGLE_KINDS:
            raise out_of_range("targets.notch_angles.kind", self.kind,
                               ", ".join(NOTCH_ANGLE_KINDS), error=InvalidTargetError)
        _finite("targets.notch_angles.tol", self.tol, positive=True)
        if self.kind == "tip_first":
            _finite("targets.notch_angles.ratio", self.ratio, 1.0)
        if self.kind == "angles":
            if not self.angles:
                raise out_of_range("targets.notch_angles.angles", self.angles,
                                   "one angle per notch (rad)", error=InvalidTargetError)
            for i, angle in enumerate(self.angles):
                _finite(f"targets.notch_angles.angles[{i}]", angle)

    def check_notches(self, notches: int) -> None:
        """Refuse a target that cannot apply to a body of ``notches`` notches."""
        if self.kind == "angles" and len(self.angles) != notches:
            raise out_of_range("targets.notch_angles.angles", list(self.angles),
                               f"{notches} angles (one per notch)", error=InvalidTargetError)
        if self.kind != "angles" and notches < 2:
            raise out_of_range("targets.notch_angles.kind", self.kind,
                               "angles (a body of one notch has no distribution)",
                               error=InvalidTargetError)

    def residuals(self, result: SolveResult) -> Array:
        phi = result.notch_angles_rad
        if self.kind == "angles":
            return (phi - np.array(self.angles)) / self.tol
        scale = max(abs(float(np.mean(phi))), 1e-12)
        if self.kind == "equal":
            return (phi - np.mean(phi)) / (self.tol * scale)
        ordered = lower_bound(np.diff(phi) / scale, 0.0, self.tol)
        ratio = phi[-1] / phi[0] if phi[0] > 0.0 else math.inf if phi[-1] > 0.0 else 0.0
        return np.r_[ordered, lower_bound(ratio / self.ratio, 1.0, self.tol)]

    def achieved(self, result: SolveResult) -> dict[str, Any]:
        phi = result.notch_angles_rad
        mean = float(np.mean(phi))
        return {"angles": phi.tolist(),
                "spread": float(np.max(np.abs(phi - mean)) / abs(mean)) if mean else math.inf,
                "ratio": float(phi[-1] / phi[0]) if phi[0] else math.inf}


@dataclass(frozen=True)
class StopAngleTarget:
    """The notches close (their hard stop) at a total bend of ``angle`` (rad) within ``tol``."""

    angle: float
    tol: float = DEFAULT_ANGLE_TOL_RAD

    def __post_init__(self) -> None:
        _finite("targets.stop_angle.angle", self.angle, positive=True, unit="rad")
        _finite("targets.stop_angle.tol", self.tol, positive=True, unit="rad")

    @staticmethod
    def stop_angle(result: SolveResult) -> float:
        """Sum of the notches' closure angles (rad)."""
        return float(np.sum(result.notch_stop_margins_rad + result.notch_angles_rad))

    def residuals(self, result: SolveResult) -> Array:
        return np.array([(self.stop_angle(result) - self.angle) / self.tol])

    def achieved(self, result: SolveResult) -> dict[str, float]:
        return {"stop_angle": self.stop_angle(result)}


Target = TipTarget | CurveTarget | NotchAngleTarget | StopAngleTarget


@dataclass(frozen=True)
class Limits:
    """Hard limits (see the module docstring): ``max_strain`` (dimensionless), ``stop_margin``
    (rad; None: a notch may close only where notch contact is modelled, which the search does
    not, so closing is a failed solve) and the fabrication minima ``min_wall``,
    ``min_backbone``, ``min_web`` (m; 0: none)."""

    max_strain: float
    stop_margin: float = 0.0
    min_wall: float = 0.0
    min_backbone: float = 0.0
    min_web: float = 0.0

    def __post_init__(self) -> None:
        _finite("limits.max_strain", self.max_strain, positive=True)
        _finite("limits.stop_margin", self.stop_margin, 0.0, unit="rad")
        for name in ("min_wall", "min_backbone", "min_web"):
            _finite(f"fabrication.{name}", getattr(self, name), 0.0, unit="m")

    def fabrication(self, design: Design) -> dict[str, float]:
        """How far ``design`` falls short of each fabrication minimum (m; 0 where it holds)."""
        gaps = design.per_notch("w_t")
        return {
            "min_wall": max(0.0, self.min_wall - (design.R_outer - design.r_inner)),
            "min_backbone": max(0.0, self.min_backbone - float(np.min(design.per_notch("w_d")))),
            "min_web": max(0.0, self.min_web - float(np.min(gaps))) if gaps.size else 0.0,
        }

    def shape(self, result: SolveResult) -> dict[str, float]:
        """How far a solved shape passes each limit (0 where it holds): strain over
        ``max_strain`` (relative), stop margin short of ``stop_margin`` (rad; only where one is
        asked for: finding the notches' closure angles costs ~10 solves)."""
        strain = float(np.max(result.notch_peak_strains))
        out = {"max_strain": max(0.0, strain / self.max_strain - 1.0)}
        if self.stop_margin > 0.0:  # a closed notch fails the solve: margin 0 holds already
            margin = float(np.min(result.notch_stop_margins_rad))
            out["stop_margin"] = max(0.0, self.stop_margin - margin)
        return out
