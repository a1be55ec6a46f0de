"""Typed partial records: what one effect sets of the world's loading or of the twin's plant.

A mechanics effect returns a :class:`LoadingPart` (fields of
:class:`~tdcm_ros.model.loading.Loading`), an actuation effect a :class:`PlantPart` (fields of
:class:`~tdcm_ros.device.plant.PlantConfig`); same names and SI units as those records, and a
field left ``None`` is not set. :func:`merge` joins the parts of a scene's effects in file
order and raises :class:`~tdcm_ros.scenes.errors.EffectConflictError` when two set one field.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, fields, replace
from typing import Any, ClassVar, TypeVar

from tdcm_ros.device import PlantConfig
from tdcm_ros.model import Loading, NotchContact, TensionProfile
from tdcm_ros.scenes.errors import EffectConflictError


@dataclass(frozen=True)
class Part:
    """Base of the partial records; ``record`` names the record the fields belong to."""

    record: ClassVar[str] = ""

    def set_fields(self) -> dict[str, Any]:
        """The fields this part sets (not ``None``), by name, in declaration order."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        return {name: value for name, value in values.items() if value is not None}


@dataclass(frozen=True)
class LoadingPart(Part):
    """Fields of :class:`~tdcm_ros.model.loading.Loading` one mechanics effect sets."""

    record: ClassVar[str] = "Loading"

    tension_profile: TensionProfile | None = None
    tip_force: tuple[float, float] | None = None
    tip_moment: float | None = None
    body_force_density: tuple[float, float] | None = None
    notch_contact: NotchContact | None = None

    def loading(self) -> Loading:
        """The Loading with these fields, the others at Loading's defaults."""
        return Loading(**self.set_fields())


@dataclass(frozen=True)
class PlantPart(Part):
    """Fields of :class:`~tdcm_ros.device.plant.PlantConfig` one actuation effect sets. The
    load cell's ``sample_period`` and the ``seed`` are the scene's own (``sensors.tension_hz``,
    ``seed``), so no effect sets them."""

    record: ClassVar[str] = "PlantConfig"

    stroke: float | None = None
    lag: float | None = None
    rate: float | None = None
    stiffness: float | None = None
    slack: float | None = None
    counts_per_newton: float | None = None
    tare_counts: int | None = None
    noise: float | None = None
    quantum: int | None = None
    deadband: float | None = None
    bias: float | None = None
    drift: float | None = None

    def over(self, base: PlantConfig) -> PlantConfig:
        """``base`` with these fields replaced (validated by PlantConfig)."""
        return replace(base, **self.set_fields())


P = TypeVar("P", bound=Part)


def merge(kind: type[P], parts: Iterable[tuple[str, P]]) -> P:
    """One ``kind`` holding every field the ``(effect name, part)`` pairs set, taken in order.

    Raises :class:`EffectConflictError` naming the effect that set a field first, the one
    that sets it again, and the field (e.g. ``Loading.tip_force``).
    """
    owners: dict[str, str] = {}
    merged: dict[str, Any] = {}
    for effect, part in parts:
        for name, value in part.set_fields().items():
            if name in owners:
                raise EffectConflictError(owners[name], effect, f"{kind.record}.{name}")
            owners[name] = effect
            merged[name] = value
    return kind(**merged)
