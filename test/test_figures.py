"""``tdcm figures`` writes the paper's figures and the feasibility map as real PNG files."""

import pytest

from tdcm_ros.cli.main import main

pytest.importorskip("matplotlib")

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def test_figures_command_writes_non_empty_pngs(tmp_path, capsys):
    out = tmp_path / "figs"
    assert main(["figures", "--out", str(out), "--points", "9", "--dpi", "60"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["feasibility.png", "fig2.png", "fig3.png"]
    for name in names:
        data = (out / name).read_bytes()
        assert data.startswith(PNG_SIGNATURE)
        assert len(data) > 10_000
    printed = capsys.readouterr().out
    assert "3 figures in" in printed and str(out / "fig2.png") in printed


def test_figures_rejects_a_bad_grid_size(tmp_path, capsys):
    assert main(["figures", "--out", str(tmp_path), "--points", "1"]) == 2
    assert "points" in capsys.readouterr().err
