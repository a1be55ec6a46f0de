"""The shipped Foxglove layout reads what ``tdcm foxglove`` bridges: every topic a panel names
is a bridged one, and every panel of the layout tree is configured; setup.py installs it."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from tdcm_ros.cli.foxglove import TOPICS

REPO = Path(__file__).resolve().parents[1]
LAYOUT = REPO / "config" / "foxglove" / "tdcm_layout.json"


def leaves(tree: Any) -> list[str]:
    return [tree] if isinstance(tree, str) else leaves(tree["first"]) + leaves(tree["second"])


def test_every_panel_reads_a_bridged_topic() -> None:
    layout = json.loads(LAYOUT.read_text())
    panels = layout["configById"]
    assert sorted(leaves(layout["layout"])) == sorted(panels)
    named = set(panels["3D!tdcm"]["topics"])
    for panel in panels.values():
        named |= {path["value"].split(".")[0] for path in panel.get("paths", [])}
        for key in ("topicToRender", "topicPath"):
            if key in panel:
                named.add(panel[key].split(".")[0])
    assert named <= set(TOPICS), named - set(TOPICS)
    assert {"/midline", "/body_markers", "/tension", "/diagnostics", "/metrics/table"} <= named
    assert panels["3D!tdcm"]["followTf"] == "tdcm_base"


def test_setup_installs_the_layout() -> None:
    assert 'glob("config/foxglove/*.json")' in (REPO / "setup.py").read_text()
