"""A scene: the simulated world (design, true material, bench, sensors, effects) and the
design the estimator uses. :func:`parse_scene` validates a mapping read from YAML.

A scene declares; it builds nothing. :meth:`Scene.compile` finalises it (see
:mod:`tdcm_ros.scenes.compiled`); :meth:`Scene.world` and :meth:`Scene.plant_config` compile
the stages they run, each time afresh (a world's effects keep their own state and seed)."""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from tdcm_ros.device import PlantConfig, StepSchedule
from tdcm_ros.errors import reject_unknown
from tdcm_ros.model import (
    FIELD_SPECS,
    Design,
    is_body_file,
    parse_field,
    preset,
    read_body_file,
)
from tdcm_ros.scenes.compiled import WORLD_STAGES, Bench, CompiledScene, compile_scene
from tdcm_ros.scenes.effects import (
    REGISTRY,
    STAGES,
    EffectContext,
    check_names,
    parse_effect,
)
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.params import Param, as_mapping, parse_params, parse_value
from tdcm_ros.scenes.schema import SECTIONS, TOP_KEYS
from tdcm_ros.scenes.stages import Metered
from tdcm_ros.scenes.trajectory import CircleTrajectory, parse_trajectory
from tdcm_ros.scenes.world import World

Array = NDArray[np.float64]
SEED = Param("seed", "", "random seed", 0, kind="int", low=0, high=2**32 - 1)


