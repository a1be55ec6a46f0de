"""``tdcm calibrate --fit E,mu --hold-out N --out MODEL`` on a bag of the friction scene, and the
model file it writes used by ``tdcm evaluate``: the band's coverage reported."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import read_model
from tdcm_ros.scenes import load_scene
from test.support.scene_recording import scene_recording

UP_DOWN = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 16.0, 12.0, 8.0, 4.0)


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rec = scene_recording(load_scene("friction_hysteresis"), UP_DOWN, trials=3)
    return write_recording(rec, tmp_path_factory.mktemp("friction") / "bag")


def test_the_fitted_model_file_carries_e_mu_and_their_covariance(
        bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "model.yaml"
    assert main(["calibrate", str(bag), "--fit", "E,mu", "--set", "E=7.7e8", "--hold-out", "1",
                 "--out", str(out), "--json"]) == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert f"wrote the fitted model to {out}" in captured.err
    e, mu = report["parameters"]["E"], report["parameters"]["mu"]
    assert e["ci_low"] <= 7.0e8 <= e["ci_high"] and mu["ci_low"] <= 0.3 <= mu["ci_high"]
    held = report["held_out"]
    # 3 trials of 10 steps and the closing zero hold (trial 3's): 20 steps fitted, 11 held out
    assert held["n_trials"] == 1 and held["band"]["markers"] == 3 * 11
    assert report["after"]["band"]["markers"] == 3 * 20 and report["notes"] == []
    model = read_model(str(out))
    assert model.design.E == e["value"] and model.friction_mu == mu["value"]
    assert model.uncertainty is not None and model.uncertainty.names == ("E", "mu")
    assert model.uncertainty.std[1] == pytest.approx(mu["std"], rel=1e-12)


def test_evaluate_with_the_model_file_reports_the_band(
        bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "model.yaml"
    assert main(["calibrate", str(bag), "--fit", "E,mu", "--out", str(out)]) == 0
    assert "fitted steps: 95 % band" in capsys.readouterr().out
    assert main(["evaluate", str(bag), "--design", str(out)]) == 0
    text = capsys.readouterr().out
    assert "95 % band (the fit's covariance and residual):" in text and "of 93 measured" in text
    assert main(["evaluate", str(bag), "--design", str(out), "--json"]) == 0
    band = json.loads(capsys.readouterr().out)["band"]
    assert band["confidence"] == 0.95 and band["markers"] == 93
    assert main(["evaluate", str(bag)]) == 0  # no model file: no band
    assert "95 % band" not in capsys.readouterr().out


@pytest.mark.parametrize(("extra", "parameter"), [
    (["--hold-out", "3"], "--hold-out"), (["--hold-out", "-1"], "--hold-out"),
    (["--out", "/nonexistent/dir/model.yaml"], "--out"), (["--fit", "E,nu"], "--fit")])
def test_bad_options_exit_2_naming_the_option(bag: Path, capsys: pytest.CaptureFixture[str],
                                              extra: list[str], parameter: str) -> None:
    assert main(["calibrate", str(bag), *extra]) == 2
    err = capsys.readouterr().err
    assert parameter in err and "Traceback" not in err
