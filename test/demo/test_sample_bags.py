"""The simulated sample bags in ``bags/`` stay readable and evaluate to the paper's protocol."""

from __future__ import annotations

from pathlib import Path

from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.demo.plan import make_plan
from tdcm_ros.demo.report import scene_options
from tdcm_ros.metrics.api import evaluate_paths
from tdcm_ros.scenes import load_scene

BAGS = Path(__file__).resolve().parents[2] / "bags"


def test_paper_experiment_sample_bag_holds_three_staircases(tmp_path: Path) -> None:
    bag = BAGS / "paper_experiment"
    reader = open_bag(bag)
    assert set(reader.topics) == {"/tension", "/sim/tension_true", "/markers", "/tf_static"}
    assert not reader.warnings
    plan = make_plan(load_scene("paper_experiment"), "paper_experiment", tmp_path)
    evaluation = evaluate_paths([bag], scene_options(plan))
    doc = evaluation.to_json()
    assert (doc["n_trials"], doc["n_steps"]) == (3, 18)
    assert sorted({round(step["tension_n"]) for step in doc["steps"]}) == [0, 4, 8, 12, 16, 20]
    # Recorded from a 0.70 GPa world, evaluated with the datasheet's 1.85 GPa: far too stiff.
    assert all(step["predicted_deflection_m"] < step["measured_deflection_m"]
               for step in doc["steps"] if step["tension_n"] > 1.0)
    assert 0.015 < doc["deflection_mean_m"] < 0.0175
