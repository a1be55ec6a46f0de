"""``tdcm scene``: list, validate, effects and explain (run in-process)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.scenes import REGISTRY


def test_list_names_every_shipped_scene(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scene", "list", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {"ideal", "paper_experiment", "near_singular"} <= set(data)
    assert data["ideal"]["effects"] == []


def test_validate_reports_ok_and_one_line_errors(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scene", "validate", "ideal", "paper_experiment"]) == 0
    assert "paper_experiment: ok" in capsys.readouterr().out
    bad = tmp_path / "bad.yaml"
    bad.write_text("effects: {frition: {}}\n")
    assert main(["scene", "validate", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "unknown effect 'frition'" in err
    assert "tendon_friction" in err


def test_effects_lists_the_registry(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scene", "effects", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data) == set(REGISTRY)
    assert data["tendon_friction"]["stage"] == "mechanics"
    assert data["load_cell"]["params"][0]["unit"] == "N"


def test_explain_ideal_has_no_rows(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scene", "explain", "ideal", "--repeats", "1"]) == 0
    assert "no effects" in capsys.readouterr().out


def test_explain_measures_each_listed_effect(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    scene = tmp_path / "mixed.yaml"
    scene.write_text(
        "schedule: {levels: [0, 10], hold_s: 3.0}\n"
        "effects:\n  tip_load: {force_n: [-0.1, 0, 0]}\n  marker_noise: {std_m: 2.0e-4}\n"
        "  load_cell: {bias_n: 0.5}\n  latency: {markers_s: 0.01}\n")
    assert main(["scene", "explain", str(scene), "--json", "--samples", "300",
                 "--repeats", "1"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["top_tension_n"] == 10.0
    rows = {row["name"]: row for row in report["rows"]}
    assert list(rows) == ["tip_load", "load_cell", "marker_noise", "latency"]
    assert rows["tip_load"]["tip_change_m"] > 1e-4
    # a 0.5 N bias: the loop holds the reading at 10 N, so the body sees ~9.5 N
    assert "9.5" in rows["load_cell"]["note"] and rows["load_cell"]["tip_change_m"] > 1e-4
    assert rows["marker_noise"]["tip_change_m"] == pytest.approx(2e-4 * 3 ** 0.5, rel=0.15)
    assert rows["latency"]["tip_change_m"] is None and "10.00 ms" in rows["latency"]["note"]


def test_explain_rejects_bad_counts(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scene", "explain", "ideal", "--samples", "0"]) == 2
    assert "--samples" in capsys.readouterr().err
