"""Actuation effects: they set fields of the device twin's
:class:`~tdcm_ros.device.plant.PlantConfig` (SI units; load cell in counts)."""

from __future__ import annotations

from typing import Any, ClassVar

from tdcm_ros.scenes.effects.base import Effect, register
from tdcm_ros.scenes.params import Param


class ActuationEffect(Effect):
    """Maps its parameters onto PlantConfig fields; the twin's plant runs them per sample."""

    stage = "actuation"
    cost_unit = "plant step"
    #: scene parameter -> PlantConfig field
    fields: ClassVar[dict[str, str]] = {}

    def apply(self, plant: dict[str, Any]) -> None:
        """Write this effect's values into the PlantConfig keyword arguments ``plant``."""
        with self.timed():
            for param, field in self.fields.items():
                plant[field] = self.values[param]


@register
class ActuatorDynamics(ActuationEffect):
    """The linear actuator's first-order lag, speed limit and backlash deadband."""

    name = "actuator_dynamics"
    summary = "actuator lag, rate limit and deadband"
    params = (
        Param("lag_s", "s", "first-order time constant of the actuator", 0.03, low=0.0,
              low_open=True, high=10.0),
        Param("rate_m_per_s", "m/s", "speed limit of the actuator", 0.025, low=0.0, low_open=True,
              high=10.0),
        Param("deadband_m", "m", "dead zone: the actuator stops this short of its command", 0.0, low=0.0,
              high=0.01),
    )
    fields: ClassVar[dict[str, str]] = {"lag_s": "lag", "rate_m_per_s": "rate", "deadband_m": "deadband"}


@register
class LoadCell(ActuationEffect):
    """The load cell's Gaussian noise, bias, quantisation and drift."""

    name = "load_cell"
    summary = "load-cell noise, bias, quantisation and drift"
    params = (
        Param("noise_n", "N", "standard deviation of the reading noise", 0.01, low=0.0,
              high=10.0),
        Param("bias_n", "N", "constant offset of the reading", 0.0, low=-10.0, high=10.0),
        Param("quantum_counts", "counts", "reading resolution (1000 counts per N)", 1,
              kind="int", low=1, high=10000),
        Param("drift_n_per_s", "N/s", "linear drift of the reading", 0.0, low=-1.0, high=1.0),
    )
    fields: ClassVar[dict[str, str]] = {"noise_n": "noise", "bias_n": "bias", "quantum_counts": "quantum",
              "drift_n_per_s": "drift"}


@register
class TendonCompliance(ActuationEffect):
    """The tendon's stretch between actuator and body: slack, then a linear spring."""

    name = "tendon_compliance"
    summary = "tendon stiffness and slack between actuator and body"
    params = (
        Param("stiffness_n_per_m", "N/m", "tendon spring rate after the slack is taken up",
              2000.0, low=0.0, low_open=True, high=1e7),
        Param("slack_m", "m", "actuator travel before the tendon carries load", 0.002, low=0.0,
              high=0.02),
    )
    fields: ClassVar[dict[str, str]] = {"stiffness_n_per_m": "stiffness", "slack_m": "slack"}
