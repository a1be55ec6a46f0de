"""Where shipped scenes live: ``$TDCM_SCENES`` (``os.pathsep`` separated), the source checkout
(``<repo>/config/scenes``), ``<prefix>/share/tdcm_ros/config/scenes`` and, under ROS, the
package's ament share directory. The first directory that has a name wins."""

from __future__ import annotations

import os
import sys
from pathlib import Path

SCENES_ENV = "TDCM_SCENES"
SUFFIXES = (".yaml", ".yml")


def scene_dirs() -> list[Path]:
    """Existing scene directories, in search order."""
    candidates = [Path(p) for p in os.environ.get(SCENES_ENV, "").split(os.pathsep) if p]
    candidates.append(Path(__file__).resolve().parents[2] / "config" / "scenes")
    candidates.append(Path(sys.prefix) / "share" / "tdcm_ros" / "config" / "scenes")
    candidates.extend(_ament_share())
    return [p for p in candidates if p.is_dir()]


def _ament_share() -> list[Path]:
    try:
        from ament_index_python.packages import (
            PackageNotFoundError,
            get_package_share_directory,
        )
    except ImportError:
        return []
    try:
        return [Path(get_package_share_directory("tdcm_ros")) / "config" / "scenes"]
    except PackageNotFoundError:
        return []


def shipped_scenes() -> dict[str, Path]:
    """Scene name -> file, over :func:`scene_dirs` (first directory wins), sorted by name."""
    found: dict[str, Path] = {}
    for root in scene_dirs():
        for path in sorted(root.iterdir()):
            if path.suffix in SUFFIXES and path.is_file():
                found.setdefault(path.stem, path)
    return dict(sorted(found.items()))
