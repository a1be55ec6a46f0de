"""Scenes: simulated worlds that compute only the effects they list.

Typical use::

    from tdcm_ros.scenes import load_scene
    scene = load_scene("paper_experiment")        # a shipped name or a YAML path
    world = scene.world()
    frame = world.markers(stamp_s=0.0, true_tension=20.0)   # MarkerFrame in `mocap`

``scene.design`` is the estimator's design, ``scene.true_design`` the world's;
``scene.plant_config()`` the device twin's plant with the actuation effects.
"""

from tdcm_ros.scenes.effects import CONSTRUCTED, REGISTRY, STAGES
from tdcm_ros.scenes.errors import InvalidSceneError, SceneError
from tdcm_ros.scenes.load import SCENE_NAMES, load_scene, scene_from_text
from tdcm_ros.scenes.scene import Scene
from tdcm_ros.scenes.world import MarkerFrame, World

__all__ = ["CONSTRUCTED", "REGISTRY", "SCENE_NAMES", "STAGES", "InvalidSceneError", "MarkerFrame",
           "Scene", "SceneError", "World", "load_scene", "scene_from_text"]
