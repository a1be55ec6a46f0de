"""``tdcm evaluate`` over bags simulated with the model: metrics, registration, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tdcm_ros.bagio.writer import BagWriter
from tdcm_ros.cli.main import main
from tdcm_ros.metrics.api import evaluate_paths
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.synthetic_bag import write_recording
from test.metrics.metrics_samples import TRUE_E, small_recording

ISSUE_KEYS = {"mape_pct", "rmse_m", "mae_m", "shape_error_m", "deflection_mean_m", "n_trials",
              "n_steps", "steps"}


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_recording(small_recording(occlusion=0.1),
                           tmp_path_factory.mktemp("bags") / "sim")


def run_json(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict]:
    code = main(["evaluate", *args, "--json"])
    out = capsys.readouterr().out
    return code, json.loads(out)


def _numbers(doc: object, path: str = "") -> dict[str, float]:
    """Every number of a JSON document by its path (lists by index)."""
    if isinstance(doc, dict):
        return {k: v for key, value in doc.items() for k, v in _numbers(value, f"{path}.{key}").items()}
    if isinstance(doc, list):
        return {k: v for i, value in enumerate(doc) for k, v in _numbers(value, f"{path}[{i}]").items()}
    return {path: doc} if isinstance(doc, int | float) and not isinstance(doc, bool) else {}


def test_json_gives_each_table_number_once_and_units_in_the_step_keys(
        bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Table I once (not again in ``details``); each step's quantities with their units in
    the keys; the calibrate document's evaluations each with their own step table."""
    _, doc = run_json(capsys, str(bag), "--set", f"E={TRUE_E}")
    assert not set(doc) & set(doc["details"])
    table = {f".{key}": doc[key] for key in ("mape_pct", "rmse_m", "mae_m", "deflection_mean_m")}
    repeated = [path for path, value in _numbers(doc).items()
                for key, number in table.items() if value == number and path != key]
    assert repeated == []
    step = doc["steps"][0]
    assert {"tension_n", "measured_deflection_m", "predicted_deflection_m", "shape_error_m",
            "start_s", "end_s", "hysteresis_m"} <= set(step)
    assert not {"tension", "measured", "predicted"} & set(step)
    assert main(["calibrate", str(bag), "--json"]) == 0
    calibration = json.loads(capsys.readouterr().out)
    assert len(calibration["after"]["steps"]) == len(calibration["before"]["steps"]) == len(
        doc["steps"])


