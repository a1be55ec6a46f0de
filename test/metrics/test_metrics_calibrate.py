"""``tdcm calibrate``: a known E is recovered within the reported interval; identifiability."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.metrics.api import calibrate_paths
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset

TRUE_E = 0.8e9


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rec = simulate(preset("paper-experiment").with_overrides(E=TRUE_E),
                   levels=(0.0, 5.0, 10.0, 15.0), hold_s=2.0, trials=2, tension_hz=200.0,
                   mocap_hz=40.0, marker_noise_m=2e-4, occlusion=0.05, seed=11)
    return write_recording(rec, tmp_path_factory.mktemp("cal") / "sim")


def test_known_modulus_is_within_the_reported_interval(bag: Path,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    assert main(["calibrate", str(bag), "--json"]) == 0  # starts from the preset's 1.85 GPa
    doc = json.loads(capsys.readouterr().out)
    e = doc["parameters"]["E"]
    assert e["initial"] == pytest.approx(1.85e9)
    assert e["ci_low"] < TRUE_E < e["ci_high"]
    assert e["ci_high"] - e["ci_low"] < 0.05 * TRUE_E  # the data pin E down to a few percent
    assert doc["identifiable"] is True and doc["warnings"] == []
    assert doc["after"]["rmse_m"] < 0.1 * doc["before"]["rmse_m"]
    assert doc["after"]["mape_pct"] < doc["before"]["mape_pct"]


def test_correlated_parameters_are_reported_not_identifiable(bag: Path) -> None:
    cal = calibrate_paths([bag], ["E", "w_d"], options_from_sets([]))
    assert not cal.identifiable
    assert any("E and w_d are correlated" in w for w in cal.warnings)


def test_text_output_and_bad_fit_names(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["calibrate", str(bag), "--set", "E=1e9"]) == 0
    out = capsys.readouterr().out
    assert "E = " in out and "95% interval" in out and "before" in out
    for fit, message in (("N", "neither a real-valued design field nor mu"), ("E,E", "distinct names"),
                         ("Young", "neither a real-valued design field nor mu")):
        assert main(["calibrate", str(bag), "--fit", fit]) == 2
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err
