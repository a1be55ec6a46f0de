"""Declare, then finalise: a :class:`~tdcm_ros.scenes.scene.Scene` only declares its effects
(validated values, nothing built); :func:`compile_scene` builds the listed effects of the
chosen stages, in file order, asks each mechanics and actuation effect once for its part, and
merges the parts into a :class:`CompiledScene`: the bundle the world
(:class:`~tdcm_ros.scenes.world.World`) and the device twin's plant run. An effect the scene
does not list is never built, so it costs nothing.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, field
from typing import Any, TypeVar

from tdcm_ros.model import Design, Loading
from tdcm_ros.scenes.effects import REGISTRY, STAGES, Effect, EffectContext, build
from tdcm_ros.scenes.effects.actuation import ActuationEffect
from tdcm_ros.scenes.effects.mechanics import MechanicsEffect
from tdcm_ros.scenes.effects.sensing import SensingEffect
from tdcm_ros.scenes.effects.timing import TimingEffect
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.parts import LoadingPart, PlantPart, merge
from tdcm_ros.scenes.stages import (
    Actuation,
    Mechanics,
    Metered,
    Pose,
    Sensing,
    SolveHistory,
    Timing,
)

#: the stages the world runs (actuation runs in the device twin)
WORLD_STAGES = ("mechanics", "sensing", "timing")

E = TypeVar("E", bound=Effect)


@dataclass(frozen=True)
class Bench:
    """The scene's world without its effects (SI units): the true design, the nominal markers
    (labels, arc lengths in m, centre distance from the midline in m, side in rad around the
    body z axis from the tendon side) and the true pose of tdcm_base in ``mocap``."""

    true_design: Design
    marker_labels: tuple[str, ...]
    marker_arc_lengths: tuple[float, ...]
    marker_radius: float
    marker_side_rad: float
    mocap_pose: Pose = field(repr=False)


@dataclass(frozen=True, eq=False)
class CompiledScene:
    """A scene's bench and its built effects per stage, in file order, with their merged parts:
    ``loading`` (None without mechanics effects: the paper's model), ``plant`` (the fields the
    actuation effects set) and ``histories`` (the state of the stateful mechanics effects)."""

    bench: Bench
    mechanics: tuple[Mechanics, ...]
    actuation: tuple[Actuation, ...]
    sensing: tuple[Sensing, ...]
    timing: tuple[Timing, ...]
    loading: Loading | None
    plant: PlantPart
    histories: tuple[SolveHistory, ...]

    def stage(self, name: str) -> tuple[Metered, ...]:
        """The built effects of stage ``name`` (one of STAGES), in file order."""
        return {"mechanics": self.mechanics, "actuation": self.actuation,
                "sensing": self.sensing, "timing": self.timing}[name]


def compile_scene(bench: Bench, effects: Mapping[str, Mapping[str, Any]], context: EffectContext,
                  stages: Collection[str] = STAGES) -> CompiledScene:
    """Build the ``effects`` (name -> validated values, in file order) of ``stages`` and merge
    their parts. Raises :class:`~tdcm_ros.scenes.errors.EffectConflictError` when two effects
    set one field of the loading or of the plant."""
    for stage in stages:
        if stage not in STAGES:
            raise InvalidSceneError(f"stage {stage!r} unknown; allowed: {', '.join(STAGES)}",
                                    parameter="stage", value=stage, allowed=", ".join(STAGES))

    def listed(stage: str, base: type[E]) -> tuple[E, ...]:
        if stage not in stages:
            return ()
        return tuple(_build(name, values, context, base) for name, values in effects.items()
                     if REGISTRY[name].stage == stage)

    mechanics = listed("mechanics", MechanicsEffect)
    actuation = listed("actuation", ActuationEffect)
    loading_part = merge(LoadingPart, ((e.name, e.loading_part()) for e in mechanics))
    return CompiledScene(
        bench=bench, mechanics=mechanics, actuation=actuation,
        sensing=listed("sensing", SensingEffect), timing=listed("timing", TimingEffect),
        loading=loading_part.loading() if mechanics else None,
        plant=merge(PlantPart, ((e.name, e.plant_part()) for e in actuation)),
        histories=tuple(e.history for e in mechanics if e.history is not None))


def _build(name: str, values: Mapping[str, Any], context: EffectContext, base: type[E]) -> E:
    effect = build(name, values, context)
    if not isinstance(effect, base):
        raise TypeError(f"effect {name!r} of stage {effect.stage!r} is not a {base.__name__}")
    return effect
