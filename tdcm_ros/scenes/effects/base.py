"""The effect registry and the base class every effect derives from.

An effect is a small class registered by name with :func:`register`; it derives from its
stage's base class (``MechanicsEffect``, ``ActuationEffect``, ``SensingEffect``,
``TimingEffect``), which implements the stage's protocol (:mod:`tdcm_ros.scenes.stages`).
Nothing builds one except :func:`build`, called by the compile step
(:mod:`tdcm_ros.scenes.compiled`) for the effects a scene lists; :data:`CONSTRUCTED` counts
constructions per name so tests can check that an unlisted effect never exists. Each
instance counts its calls and the wall time spent in them (:attr:`Effect.calls`,
:attr:`Effect.time_s`).
"""

from __future__ import annotations

import zlib
from collections import Counter
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from time import perf_counter
from typing import Any, ClassVar

import numpy as np

from tdcm_ros.errors import reject_unknown
from tdcm_ros.model import Design
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.params import Param, parse_params

STAGES = ("mechanics", "actuation", "sensing", "timing")

REGISTRY: dict[str, type[Effect]] = {}
CONSTRUCTED: Counter[str] = Counter()


@dataclass(frozen=True)
class EffectContext:
    """What an effect may know about its scene: the seed, the world's design and material."""

    seed: int
    true_design: Design
    density: float
    marker_arc_lengths: tuple[float, ...]


class Effect:
    """Base of every effect: ``name``, ``stage``, ``params`` and ``cost_unit`` (what one call
    is: ``solve``, ``sample``, ``call``) are class attributes."""

    name: ClassVar[str]
    stage: ClassVar[str]
    summary: ClassVar[str]
    params: ClassVar[tuple[Param, ...]] = ()
    cost_unit: ClassVar[str] = "call"

    @classmethod
    def validate(cls, where: str, values: Mapping[str, Any], context: EffectContext) -> None:
        """Checks across parameters and against the scene (after each value is in range);
        raise :class:`InvalidSceneError` naming the key. None by default."""

    def __init__(self, values: Mapping[str, Any], context: EffectContext) -> None:
        CONSTRUCTED[self.name] += 1
        self.values = dict(values)
        self.context = context
        self.calls = 0
        self.time_s = 0.0
        self.rng = np.random.default_rng([context.seed, zlib.crc32(self.name.encode())])

    @contextmanager
    def timed(self) -> Iterator[None]:
        """Count one call and add its wall time to :attr:`time_s`."""
        started = perf_counter()
        try:
            yield
        finally:
            self.calls += 1
            self.time_s += perf_counter() - started

    @property
    def cost_s(self) -> float:
        """Mean wall time per call (s), 0 before the first call."""
        return self.time_s / self.calls if self.calls else 0.0


def register(cls: type[Effect]) -> type[Effect]:
    """Class decorator: add ``cls`` to :data:`REGISTRY` under ``cls.name``."""
    if cls.stage not in STAGES:
        raise ValueError(f"effect {cls.name!r}: stage {cls.stage!r} not in {STAGES}")
    if cls.name in REGISTRY:
        raise ValueError(f"effect {cls.name!r} registered twice")
    REGISTRY[cls.name] = cls
    return cls


def check_names(effects: Mapping[str, Any]) -> None:
    """Raise :class:`InvalidSceneError` for an effect name that is not registered."""
    reject_unknown("effect", effects, REGISTRY, error=InvalidSceneError)


def parse_effect(name: str, raw: Any, context: EffectContext) -> dict[str, Any]:
    """Validated parameter values of effect ``name`` from its YAML mapping."""
    check_names({name: raw})
    cls = REGISTRY[name]
    values = parse_params(f"effects.{name}", cls.params, raw)
    cls.validate(f"effects.{name}", values, context)
    return values


def build(name: str, values: Mapping[str, Any], context: EffectContext) -> Effect:
    """Construct effect ``name`` from validated values (the only way effects are built)."""
    return REGISTRY[name](values, context)
