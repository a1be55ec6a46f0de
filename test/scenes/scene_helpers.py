"""Scene builders shared by the scene tests."""

from __future__ import annotations

from typing import Any

import yaml

from tdcm_ros.scenes import Scene, scene_from_text


def make_scene(effects: dict[str, Any] | None = None, **sections: Any) -> Scene:
    """A scene on the paper's design with ``effects`` and top-level ``sections`` overridden."""
    data: dict[str, Any] = {"name": "test", "seed": 11, "design": {"preset": "paper-experiment"},
                            "mocap_frame": {"translation_m": [0.3, -0.1, 0.2],
                                            "rpy_deg": [10.0, -20.0, 35.0]}}
    data.update(sections)
    data["effects"] = effects or {}
    return scene_from_text(yaml.safe_dump(data, sort_keys=False))
