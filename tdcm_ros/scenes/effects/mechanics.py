"""Mechanics effects: what the world's solve includes beyond the paper's base model.

Each returns the part of :class:`tdcm_ros.model.loading.Loading` it sets (a
:class:`~tdcm_ros.scenes.parts.LoadingPart`, SI units, frame ``tdcm_base``); compiling a scene
merges the parts of the listed effects only into the world's one ``Loading``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from tdcm_ros.model import FrictionState, StickSlipTension
from tdcm_ros.model import NotchContact as NotchContactLaw
from tdcm_ros.scenes.effects.base import Effect, EffectContext, register
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.params import Param
from tdcm_ros.scenes.parts import LoadingPart
from tdcm_ros.scenes.stages import SolveHistory

G_STANDARD = 9.80665


def planar(where: str, vector: tuple[float, ...]) -> tuple[float, float]:
    """``(x, z)`` of a base-frame vector whose y component is zero (the model is planar)."""
    x, y, z = vector
    if abs(y) > 1e-12 * max(1.0, abs(x), abs(z)):
        raise InvalidSceneError(
            f"{where} = {list(vector)!r} has a y component; the model bends in the x-z plane of "
            "tdcm_base only", parameter=where, value=list(vector), allowed="[x, 0, z]")
    return x, z


class MechanicsEffect(Effect):
    """Base of the mechanics effects (:class:`~tdcm_ros.scenes.stages.Mechanics`): a load on
    the body inside the world's solve. ``history`` is None unless the effect keeps state
    between solves (the world then cannot cache shapes by tension)."""

    stage = "mechanics"
    cost_unit = "solve"
    history: SolveHistory | None = None

    def loading_part(self) -> LoadingPart:
        """The fields of the world's ``Loading`` this effect sets."""
        raise NotImplementedError


@register
class TendonFriction(MechanicsEffect):
    """Capstan friction between tendon and channel, stick-slip with loading/unloading
    hysteresis (see :mod:`tdcm_ros.model.friction`): its ``history`` is the
    :class:`FrictionState`, the profile it hands the model a :class:`StickSlipTension` over it."""

    name = "tendon_friction"
    summary = "capstan tension loss along the tendon, with stick-slip hysteresis"
    params = (Param("mu", "", "capstan friction coefficient tendon/channel", 0.05, low=0.0,
                    high=2.0),)
    history: FrictionState

    def __init__(self, values: Mapping[str, Any], context: EffectContext) -> None:
        super().__init__(values, context)
        self.history = FrictionState()

    def loading_part(self) -> LoadingPart:
        with self.timed():
            return LoadingPart(tension_profile=StickSlipTension(float(self.values["mu"]),
                                                                self.history))


@register
class Gravity(MechanicsEffect):
    """The body's weight: ``density * g`` per unit volume along ``direction`` (tdcm_base)."""

    name = "gravity"
    summary = "body weight, direction in tdcm_base"
    params = (
        Param("direction", "", "gravity direction in tdcm_base (normalised; y must be 0)",
              (0.0, 0.0, -1.0), kind="vector", low=-1e6, high=1e6),
        Param("g", "m/s^2", "gravitational acceleration", G_STANDARD, low=0.0, high=100.0),
    )

    @classmethod
    def validate(cls, where: str, values: Mapping[str, Any], context: EffectContext) -> None:
        x, z = planar(f"{where}.direction", values["direction"])
        if math.hypot(x, z) == 0.0:
            raise InvalidSceneError(f"{where}.direction = [0, 0, 0] has no direction",
                                    parameter=f"{where}.direction", value=[0, 0, 0],
                                    allowed="a non-zero [x, 0, z]")

    def loading_part(self) -> LoadingPart:
        with self.timed():
            x, _, z = self.values["direction"]
            norm = math.hypot(x, z)
            weight = self.context.density * self.values["g"]
            return LoadingPart(body_force_density=(weight * x / norm, weight * z / norm))


@register
class TipLoad(MechanicsEffect):
    """An external force and moment at the tip midline (tdcm_base)."""

    name = "tip_load"
    summary = "external force and moment at the tip"
    params = (
        Param("force_n", "N", "tip force [x, 0, z] in tdcm_base", (0.0, 0.0, 0.0), kind="vector",
              low=-1000.0, high=1000.0),
        Param("moment_nm", "N m", "tip moment about +y", 0.0, low=-100.0, high=100.0),
    )

    @classmethod
    def validate(cls, where: str, values: Mapping[str, Any], context: EffectContext) -> None:
        planar(f"{where}.force_n", values["force_n"])

    def loading_part(self) -> LoadingPart:
        with self.timed():
            x, _, z = self.values["force_n"]
            return LoadingPart(tip_force=(x, z), tip_moment=self.values["moment_nm"])


@register
class NotchContact(MechanicsEffect):
    """Closed notches stiffen (``stiffness_factor * E * I0`` past closure) instead of raising
    the closure error."""

    name = "notch_contact"
    summary = "closed notches stiffen instead of raising the closure error"
    params = (Param("stiffness_factor", "", "closed-notch stiffness / (E I0 of the uncut tube)",
                    1.0, low=0.0, low_open=True, high=1e6),)

    def loading_part(self) -> LoadingPart:
        with self.timed():
            return LoadingPart(notch_contact=NotchContactLaw(self.values["stiffness_factor"]))
