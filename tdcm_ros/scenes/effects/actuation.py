"""Actuation effects: each returns the part of the device twin's
:class:`~tdcm_ros.device.plant.PlantConfig` it sets (a :class:`~tdcm_ros.scenes.parts.PlantPart`,
SI units; load cell in counts); the twin's plant runs them per sample."""

from __future__ import annotations

from tdcm_ros.scenes.effects.base import Effect, register
from tdcm_ros.scenes.params import Param
from tdcm_ros.scenes.parts import PlantPart


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
        Param("lag_s", "s", "first-order time constant of the actuator", 0.03, low=0.0,
              low_open=True, high=10.0),
        Param("rate_m_per_s", "m/s", "speed limit of the actuator", 0.025, low=0.0, low_open=True,
              high=10.0),
        Param("deadband_m", "m", "dead zone: the actuator stops this short of its command", 0.0, low=0.0,
              high=0.01),
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
        Param("noise_n", "N", "standard deviation of the reading noise", 0.01, low=0.0,
              high=10.0),
        Param("bias_n", "N", "constant offset of the reading", 0.0, low=-10.0, high=10.0),
        Param("quantum_counts", "counts", "reading resolution (1000 counts per N)", 1,
              kind="int", low=1, high=10000),
        Param("drift_n_per_s", "N/s", "linear drift of the reading", 0.0, low=-1.0, high=1.0),
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
        Param("stiffness_n_per_m", "N/m", "tendon spring rate after the slack is taken up",
              2000.0, low=0.0, low_open=True, high=1e7),
        Param("slack_m", "m", "actuator travel before the tendon carries load", 0.002, low=0.0,
              high=0.02),
    )

    def plant_part(self) -> PlantPart:
        with self.timed():
            v = self.values
            return PlantPart(stiffness=v["stiffness_n_per_m"], slack=v["slack_m"])
