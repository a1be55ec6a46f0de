"""Timing effects: per-topic latency, read by the nodes through ``World.delay_s(topic)``."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from tdcm_ros.scenes.effects.base import Effect, EffectContext, register
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.params import Param

#: topics a latency can be declared for
LATENCY_TOPICS = ("markers", "tension")


class TimingEffect(Effect):
    """Base of the timing effects (:class:`~tdcm_ros.scenes.stages.Timing`)."""

    stage = "timing"
    cost_unit = "message"

    def delay(self, topic: str) -> float:
        """One delay draw (s) for ``topic`` (one of :data:`LATENCY_TOPICS`)."""
        raise NotImplementedError


@register
class Latency(TimingEffect):
    """Delay of each message of a topic: ``mean + jitter * u``, ``u`` uniform in [-1, 1]."""

    name = "latency"
    summary = "per-topic delay with uniform jitter"
    params = tuple(
        Param(f"{topic}{suffix}", "s", f"{what} of the {topic} topic", 0.0, low=0.0, high=10.0)
        for topic in LATENCY_TOPICS
        for suffix, what in (("_s", "mean delay"), ("_jitter_s", "jitter half-width")))

    @classmethod
    def validate(cls, where: str, values: Mapping[str, Any], context: EffectContext) -> None:
        for topic in LATENCY_TOPICS:
            mean, jitter = values[f"{topic}_s"], values[f"{topic}_jitter_s"]
            if jitter > mean:
                raise InvalidSceneError(
                    f"{where}.{topic}_jitter_s = {jitter!r} exceeds {topic}_s = {mean!r}; "
                    f"allowed: [0, {topic}_s] s (a delay is never negative)",
                    parameter=f"{where}.{topic}_jitter_s", value=jitter,
                    allowed=f"[0, {mean:g}] s")

    def delay(self, topic: str) -> float:
        with self.timed():
            mean: float = self.values[f"{topic}_s"]
            jitter: float = self.values[f"{topic}_jitter_s"]
            return mean + jitter * float(self.rng.uniform(-1.0, 1.0)) if jitter else mean
