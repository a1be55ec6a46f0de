"""Actuation effects: each returns the part of the device twin's
:class:`~tdcm_ros.device.plant.PlantConfig` it sets (a :class:`~tdcm_ros.scenes.parts.PlantPart`,
SI units; load cell in counts); the twin's plant runs them per sample.

Each parameter is the ``PlantConfig`` field's spec (unit, meaning, default) renamed to its scene
key with the unit in it, its range capped: the plant takes any positive lag or spring, a scene
keeps to a plausible bench so that a slip of a digit is refused rather than simulated.
"""

from __future__ import annotations

from tdcm_ros.device import PLANT_SPECS
from tdcm_ros.scenes.effects.base import Effect, register
from tdcm_ros.scenes.parts import PlantPart
from tdcm_ros.spec import Spec


def _scene_key(field: str, key: str, *, low: float | None = None, high: float | None = None
               ) -> Spec:
    """The plant field's spec as the scene key ``key``, its range narrowed to ``[low, high]``."""
    return PLANT_SPECS[field].renamed(key).narrowed(low=low, high=high)


class ActuationEffect(Effect):
    """Base of the actuation effects (:class:`~tdcm_ros.scenes.stages.Actuation`)."""

    stage = "actuation"
    cost_unit = "plant step"

    def plant_part(self) -> PlantPart:
        """The fields of the twin's ``PlantConfig`` this effect sets."""
        raise NotImplementedError


@register
class ActuatorDynamics(ActuationEffect):
    """The linear actuator's first-order lag, speed limit and backlash deadband."""

    name = "actuator_dynamics"
    summary = "actuator lag, rate limit and deadband"
    params = (
        _scene_key("lag", "lag_s", high=10.0),
        _scene_key("rate", "rate_m_per_s", high=10.0),
        _scene_key("deadband", "deadband_m", high=0.01),
    )

    def plant_part(self) -> PlantPart:
        with self.timed():
            v = self.values
            return PlantPart(lag=v["lag_s"], rate=v["rate_m_per_s"], deadband=v["deadband_m"])


@register
class LoadCell(ActuationEffect):
    """The load cell's Gaussian noise, bias, quantisation and drift."""

    name = "load_cell"
    summary = "load-cell noise, bias, quantisation and drift"
    params = (
        _scene_key("noise", "noise_n", high=10.0),
        _scene_key("bias", "bias_n", low=-10.0, high=10.0),
        _scene_key("quantum", "quantum_counts", high=10000),
        _scene_key("drift", "drift_n_per_s", low=-1.0, high=1.0),
    )

    def plant_part(self) -> PlantPart:
        with self.timed():
            v = self.values
            return PlantPart(noise=v["noise_n"], bias=v["bias_n"], quantum=v["quantum_counts"],
                             drift=v["drift_n_per_s"])


@register
class TendonCompliance(ActuationEffect):
    """The tendon's stretch between actuator and body: slack, then a linear spring."""

    name = "tendon_compliance"
    summary = "tendon stiffness and slack between actuator and body"
    params = (
        _scene_key("stiffness", "stiffness_n_per_m", high=1e7),
        _scene_key("slack", "slack_m", high=0.02),
    )

    def plant_part(self) -> PlantPart:
        with self.timed():
            v = self.values
            return PlantPart(stiffness=v["stiffness_n_per_m"], slack=v["slack_m"])