def test_json_has_the_issue_keys_and_small_errors(bag: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    code, doc = run_json(capsys, str(bag), "--set", f"E={TRUE_E}")
    assert code == 0
    assert ISSUE_KEYS <= set(doc)
    # Table I: 0, 8, 16 twice (loading); the final return to 0 is trial 2's unloading
    assert doc["n_trials"] == 2 and doc["n_steps"] == 6
    assert {"trial", "phase", "tension_n", "measured_deflection_m",
            "predicted_deflection_m"} <= set(doc["steps"][0])
    assert [s["trial"] for s in doc["steps"]] == [1, 1, 1, 2, 2, 2, 2]
    assert [s["phase"] for s in doc["steps"]] == ["loading"] * 6 + ["unloading"]
    assert doc["unloading"]["n_steps"] == 1 and doc["unloading"]["mae_m"] < 2e-5
    # model = truth: only the 0.05 mm marker noise (averaged over ~100 frames) is left
    assert doc["mae_m"] < 2e-5 and doc["rmse_m"] < 2e-5
    assert doc["mape_pct"] < 0.5
    assert doc["shape_error_m"] < 1e-4
    top = [s["measured_deflection_m"] for s in doc["steps"] if abs(s["tension_n"] - 16.0) < 0.5]
    assert doc["deflection_mean_m"] == pytest.approx(np.mean(top))
    assert doc["details"]["sources"][0]["registration"]["method"] == "tf_static"


def test_a_wrong_modulus_shows_in_the_metrics(bag: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    _, right = run_json(capsys, str(bag), "--set", f"E={TRUE_E}")
    _, wrong = run_json(capsys, str(bag), "--set", f"E={1.5 * TRUE_E}")
    # deflection ~ 1/E: the stiffer model under-predicts by about a third
    assert wrong["mape_pct"] > 20.0 > right["mape_pct"]
    assert wrong["rmse_m"] > 100 * right["rmse_m"]


def test_registration_estimated_without_tf_static(tmp_path: Path) -> None:
    rec = small_recording(seed=2)
    path = write_recording(rec, tmp_path / "no_tf", tf_static=False)
    ev = evaluate_paths([path], options_from_sets([f"E={TRUE_E}"]))
    (reg,) = ev.registrations
    assert reg.method == "estimated"
    np.testing.assert_allclose(reg.translation, rec.registration.translation, atol=2e-4)
    assert ev.metrics.rmse_m < 5e-5


def test_text_report_and_plots(bag: Path, tmp_path: Path,
                               capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("matplotlib")
    assert main(["evaluate", str(bag), "--set", f"E={TRUE_E}", "--plots",
                 str(tmp_path / "p")]) == 0
    out = capsys.readouterr().out
    assert "Table I over 2 trials, 6 loading steps" in out and "from /tf_static" in out
    assert "Unloading steps (not in Table I; hysteresis): 1 steps" in out
    assert "measured unloading - loading deflection at the same level" in out
    assert (tmp_path / "p" / "shapes.png").stat().st_size > 1000
    assert (tmp_path / "p" / "error_vs_tension.png").stat().st_size > 1000


def test_two_bags_number_trials_on(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, doc = run_json(capsys, str(bag), str(bag), "--set", f"E={TRUE_E}")
    assert code == 0 and doc["n_trials"] == 4 and doc["n_steps"] == 12  # unloading: 2


def _error(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    code = main(["evaluate", *args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    return err


def test_bad_input_is_one_line(bag: Path, tmp_path: Path,
                               capsys: pytest.CaptureFixture[str]) -> None:
    assert "no topic 'nope'" in _error(capsys, str(bag), "--tension-topic", "nope")
    assert "expected geometry_msgs/msg/WrenchStamped" in _error(
        capsys, str(bag), "--tension-topic", "markers")
    assert "no such bag" in _error(capsys, str(tmp_path / "missing"))
    assert "unknown --set name 'Q'" in _error(capsys, str(bag), "--set", "Q=1")
    assert "not NAME=VALUE" in _error(capsys, str(bag), "--set", "E")


def test_empty_and_truncated_bags(bag: Path, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    with BagWriter(tmp_path / "empty") as writer:
        writer.add_topic("tension", "geometry_msgs/msg/WrenchStamped")
    assert "empty bag" in _error(capsys, str(tmp_path / "empty"))
    mcap = next(bag.glob("*.mcap"))
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(mcap.read_bytes()[:200])
    assert "cut.mcap" in _error(capsys, str(cut))
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"not an mcap file at all")
    assert "garbage.mcap" in _error(capsys, str(garbage))


def test_markers_never_in_view(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = small_recording()
    rec.markers.positions[:, 2] = np.nan  # the tip marker is never seen
    path = write_recording(rec, tmp_path / "hidden")
    err = _error(capsys, str(path))
    assert "m3 never come into view" in err


def test_a_bag_cut_mid_write_is_evaluated_up_to_its_last_chunk(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write_recording(small_recording(trials=3), tmp_path / "whole")
    mcap = next(path.glob("*.mcap"))
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(mcap.read_bytes()[: int(mcap.stat().st_size * 0.8)])
    code, doc = run_json(capsys, str(cut), "--set", f"E={TRUE_E}")
    assert code == 0
    assert 0 < doc["n_steps"] < 10  # the tail of the third trial is lost with the cut
    assert any("truncated" in w or "footer" in w for w in doc["details"]["warnings"])


def test_json_errors_are_json(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, doc = run_json(capsys, str(bag), "--markers-topic", "nope")
    assert code == 2 and doc["error"]["kind"] == "input" and "nope" in doc["error"]["message"]
