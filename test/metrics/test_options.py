"""``tdcm evaluate/calibrate --set``: the design may be a body file."""

from __future__ import annotations

from pathlib import Path

from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.model import body_file_text, preset


def test_a_body_file_names_the_design_and_fields_override_it(tmp_path: Path) -> None:
    body = tmp_path / "fig2.yaml"
    body.write_text(body_file_text(preset("fig2-wn-1")), encoding="utf-8")
    options = options_from_sets(["E=1.2e9", f"design.preset={body}"])
    assert options.design == preset("fig2-wn-1").with_overrides(E=1.2e9)
