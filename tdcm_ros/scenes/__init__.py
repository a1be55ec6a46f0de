"""Scenes: simulated worlds that compute only the effects they list.

Typical use::

    from tdcm_ros.scenes import load_scene
    scene = load_scene("paper_experiment")        # a shipped name or a YAML path
    world = scene.world()
    frame = world.markers(stamp_s=0.0, true_tension=20.0)   # MarkerFrame in `mocap`

A scene declares; ``scene.compile(stages)`` finalises it into a :class:`CompiledScene` (the
listed effects built in file order, their loading and plant parts merged; two effects setting
one field raise :class:`EffectConflictError`). ``scene.world()`` runs the compiled mechanics,
sensing and timing stages; ``scene.plant_config()`` is the device twin's plant with the
actuation stage. ``scene.design`` is the estimator's design, ``scene.true_design`` the world's.
"""

from tdcm_ros.scenes.compiled import CompiledScene
from tdcm_ros.scenes.effects import CONSTRUCTED, REGISTRY, STAGES
from tdcm_ros.scenes.errors import EffectConflictError, InvalidSceneError, SceneError
from tdcm_ros.scenes.explain import explain, format_table
from tdcm_ros.scenes.load import SCENE_NAMES, load_scene, scene_from_text
from tdcm_ros.scenes.params import param_table
from tdcm_ros.scenes.parts import LoadingPart, PlantPart
from tdcm_ros.scenes.paths import shipped_scenes
from tdcm_ros.scenes.scene import Scene
from tdcm_ros.scenes.trajectory import (
    FEEDBACK,
    FEEDFORWARD,
    FEEDFORWARD_LEARNED,
    MODES,
    PHASE_MODES,
    PHASES,
    CircleTrajectory,
    parse_trajectory,
)
from tdcm_ros.scenes.world import MarkerFrame, World

__all__ = ["CONSTRUCTED", "FEEDBACK", "FEEDFORWARD", "FEEDFORWARD_LEARNED", "MODES", "PHASES",
           "PHASE_MODES", "REGISTRY", "SCENE_NAMES", "STAGES",
           "CircleTrajectory", "CompiledScene",
           "EffectConflictError", "InvalidSceneError", "LoadingPart", "MarkerFrame", "PlantPart",
           "Scene", "SceneError", "World", "explain", "format_table", "load_scene", "param_table",
           "parse_trajectory", "scene_from_text", "shipped_scenes"]
