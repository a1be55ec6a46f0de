"""The shape controller's core: a target in, the driver's setpoints out, the stiffness
correction learned from the measured tip.

Law: the inverse model gives the model tension ``T_m`` for the target (warm-started from the
previous answer); the world behaves like the model at ``g T`` (:mod:`.estimator`), so the
command is ``T = T_m / g_hat`` within ``[0, tension_max]``, and the roll is the target's.
``feedforward`` keeps ``g_hat`` as it is; ``feedback`` updates it from each measured tip while
the measured tension is at least ``adapt_min_n`` (a released or disarmed tendon teaches
nothing).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from numpy.typing import ArrayLike

from tdcm_ros.control.errors import TargetRefusedError
from tdcm_ros.control.estimator import GainEstimator, GainSettings, ModelTip
from tdcm_ros.control.limits import DriverLimits, clamp
from tdcm_ros.control.measured import measured_tip
from tdcm_ros.control.target import PlaneTarget, in_plane, rotate_z
from tdcm_ros.errors import out_of_range
from tdcm_ros.model import (
    Design,
    MarkerLayout,
    SolveResult,
    SolverSettings,
    solve_inverse,
)

MODES = ("feedforward", "feedback")
#: Default largest distance (m) of a point target from the tip's reachable path.
DEFAULT_TOLERANCE_M = 5e-4
#: Default smallest measured tension (N) at which the estimate adapts.
DEFAULT_ADAPT_MIN_N = 0.5


@dataclass(frozen=True)
class Resolved:
    """A target the controller commands: its roll and plane target, the model tension ``T_m``
    (N) that reaches it, the distance left (m, or rad for an angle) and the tip it asks for
    (m, ``tdcm_base``)."""

    plane: PlaneTarget
    model_tension_n: float
    residual: float
    tip_base: tuple[float, float, float]


@dataclass(frozen=True)
class Observation:
    """One measurement's outcome: the measured tip (``None`` without a visible tip marker)
    and the model's tip at the measured tension and roll with the estimate (m, ``tdcm_base``);
    whether the estimate adapted."""

    measured: tuple[float, float, float] | None
    predicted: tuple[float, float, float]
    adapted: bool


class ShapeController:
    """Targets, the feed-forward command and the gain estimate of one design."""

    def __init__(self, design: Design, layout: MarkerLayout, *,
                 gain: GainSettings | None = None, settings: SolverSettings | None = None,
                 tolerance_m: float = DEFAULT_TOLERANCE_M,
                 adapt_min_n: float = DEFAULT_ADAPT_MIN_N) -> None:
        if not (math.isfinite(tolerance_m) and tolerance_m > 0.0):
            raise out_of_range("target_tolerance_m", tolerance_m, "(0, inf) m")
        self.design, self.layout = design, layout
        self.settings = settings or SolverSettings()
        self.estimator = GainEstimator(gain)
        self.model = ModelTip(design, self.settings)
        self.tolerance_m, self.adapt_min_n = tolerance_m, adapt_min_n
        self.target: Resolved | None = None
        self._warm: SolveResult | None = None

    def resolve(self, plane: PlaneTarget, limits: DriverLimits) -> Resolved:
        """The model tension for ``plane`` within what the driver allows at the current
        estimate (``[0, g_hat tension_max]`` of model tension); becomes the target. Raises
        :class:`TargetRefusedError` past the tolerance, the model's
        ``UnreachableTargetError`` / ``InvalidTargetError`` (naming the reachable range)."""
        answer = solve_inverse(self.design, tip_point=plane.tip_point, tip_angle=plane.tip_angle,
                               tension_max=self.estimator.gain * limits.tension_max,
                               settings=self.settings, warm_start=self._warm)
        if plane.tip_point is not None and answer.residual > self.tolerance_m:
            u, z = answer.tip_point_m
            raise out_of_range(
                "target distance from the reachable path", answer.residual,
                f"[0, {self.tolerance_m:g}] m (target_tolerance_m; closest tip ({u:.6g}, "
                f"{z:.6g}) m in the bending plane at {answer.tension_n / self.estimator.gain:.4g}"
                " N)", unit="m", error=TargetRefusedError)
        self._warm = answer.result
        u, z = plane.tip_point if plane.tip_point is not None else answer.tip_point_m
        self.target = Resolved(plane, answer.tension_n, answer.residual,
                               rotate_z((u, 0.0, z), plane.roll_rad))
        return self.target

    def goal(self, limits: DriverLimits) -> tuple[float, float] | None:
        """The tension (N) and roll (rad) for the current target within the limits (before
        the slew); ``None`` without a target."""
        if self.target is None:
            return None
        tension = clamp(self.target.model_tension_n / self.estimator.gain, 0.0,
                        limits.tension_max)
        roll = clamp(self.target.plane.roll_rad, -limits.roll_max, limits.roll_max)
        return tension, roll

    def observe(self, tension_n: float, roll_rad: float, markers_base: ArrayLike | None,
                dt_s: float, *, adapt: bool) -> Observation:
        """One measurement: tension (N) and roll (rad) measured, marker rows (k, 3) m in
        ``tdcm_base`` (or ``None``), ``dt_s`` s since the previous one. Adapts the estimate when
        ``adapt``, the tip marker is visible and the tension is at least ``adapt_min_n``."""
        estimator = self.estimator
        if adapt:
            estimator.predict(dt_s)
        tension = tension_n if math.isfinite(tension_n) else 0.0
        result, tip, slope = self.model.tip_and_jacobian(estimator.gain, max(tension, 0.0))
        measured = (None if markers_base is None
                    else measured_tip(markers_base, result, self.layout, roll_rad))
        adapted = False
        if adapt and measured is not None and tension >= self.adapt_min_n:
            adapted = estimator.update(in_plane(measured, roll_rad), tip, slope)
        return Observation(measured, rotate_z((tip[0], 0.0, tip[1]), roll_rad), adapted)
