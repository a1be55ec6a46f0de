"""Where shipped scenes live: ``$TDCM_SCENES`` (``os.pathsep`` separated), the source checkout
(``<repo>/config/scenes``), ``<prefix>/share/tdcm_ros/config/scenes`` and, under ROS, the
package's ament share directory. The first directory that has a name wins."""

from __future__ import annotations

from pathlib import Path

from tdcm_ros.resources import resource_dirs

SCENES_ENV = "TDCM_SCENES"
SUFFIXES = (".yaml", ".yml")


def scene_dirs() -> list[Path]:
    """Existing scene directories, in search order."""
    return resource_dirs("config/scenes", SCENES_ENV)


def shipped_scenes() -> dict[str, Path]:
    """Scene name -> file, over :func:`.scene_dirs` (first directory wins), sorted by name."""
    found: dict[str, Path] = {}
    for root in scene_dirs():
        for path in sorted(root.iterdir()):
            if path.suffix in SUFFIXES and path.is_file():
                found.setdefault(path.stem, path)
    return dict(sorted(found.items()))
