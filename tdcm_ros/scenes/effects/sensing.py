"""Sensing effects: applied in :meth:`tdcm_ros.scenes.world.World.markers` (SI units).

Hooks, each called only for listed effects: :meth:`SensingEffect.placement` (where the
markers really sit on the body), :meth:`SensingEffect.published` (the mocap -> tdcm_base
transform the mocap node publishes), :meth:`SensingEffect.observe` (what the cameras report).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from tdcm_ros.scenes.effects.base import Effect, EffectContext, register
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.params import Param
from tdcm_ros.scenes.stages import Pose

Array = NDArray[np.float64]


class SensingEffect(Effect):
    """Base of the sensing effects (:class:`~tdcm_ros.scenes.stages.Sensing`): a property of
    the markers or the motion capture; each hook defaults to "no change"."""

    stage = "sensing"
    cost_unit = "sample"

    def placement(self, s: Array, radius: float, side: float) -> tuple[Array, float, float]:
        """True arc lengths (m) of the markers, their distance from the midline (m) and side
        (rad) around the body z axis from the tendon side."""
        return s, radius, side

    def published(self, pose: Pose) -> Pose:
        """The transform the mocap node publishes, given the true one."""
        return pose

    def observe(self, positions: Array, stamp_s: float) -> Array:
        """Reported marker positions (k, 3) m in ``mocap`` at ``stamp_s`` s; NaN = not seen."""
        return positions


@register
class MarkerNoise(SensingEffect):
    """Independent Gaussian noise on every coordinate of every visible marker."""

    name = "marker_noise"
    summary = "Gaussian position noise per marker coordinate"
    params = (Param("std_m", "m", "standard deviation per axis", 1e-4, low=0.0, high=0.01),)

    def observe(self, positions: Array, stamp_s: float) -> Array:
        with self.timed():
            return positions + self.rng.normal(0.0, self.values["std_m"], positions.shape)


@register
class MarkerDropout(SensingEffect):
    """Markers not seen: independently per frame, and in bursts (occlusions) that start as a
    Poisson process and last an exponentially distributed time."""

    name = "marker_dropout"
    summary = "markers lost at random and in bursts"
    params = (
        Param("probability", "", "chance that a marker is lost in one frame", 0.01, low=0.0,
              high=1.0),
        Param("burst_rate_hz", "1/s", "mean number of occlusion bursts per second", 0.0,
              low=0.0, high=100.0),
        Param("burst_duration_s", "s", "mean length of a burst", 0.2, low=0.0, low_open=True,
              high=60.0),
        Param("burst_scope", "", "a burst hides one random marker or all of them", "one",
              kind="str", choices=("one", "all")),
    )

    def __init__(self, values: Mapping[str, Any], context: EffectContext) -> None:
        super().__init__(values, context)
        self._hidden_until = np.full(len(context.marker_arc_lengths), -math.inf)
        self._last_stamp: float | None = None

    def observe(self, positions: Array, stamp_s: float) -> Array:
        with self.timed():
            v = self.values
            count = positions.shape[0]
            elapsed = 0.0 if self._last_stamp is None else max(stamp_s - self._last_stamp, 0.0)
            self._last_stamp = stamp_s
            if v["burst_rate_hz"] > 0.0 and \
                    self.rng.random() < -math.expm1(-v["burst_rate_hz"] * elapsed):
                which = (slice(None) if v["burst_scope"] == "all"
                         else int(self.rng.integers(count)))
                end = stamp_s + self.rng.exponential(v["burst_duration_s"])
                self._hidden_until[which] = np.maximum(self._hidden_until[which], end)
            hidden = (self.rng.random(count) < v["probability"]) | (stamp_s < self._hidden_until)
            out = positions.copy()
            out[hidden] = np.nan
            return out


@register
class MarkerOffset(SensingEffect):
    """Markers glued off their nominal spot: along the body, further from the axis (ball size,
    glue) and around it. The estimator keeps the nominal placement."""

    name = "marker_offset"
    summary = "true marker placement differs from the nominal one"
    params = (
        Param("arc_offset_m", "m", "shift along s, one value for all or one per marker",
              (0.0,), kind="list", low=-0.01, high=0.01),
        Param("radial_offset_m", "m", "extra distance from the midline", 0.0, low=-0.005,
              high=0.005),
        Param("side_offset_deg", "deg", "rotation around the body axis", 0.0, low=-180.0,
              high=180.0),
    )

    @classmethod
    def validate(cls, where: str, values: Mapping[str, Any], context: EffectContext) -> None:
        key = f"{where}.arc_offset_m"
        nominal = np.asarray(context.marker_arc_lengths)
        offsets = np.asarray(values["arc_offset_m"])
        if offsets.size not in (1, nominal.size):
            raise InvalidSceneError(
                f"{key} has {offsets.size} values; allowed: 1 or {nominal.size} (one per marker)",
                parameter=key, value=list(offsets), allowed=f"1 or {nominal.size} values")
        length = context.true_design.length
        moved = nominal + offsets
        if np.any(moved < 0.0) or np.any(moved > length):
            raise InvalidSceneError(
                f"{key} moves markers to {moved.tolist()} m; allowed: within [0, {length:g}] m",
                parameter=key, value=list(offsets), allowed=f"markers within [0, {length:g}] m")

    def placement(self, s: Array, radius: float, side: float) -> tuple[Array, float, float]:
        with self.timed():
            return (s + np.asarray(self.values["arc_offset_m"]), radius + self.values["radial_offset_m"],
                    side + math.radians(self.values["side_offset_deg"]))


@register
class RegistrationError(SensingEffect):
    """The published mocap -> tdcm_base transform is off by a rigid motion expressed in
    tdcm_base (the calibration part's error): published = true * error."""

    name = "registration_error"
    summary = "error of the published mocap -> tdcm_base transform"
    cost_unit = "world"
    params = (
        Param("translation_m", "m", "translation error [x, y, z] in tdcm_base", (0.0, 0.0, 0.0),
              kind="vector", low=-1.0, high=1.0),
        Param("rotation_deg", "deg", "rotation error, roll-pitch-yaw about tdcm_base x, y, z",
              (0.0, 0.0, 0.0), kind="vector", low=-180.0, high=180.0),
    )

    def published(self, pose: Pose) -> Pose:
        with self.timed():
            true_rot = Rotation.from_quat(pose[1])
            error_rot = Rotation.from_euler("xyz", self.values["rotation_deg"], degrees=True)
            translation = pose[0] + true_rot.apply(np.asarray(self.values["translation_m"]))
            return translation, (true_rot * error_rot).as_quat()
