"""Mechanics effects: what the world's solve includes beyond the paper's base model.

Each contributes fields of :class:`tdcm_ros.model.loading.Loading` (SI units, frame
``tdcm_base``); the world builds one ``Loading`` from the listed effects only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.loading import NotchContact as NotchContactLaw
from tdcm_ros.scenes.effects.base import Effect, EffectContext, register
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.params import Param

Array = NDArray[np.float64]
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
    """A load on the body inside the world's solve; ``stateful`` ones keep history between
    solves (the world then cannot cache shapes by tension)."""

    stage = "mechanics"
    cost_unit = "solve"
    stateful: ClassVar[bool] = False

    def contribute(self, loading: dict[str, Any]) -> None:
        """Set this effect's fields of the ``Loading`` keyword arguments."""
        raise NotImplementedError

    def commit(self) -> None:
        """The last solve converged and is the world's new state (stateful effects only)."""


@register
class TendonFriction(MechanicsEffect):
    """Capstan friction between tendon and channel, stick-slip with loading/unloading hysteresis.

    Where the tendon slips, the tension obeys the capstan law ``|dT/dw| = mu T`` against the
    motion: pulled in (loading) it falls toward the tip, ``T_base exp(-mu w)``; paid out
    (unloading) it rises, ``T_base exp(mu w)``, with ``w`` the tendon's turning from the base.
    Where it sticks, the tension keeps its previous value. Both together: the new profile is
    the previous one clipped to ``[T_base exp(-mu w), T_base exp(mu w)]`` (a play operator per
    point), which starts from a slack tendon. The stuck state is kept per node (the solver asks
    for the tension just before and just after each kink; the state is the latter), so a stuck
    kink carries no friction jump: an error of about ``mu`` times the kink's turning.
    """

    name = "tendon_friction"
    summary = "capstan tension loss along the tendon, with stick-slip hysteresis"
    stateful = True
    params = (Param("mu", "", "capstan friction coefficient tendon/channel", 0.05, low=0.0,
                    high=2.0),)

    def __init__(self, values: Mapping[str, Any], context: EffectContext) -> None:
        super().__init__(values, context)
        self.mu = float(self.values["mu"])
        self._state: tuple[Array, Array] | None = None
        self._pending: tuple[Array, Array] | None = None

    def contribute(self, loading: dict[str, Any]) -> None:
        loading["tension_profile"] = self

    def __call__(self, s: Array, wrap_angle: Array, tension_base: float) -> Array:
        """Tension at each node (N) for base tension ``tension_base`` (N)."""
        with self.timed():
            low = tension_base * np.exp(-self.mu * wrap_angle)
            high = tension_base * np.exp(self.mu * wrap_angle)
            out = np.clip(self._previous(s), low, high)
            self._pending = (np.array(s, dtype=float), out)
            return out

    def _previous(self, s: Array) -> Array:
        if self._state is None:
            return np.zeros_like(s, dtype=float)
        s_prev, t_prev = self._state
        if s_prev.shape == np.shape(s) and np.array_equal(s_prev, s):
            return t_prev
        return np.interp(s, s_prev, t_prev)

    def commit(self) -> None:
        if self._pending is not None:
            self._state = self._pending

    @property
    def tension_along(self) -> tuple[Array, Array] | None:
        """``(s, T)`` of the last committed solve, or ``None`` before the first."""
        return self._state


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

    def contribute(self, loading: dict[str, Any]) -> None:
        with self.timed():
            x, _, z = self.values["direction"]
            norm = math.hypot(x, z)
            weight = self.context.density * self.values["g"]
            loading["body_force_density"] = (weight * x / norm, weight * z / norm)


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

    def contribute(self, loading: dict[str, Any]) -> None:
        with self.timed():
            x, _, z = self.values["force_n"]
            loading["tip_force"] = (x, z)
            loading["tip_moment"] = self.values["moment_nm"]


@register
class NotchContact(MechanicsEffect):
    """Closed notches stiffen (``stiffness_factor * E * I0`` past closure) instead of raising
    the closure error."""

    name = "notch_contact"
    summary = "closed notches stiffen instead of raising the closure error"
    params = (Param("stiffness_factor", "", "closed-notch stiffness / (E I0 of the uncut tube)",
                    1.0, low=0.0, low_open=True, high=1e6),)

    def contribute(self, loading: dict[str, Any]) -> None:
        with self.timed():
            loading["notch_contact"] = NotchContactLaw(self.values["stiffness_factor"])
