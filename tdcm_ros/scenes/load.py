"""Load a scene by shipped name or from a YAML file."""

from __future__ import annotations

from pathlib import Path

from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.paths import SUFFIXES, shipped_scenes
from tdcm_ros.scenes.scene import Scene, parse_scene
from tdcm_ros.spec import spelled_as
from tdcm_ros.yamlio import load_yaml

#: names of the shipped scenes found at import time
SCENE_NAMES: tuple[str, ...] = tuple(shipped_scenes())


def scene_from_text(text: str, *, name: str = "scene", source: Path | None = None) -> Scene:
    """Parse and validate a scene from YAML text (bounded: see :mod:`tdcm_ros.yamlio`);
    ``name`` is used when the file has none."""
    data = load_yaml(text, str(source or name), parameter="file", error=InvalidSceneError)
    return parse_scene(data, default_name=name, source=source)


def load_scene(scene: str | Path) -> Scene:
    """A shipped scene by name (see :data:`SCENE_NAMES`; ``-`` and ``_`` are the same in names:
    ``paper-experiment`` is ``paper_experiment``) or a scene file by path."""
    shipped = shipped_scenes()
    path = Path(scene)
    name = spelled_as(str(scene), shipped)
    if name is not None:
        path = shipped[name]
    elif not (path.suffix in SUFFIXES or path.exists()):
        allowed = ", ".join(shipped) + ", or a path to a .yaml file"
        raise InvalidSceneError(f"unknown scene {str(scene)!r}; allowed: {allowed}",
                                parameter="scene", value=str(scene), allowed=allowed)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or error
        raise InvalidSceneError(f"scene file {str(path)!r} cannot be read: {reason}",
                                parameter="scene", value=str(path),
                                allowed="a readable .yaml file") from error
    return scene_from_text(text, name=path.stem, source=path)
