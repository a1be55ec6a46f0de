"""On-line effective-stiffness correction: a scalar extended Kalman filter on the tip.

The model has no gravity, so its shape depends on the tension only through ``T / E``: a world
whose modulus is ``E_world`` is the model at the effective tension ``g T`` with
``g = E_model / E_world`` (and any other error that scales the bending the same way). The state
is ``g`` (dimensionless, 1 = the model as is), a random walk:

    predict:  P <- P + q**2 dt                       (q: ``process_std`` per sqrt(s))
    measure:  y = tip(g T) + v,  v ~ N(0, sigma**2 I)  (y: in-plane tip (u, z), m)
    update:   H = T d(tip)/dT at g T                 (m per unit g, 2-vector)
              P+ = 1 / (1/P + |H|**2 / sigma**2)
              g+ = g + P+ H . (y - tip(g T)) / sigma**2

(the Kalman update for a scalar state with an isotropic 2D measurement noise). At a small
tension ``H`` is small and the update carries little weight, as it should: a released tendon
says nothing about the stiffness. ``g`` stays within ``bounds``; non-finite input is refused
and leaves the estimate unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tdcm_ros.errors import out_of_range
from tdcm_ros.model import Design, SolveResult, SolverSettings, solve

#: Relative tension step of the tip's finite-difference derivative.
DERIVATIVE_STEP = 1e-3


@dataclass(frozen=True)
class GainSettings:
    """Prior ``initial`` +- ``initial_std``, random-walk ``process_std`` (per sqrt(s)),
    measurement noise ``noise_m`` (m, per tip coordinate), ``bounds`` of ``g``."""

    initial: float = 1.0
    initial_std: float = 0.3
    process_std: float = 0.01
    noise_m: float = 2e-4
    bounds: tuple[float, float] = (0.2, 5.0)

    def __post_init__(self) -> None:
        low, high = self.bounds
        if not (math.isfinite(low) and math.isfinite(high) and 0.0 < low < high):
            raise out_of_range("gain.bounds", self.bounds, "0 < low < high, finite")
        if not low <= self.initial <= high:
            raise out_of_range("gain.initial", self.initial, f"[{low:g}, {high:g}]")
        for name in ("initial_std", "noise_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise out_of_range(f"gain.{name}", value, "(0, inf)")
        if not (math.isfinite(self.process_std) and self.process_std >= 0.0):
            raise out_of_range("gain.process_std", self.process_std, "[0, inf) per sqrt(s)")


class GainEstimator:
    """The estimate ``gain`` of ``g`` and its standard deviation ``std``; see the module."""

    def __init__(self, settings: GainSettings | None = None) -> None:
        self.settings = settings or GainSettings()
        self.gain = self.settings.initial
        self.variance = self.settings.initial_std ** 2
        self.updates = 0
        self.refused = 0

    @property
    def std(self) -> float:
        """Standard deviation of the estimate."""
        return math.sqrt(self.variance)

    def predict(self, dt_s: float) -> None:
        """Let the variance grow by the random walk over ``dt_s`` s (ignored unless > 0)."""
        if math.isfinite(dt_s) and dt_s > 0.0:
            self.variance += self.settings.process_std ** 2 * dt_s

    def update(self, measured: tuple[float, float], predicted: tuple[float, float],
               jacobian: tuple[float, float]) -> bool:
        """One measurement: the measured and predicted in-plane tip (m) and ``d(tip)/dg``
        (m). Returns whether it was used (all finite)."""
        y, h, big_h = (np.asarray(v, dtype=float) for v in (measured, predicted, jacobian))
        if not (np.all(np.isfinite(y)) and np.all(np.isfinite(h)) and np.all(np.isfinite(big_h))):
            self.refused += 1
            return False
        noise = self.settings.noise_m ** 2
        variance = 1.0 / (1.0 / self.variance + float(big_h @ big_h) / noise)
        gain = self.gain + variance * float(big_h @ (y - h)) / noise
        low, high = self.settings.bounds
        self.gain, self.variance = min(max(gain, low), high), variance
        self.updates += 1
        return True


class ModelTip:
    """The model's in-plane tip ``(x, z)`` (m) at an effective tension and its derivative,
    warm-started from the previous call."""

    def __init__(self, design: Design, settings: SolverSettings | None = None) -> None:
        self.design, self.settings = design, settings or SolverSettings()
        self._last: SolveResult | None = None

    def result(self, tension_n: float) -> SolveResult:
        """The forward solve at ``tension_n`` (N, >= 0)."""
        self._last = solve(self.design, max(tension_n, 0.0), settings=self.settings,
                           warm_start=self._last)
        return self._last

    def tip_and_jacobian(self, gain: float, tension_n: float
                         ) -> tuple[SolveResult, tuple[float, float], tuple[float, float]]:
        """The solve at ``gain * tension_n``, its tip ``(x, z)`` (m) and ``d(tip)/d(gain)``
        = ``tension_n d(tip)/dT`` (m), a forward difference."""
        effective = max(gain * tension_n, 0.0)
        step = DERIVATIVE_STEP * max(effective, 1.0)
        base = self.result(effective)
        ahead = solve(self.design, effective + step, settings=self.settings, warm_start=base)
        tip = (float(base.tip_position[0]), float(base.tip_position[2]))
        slope = (ahead.tip_position - base.tip_position) / step * tension_n
        return base, tip, (float(slope[0]), float(slope[2]))