@dataclass(frozen=True)
class Scene:
    """A validated scene (SI units). ``effects`` maps each listed effect to its parameter
    values, in file order; nothing else is ever built."""

    name: str
    description: str
    seed: int
    design: Design
    true_design: Design
    density: float
    schedule: StepSchedule
    tension_rate_hz: float
    mocap_rate_hz: float
    marker_labels: tuple[str, ...]
    marker_arc_lengths: tuple[float, ...]
    marker_ball_radius: float
    marker_side_deg: float
    mocap_pose: tuple[Array, Array] = field(repr=False)
    effects: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    source: Path | None = None
    marker_radial_offset: float | None = None
    trajectory: CircleTrajectory | None = None  #: a tip path to follow; None: a staircase scene

    @property
    def marker_radius(self) -> float:
        """Nominal distance of a marker centre from the midline (m): ``markers.radial_offset``
        if given, else ``R_outer`` + ball (on the surface)."""
        if self.marker_radial_offset is not None:
            return self.marker_radial_offset
        return self.design.R_outer + self.marker_ball_radius

    @property
    def marker_side_rad(self) -> float:
        """Nominal marker side around the body z axis from the tendon side (rad)."""
        return math.radians(self.marker_side_deg)

    def context(self) -> EffectContext:
        """What effects may know about this scene."""
        return EffectContext(seed=self.seed, true_design=self.true_design, density=self.density,
                             marker_arc_lengths=self.marker_arc_lengths)

    def effect_names(self, stage: str | None = None) -> tuple[str, ...]:
        """Listed effects, optionally of one stage, in file order."""
        return tuple(n for n in self.effects if stage is None or REGISTRY[n].stage == stage)

    @property
    def bench(self) -> Bench:
        """The world of this scene without its effects."""
        return Bench(true_design=self.true_design, marker_labels=self.marker_labels,
                     marker_arc_lengths=self.marker_arc_lengths,
                     marker_radius=self.marker_radius, marker_side_rad=self.marker_side_rad,
                     mocap_pose=self.mocap_pose)

    def compile(self, stages: Collection[str] = STAGES) -> CompiledScene:
        """Build this scene's effects of ``stages`` (of STAGES) in file order and merge their
        parts; raises :class:`~tdcm_ros.scenes.errors.EffectConflictError` when two effects
        set one field of the loading or of the plant."""
        return compile_scene(self.bench, self.effects, self.context(), stages)

    def build_effects(self, stage: str) -> list[Metered]:
        """Construct this scene's effects of ``stage`` (one of STAGES), in file order."""
        return list(self.compile((stage,)).stage(stage))

    def without(self, *names: str) -> Scene:
        """The same scene without the effects ``names`` (each must be listed)."""
        reject_unknown("listed effect", dict.fromkeys(names), self.effects,
                       error=InvalidSceneError)
        return replace(self, effects={n: v for n, v in self.effects.items() if n not in names})

    def with_nominal_material(self) -> Scene:
        """The same scene with the world's E set to the estimator's (nominal) E."""
        return replace(self, true_design=self.true_design.with_overrides(E=self.design.E))

    def plant_config(self) -> PlantConfig:
        """The device twin's plant: the twin's nominal bench with an exact load cell
        (``noise`` 0), sampled at ``tension_rate_hz``, then the listed actuation effects."""
        nominal = PlantConfig(noise=0.0, sample_period=1.0 / self.tension_rate_hz, seed=self.seed)
        return self.compile(("actuation",)).plant.over(nominal)

    def world(self) -> World:
        """A fresh, seeded simulated world of this scene (its non-actuation stages compiled)."""
        return World(self.compile(WORLD_STAGES))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (SI units)."""
        translation, quaternion = self.mocap_pose
        return {
            "name": self.name, "description": self.description, "seed": self.seed,
            "design": self.design.to_dict(), "true_E": self.true_design.E,
            "density": self.density,
            "schedule": {"levels": list(self.schedule.levels), "hold_s": self.schedule.hold,
                         "trials": self.schedule.trials},
            "tension_rate_hz": self.tension_rate_hz, "mocap_rate_hz": self.mocap_rate_hz,
            "markers": {"labels": list(self.marker_labels),
                        "arc_lengths_m": list(self.marker_arc_lengths),
                        "radius_m": self.marker_radius, "side_deg": self.marker_side_deg},
            "mocap_to_base": {"translation_m": translation.tolist(),
                              "quaternion_xyzw": quaternion.tolist()},
            "effects": {n: {k: list(v) if isinstance(v, tuple) else v for k, v in p.items()}
                        for n, p in self.effects.items()},
            "trajectory": None if self.trajectory is None else self.trajectory.to_dict(),
        }


def parse_scene(data: Any, *, default_name: str, source: Path | None = None) -> Scene:
    """Validate a scene mapping; every error is an :class:`InvalidSceneError` naming the key."""
    data = as_mapping("scene", data)
    reject_unknown("scene key", data, TOP_KEYS, error=InvalidSceneError)
    name = data.get("name", default_name)
    description = data.get("description", "")
    for key, value in (("name", name), ("description", description)):
        if not isinstance(value, str) or (key == "name" and not value):
            raise InvalidSceneError(f"{key} = {value!r} is not a string", parameter=key,
                                    value=value, allowed="a string")
    seed = parse_value("seed", SEED, data.get("seed", 0))
    sections = {key: parse_params(key, specs, data.get(key))
                for key, specs in SECTIONS.items() if key not in ("design", "trajectory")}
    design = _design(data.get("design"), source)
    material = sections["material"]
    true_e = design.E if material["E"] is None else material["E"]
    true_design = design.with_overrides(E=true_e)
    schedule = sections["schedule"]
    markers = sections["markers"]
    _check_markers(markers, design)
    frame = sections["mocap_frame"]
    quaternion = Rotation.from_euler("xyz", frame["rpy_deg"], degrees=True).as_quat()
    scene = Scene(
        name=name, description=description, seed=seed, design=design, true_design=true_design,
        density=material["density"],
        schedule=StepSchedule(levels=schedule["levels"], hold=schedule["hold_s"],
                              trials=schedule["trials"]),
        tension_rate_hz=sections["sensors"]["tension_hz"],
        mocap_rate_hz=sections["sensors"]["mocap_hz"],
        marker_labels=markers["labels"], marker_arc_lengths=markers["arc_lengths"],
        marker_ball_radius=markers["ball_radius"], marker_side_deg=markers["side_deg"],
        mocap_pose=(np.asarray(frame["translation_m"], dtype=float), quaternion),
        source=source, marker_radial_offset=markers["radial_offset"],
        trajectory=parse_trajectory(as_mapping("trajectory", data["trajectory"]))
        if "trajectory" in data else None)
    raw_effects = as_mapping("effects", data.get("effects"))
    check_names(raw_effects)
    context = scene.context()
    effects = {n: parse_effect(n, raw, context) for n, raw in raw_effects.items()}
    return replace(scene, effects=effects)


def _design(raw: Any, source: Path | None) -> Design:
    """The estimator's design: ``preset`` or ``file`` (a body file, relative to the scene
    file's folder), then ``overrides``."""
    data = as_mapping("design", raw)
    reject_unknown("key in design", data, ("preset", "file", "overrides"),
                   error=InvalidSceneError)
    if "preset" in data and "file" in data:
        raise InvalidSceneError("design has both preset and file; allowed: one of them",
                                parameter="design.file", value=data["file"],
                                allowed="design.preset or design.file")
    if "file" in data:
        if not isinstance(data["file"], str) or not is_body_file(data["file"]):
            raise InvalidSceneError(f"design.file = {data['file']!r} is not a body file path; "
                                    "allowed: a .yaml path", parameter="design.file",
                                    value=data["file"], allowed="a .yaml path")
        folder = source.parent if source is not None else Path.cwd()
        base = read_body_file(folder / data["file"]).design()
    else:
        name = parse_params("design", SECTIONS["design"], {"preset": data.get(
            "preset", "paper-experiment")})
        base = preset(name["preset"])
    overrides = dict(as_mapping("design.overrides", data.get("overrides")))
    for key, value in overrides.items():
        if isinstance(value, str) and key in FIELD_SPECS:  # YAML 1.1: 1.85e9 is a string
            overrides[key] = parse_field(key, value)
    return base.with_overrides(**overrides)


def _check_markers(markers: Mapping[str, Any], design: Design) -> None:
    labels, arcs = markers["labels"], markers["arc_lengths"]
    if len(labels) != len(arcs):
        raise InvalidSceneError(
            f"markers.labels has {len(labels)} entries but markers.arc_lengths has {len(arcs)}",
            parameter="markers.labels", value=list(labels), allowed=f"{len(arcs)} labels")
    if max(arcs) > design.length:
        raise InvalidSceneError(
            f"markers.arc_lengths = {list(arcs)!r} is invalid; allowed: within "
            f"(0, {design.length:g}] m (the body length)", parameter="markers.arc_lengths",
            value=list(arcs), allowed=f"(0, {design.length:g}] m")
