"""``tdcm calibrate`` exit status: a fit that is not usable (not identifiable, not converged) is
not a success; its warnings come before the table."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rec = simulate(preset("paper-experiment").with_overrides(E=0.8e9), levels=(0.0, 5.0, 10.0),
                   hold_s=2.0, trials=1, tension_hz=200.0, mocap_hz=40.0, seed=5)
    return write_recording(rec, tmp_path_factory.mktemp("cal") / "sim")


def test_a_fit_that_is_not_identifiable_exits_3_with_the_warnings_first(
        bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["calibrate", str(bag), "--fit", "E,w_d"]) == 3
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert lines[0].startswith("warning: not identifiable")
    assert "Table I" in captured.out
    assert "tdcm calibrate: the fit is not usable: not identifiable" in captured.err
    assert main(["calibrate", str(bag), "--fit", "E,w_d", "--json"]) == 3
    assert json.loads(capsys.readouterr().out)["identifiable"] is False


def test_an_identifiable_fit_exits_0(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["calibrate", str(bag)]) == 0
    assert not capsys.readouterr().out.startswith("warning")
