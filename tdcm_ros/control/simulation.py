"""The controller core closed around a simulated world: the model's design with another modulus
(``E_world = E_model / modulus_ratio``, so the true ``g`` is ``modulus_ratio``), a driver that
holds the slewed setpoints exactly, a tension sensor and markers with Gaussian noise.

For tests and benchmarks of the law and the estimator without a graph (the live version runs
the nodes: ``tdcm demo --scene tracking``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.control.controller import ShapeController
from tdcm_ros.control.estimator import GainSettings
from tdcm_ros.control.limits import DriverLimits, slew
from tdcm_ros.control.target import point_target, rotate_z
from tdcm_ros.model import Design, MarkerLayout, roll_points, solve, surface_points

Array = NDArray[np.float64]


@dataclass(frozen=True)
class TrackingRun:
    """Per control step: time (s), target index, target and world tip (m, ``tdcm_base``),
    commanded tension (N) and roll (rad), the gain estimate and its std."""

    time_s: Array
    target_index: NDArray[np.int64]
    target: Array
    tip: Array
    tension_n: Array
    roll_rad: Array
    gain: Array
    gain_std: Array

    @property
    def error_m(self) -> Array:
        """Distance of the world's tip from the target per step (m)."""
        return np.asarray(np.linalg.norm(self.tip - self.target, axis=1), dtype=float)

    def settled_error_m(self, settled_s: float) -> Array:
        """The largest error of each target over its last ``settled_s`` s (m)."""
        out = []
        for k in np.unique(self.target_index):
            held = self.target_index == k
            end = self.time_s[held][-1]
            out.append(float(self.error_m[held & (self.time_s > end - settled_s)].max()))
        return np.asarray(out)


def simulate_tracking(design: Design, targets: Sequence[tuple[float, float, float]], *,
                      modulus_ratio: float, mode: str, limits: DriverLimits,
                      layout: MarkerLayout | None = None, gain: GainSettings | None = None,
                      hold_s: float = 4.0, dt_s: float = 0.02, tension_noise_n: float = 0.02,
                      marker_noise_m: float = 1e-4, seed: int = 0) -> TrackingRun:
    """Hold each target (m, ``tdcm_base``) for ``hold_s`` s, one control step and one
    measurement every ``dt_s`` s; ``mode`` ``feedback`` adapts the gain, ``feedforward`` not."""
    layout = layout or MarkerLayout()
    world = design.with_overrides(E=design.E / modulus_ratio)
    controller = ShapeController(design, layout, gain=gain)
    rng = np.random.default_rng(seed)
    radius = layout.radius(design.R_outer)
    tension = roll = 0.0
    rows: list[tuple[float, ...]] = []
    steps = round(hold_s / dt_s)
    for k, target in enumerate(targets):
        controller.resolve(point_target(target, roll, limits.roll_max), limits)
        for i in range(steps):
            goal = controller.goal(limits)
            assert goal is not None  # resolved above
            tension = slew(tension, goal[0], limits.setpoint_rate, dt_s)
            roll = slew(roll, goal[1], limits.roll_rate, dt_s)
            result = solve(world, tension)
            planar = surface_points(result, layout.s, radius, layout.side_rad)[0]
            markers = roll_points(planar, roll)
            controller.observe(tension + rng.normal(0.0, tension_noise_n), roll,
                               markers + rng.normal(0.0, marker_noise_m, markers.shape), dt_s,
                               adapt=mode == "feedback")
            x, _, z = result.tip_position
            estimator = controller.estimator
            rows.append(((k * steps + i + 1) * dt_s, k, *target, *rotate_z((x, 0.0, z), roll),
                         tension, roll, estimator.gain, estimator.std))
    table = np.asarray(rows, dtype=float)
    return TrackingRun(table[:, 0], table[:, 1].astype(np.int64), table[:, 2:5], table[:, 5:8],
                       table[:, 8], table[:, 9], table[:, 10], table[:, 11])
