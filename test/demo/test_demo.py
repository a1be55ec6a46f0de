"""``tdcm demo`` end to end on a shortened schedule (on zenoh, and on rclpy: marked ``rclpy``),
and its input checks."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.cli.main import main
from tdcm_ros.demo.plan import NODE_ORDER, RECORDED_TOPICS, make_plan
from tdcm_ros.demo.report import missed_holds, scene_options
from tdcm_ros.device.schedule import StepSchedule
from tdcm_ros.errors import InputError
from tdcm_ros.metrics.api import evaluate_paths
from tdcm_ros.metrics.steps import StepSettings
from tdcm_ros.model import named_design, preset
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.registry import NODES
from tdcm_ros.scenes import load_scene

REPO = Path(__file__).resolve().parents[2]
RUNTIMES = ["zenoh", pytest.param("rclpy", marks=pytest.mark.rclpy)]
#: Python packages the demo needs on rclpy: rclpy and the message packages not in the Jazzy
#: wheels (.ci/ros.sh builds them).
RCLPY_NEEDS = ("rclpy", "tf2_msgs.msg", "mocap4r2_msgs.msg")
#: What every demo bag holds, whatever the runtime.
BAG_TYPES = {
    "/tension": "geometry_msgs/msg/WrenchStamped", "/sim/tension_true":
    "geometry_msgs/msg/WrenchStamped", "/markers": "mocap4r2_msgs/msg/Markers",
    "/tf_static": "tf2_msgs/msg/TFMessage", "/tip_pose": "geometry_msgs/msg/PoseStamped",
    "/predicted_markers": "geometry_msgs/msg/PoseArray", "/midline": "nav_msgs/msg/Path",
    "/tendon_states": "sensor_msgs/msg/JointState", "/joint_states": "sensor_msgs/msg/JointState",
    "/device_state": "diagnostic_msgs/msg/DiagnosticStatus",
    "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray"}


def _runtime_env(runtime: str) -> dict[str, str]:
    """Environment of a demo on ``runtime``: rclpy in a private domain on this host only.

    Without rclpy or its message packages the rclpy half is skipped, unless
    ``TDCM_REQUIRE_RCLPY=1`` (CI's ROS step), where that fails (as test/runtime/conftest.py)."""
    if runtime == "zenoh":
        pytest.importorskip("zenoh", reason="eclipse-zenoh not installed")
        return {"TDCM_RUNTIME": "zenoh"}
    for module in RCLPY_NEEDS:
        try:
            importlib.import_module(module)
        except ImportError as error:
            if os.environ.get("TDCM_REQUIRE_RCLPY") == "1":
                pytest.fail(f"TDCM_REQUIRE_RCLPY=1 but {module} is not importable: {error}")
            pytest.skip(f"{module} is not importable; run .ci/ros.sh for the rclpy half")
    return {"TDCM_RUNTIME": "rclpy", "ROS_DOMAIN_ID": str(100 + os.getpid() % 100),
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


def _run_demo(out: Path, *args: str, hold_s: float,
              runtime: str = "zenoh") -> subprocess.CompletedProcess[str]:
    env = {**os.environ, **_runtime_env(runtime), "PYTHONPATH": os.pathsep.join(
        [str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])])}
    env.pop("TDCM_ZENOH_ENDPOINT", None)
    return subprocess.run([sys.executable, "-m", "tdcm_ros", "demo", "--out", str(out),
                           "--trials", "1", "--hold", str(hold_s), "--runtime", runtime, *args],
                          env=env, cwd=REPO, capture_output=True, text=True, timeout=240,
                          check=False)


def _said(done: subprocess.CompletedProcess[str], out: Path) -> str:
    """What a finished demo said, and its driver's and twin's logs: the context of a failed
    check on its results."""
    logs = "".join(f"\n--- {log.name} (end)\n{log.read_text(errors='replace')[-2000:]}"
                   for log in sorted((out / "logs").glob("*.log"))
                   if log.stem in ("tension_driver", "device_twin"))
    return done.stdout[-3000:] + done.stderr[-2000:] + logs


@pytest.mark.demo
@pytest.mark.parametrize("runtime", RUNTIMES)
def test_ideal_scene_demo_gives_a_readable_bag_and_near_zero_metrics(tmp_path: Path,
                                                                     runtime: str) -> None:
    # 1.5 s holds: at 1 s the ideal scene's 4 N level settles too late to be found (the demo warns)
    done = _run_demo(tmp_path / "ideal", "--scene", "ideal", "--no-calibrate", hold_s=1.5,
                     runtime=runtime)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert f"graph up on {runtime}" in done.stdout
    bag = tmp_path / "ideal" / "bag"
    assert sorted(p.name for p in bag.iterdir()) == ["bag_0.mcap", "metadata.yaml"]
    reader = open_bag(bag)
    assert reader.topics == BAG_TYPES and len(BAG_TYPES) == len(RECORDED_TOPICS)
    for topic in BAG_TYPES:
        assert reader.counts[topic] > 0, topic
    assert reader.counts["/tf_static"] == 1
    assert not reader.warnings
    metrics = json.loads((tmp_path / "ideal" / "metrics.json").read_text())["before_calibration"]
    said = _said(done, tmp_path / "ideal")
    assert metrics["n_trials"] == 1, said
    assert metrics["n_steps"] == 6, said
    levels = sorted(round(step["tension_n"]) for step in metrics["steps"])
    assert levels == [0, 4, 8, 12, 16, 20], said
    # The world is the estimator's model: what is left is the load-cell reading versus the true
    # tension inside a hold and the 3-marker spline; both are far below a Vicon's noise.
    assert metrics["rmse_m"] < 2e-5
    assert metrics["mae_m"] < 2e-5
    assert metrics["mape_pct"] < 0.5
    assert metrics["shape_error_m"] < 1e-4
    assert (tmp_path / "ideal" / "plots" / "shapes.png").stat().st_size > 0


def loading_levels(evaluation: dict[str, Any]) -> list[int]:
    """The loading levels (N, rounded) of an evaluation's steps. Besides them, only the release
    to 0 N after the schedule may be a step: the recorder stops ``SETTLE_S`` after the driver's
    ``schedule_done`` reaches the demo (a diagnostics period or less after the schedule ends),
    so that unloading hold lasts about ``min_hold_s`` at 1 s holds and is found in some runs."""
    steps = evaluation["steps"]
    release = [step for step in steps if step["phase"] != "loading"]
    assert len(release) <= 1 and all(round(step["tension_n"]) == 0 for step in release), steps
    return sorted(round(step["tension_n"]) for step in steps if step["phase"] == "loading")


@pytest.mark.demo
def test_paper_scene_demo_calibrates_into_the_papers_range_on_short_holds(tmp_path: Path) -> None:
    """``--hold 1``: the step settings follow the schedule (the defaults' 1 s shortest hold
    found 1 of 6 levels); ``--set`` reaches the evaluation as in ``tdcm evaluate``; the fit of E
    lands in the paper's range."""
    done = _run_demo(tmp_path / "paper", "--scene", "paper_experiment", "--set",
                     "mape_threshold_m=0.002", hold_s=1.0)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "warning: found" not in done.stdout
    results = json.loads((tmp_path / "paper" / "metrics.json").read_text())
    before = results["before_calibration"]
    said = done.stdout[-3000:]  # the bench's holds and the steps found, for a failure
    assert before["n_trials"] == 1 and 6 <= before["n_steps"] <= len(before["steps"]), said
    assert loading_levels(before) == [0, 4, 8, 12, 16, 20], said
    assert before["details"]["mape_threshold_m"] == 0.002
    calibration, after = results["calibration"], results["after_calibration"]
    # each number once: the fit holds no evaluation; the one after it has its own step table
    assert set(results) == {"scene", "before_calibration", "calibration", "after_calibration"}
    assert not {"before", "after"} & set(calibration)
    assert loading_levels(after) == [0, 4, 8, 12, 16, 20]
    # Datasheet E (1.85 GPa) against a 0.70 GPa world: the tip is predicted far too stiff.
    assert before["mape_pct"] > 40.0
    # After fitting E: the paper's Table I range (MAPE 2.51 %, RMSE 0.54 mm, shape 0.85 mm),
    # with margin for a single shortened trial.
    assert after["mape_pct"] < 8.0
    assert after["rmse_m"] < 1e-3
    assert after["shape_error_m"] < 1.5e-3
    fitted = calibration["parameters"]["E"]
    assert fitted["ci_low"] <= fitted["value"] <= fitted["ci_high"]
    assert 0.6e9 < fitted["value"] < 0.9e9
    assert "Table I" in done.stdout
    plots = sorted(p.name for p in (tmp_path / "paper" / "plots").iterdir())
    assert plots == ["calibration.png", "error_vs_tension.png", "shapes.png",
                     "shapes_calibrated.png"]


def test_demo_never_overwrites_a_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "bag").mkdir()
    (tmp_path / "bag" / "keep.mcap").write_bytes(b"recorded")
    assert main(["demo", "--out", str(tmp_path), "--scene", "ideal"]) == 2
    assert "already exists" in capsys.readouterr().err
    assert main(["demo", "--out", str(tmp_path / "x"), "--bag", str(tmp_path / "bag")]) == 2
    assert (tmp_path / "bag" / "keep.mcap").read_bytes() == b"recorded"


def test_demo_refuses_to_record_without_the_evaluated_topics(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--out", str(tmp_path), "--record", "tension,markers"]) == 2
    assert "/tf_static" in capsys.readouterr().err


def test_demo_rejects_an_unknown_scene(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--out", str(tmp_path), "--scene", "no_such_scene"]) == 2
    assert "no_such_scene" in capsys.readouterr().err
    assert not (tmp_path / "bag").exists()


def test_demo_rejects_a_schedule_that_never_tensions(tmp_path: Path) -> None:
    scene = load_scene("ideal")
    plan = make_plan(scene, "ideal", tmp_path, trials=2, hold_s=1.0)
    assert plan.schedule.trials == 2 and plan.schedule.hold == 1.0
    idle = replace(scene, schedule=StepSchedule(levels=(0.0,), hold=1.0, trials=1))
    with pytest.raises(InputError, match="schedule.levels"):
        make_plan(idle, "ideal", tmp_path)


def test_every_demo_node_is_registered_and_configured(tmp_path: Path) -> None:
    plan = make_plan(load_scene("paper_experiment"), "paper_experiment", tmp_path)
    overrides = plan.node_overrides()
    assert set(overrides) == set(NODE_ORDER) <= set(NODES)
    assert overrides["tension_driver"]["port"] == overrides["device_twin"]["link"]
    assert overrides["model_node"]["design.E"] == pytest.approx(1.85e9)
    rectangular = replace(load_scene("paper_experiment"), design=preset(
        "paper-experiment").with_overrides(profile="rectangular"))
    given = make_plan(rectangular, "paper_experiment", tmp_path).node_overrides()
    for node in ("model_node", "metrics_node"):  # the scene's notches, as cut
        assert given[node]["design.profile"] == "rectangular", node


@pytest.mark.parametrize("body", ["graded", "tee_notches.yaml", "tee_mesh.yaml"])
def test_a_per_notch_or_polygon_scene_reaches_the_nodes_as_a_body_file(tmp_path: Path,
                                                                       body: str) -> None:
    """Per-notch values and sections given whole (a uniform polygon body, a mesh) are not
    parameters: the plan writes the scene's design as a body file the nodes read."""
    design = preset("paper-experiment").with_overrides(
        w_d=[1.6e-3, 1.5e-3, 1.4e-3, 1.3e-3, 1.2e-3, 1.1e-3, 1.0e-3, 0.9e-3]) \
        if body == "graded" else named_design(str(REPO / "config" / "bodies" / body))
    scene = replace(load_scene("paper_experiment"), design=design)
    given = make_plan(scene, "paper_experiment", tmp_path).node_overrides()["model_node"]
    assert "design.w_d" not in given and given["design.E"] == design.E
    node = ModelNode(MemoryPort(given, name="model_node"))
    assert node.config.design == design


def test_demo_rejects_a_bad_set_before_the_run(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--out", str(tmp_path / "x"), "--set", "steps.min_hold_s=-1"]) == 2
    err = capsys.readouterr().err
    assert "steps.min_hold_s = '-1' is out of range; allowed: > 0 s" in err
    assert not (tmp_path / "x").exists()


def test_holds_the_evaluation_missed_are_reported(tmp_path: Path) -> None:
    plan = make_plan(load_scene("paper_experiment"), "paper_experiment", tmp_path)
    options = replace(scene_options(plan), steps=StepSettings(min_hold_s=3.9))
    evaluation = evaluate_paths([REPO / "bags" / "paper_experiment"], options)
    found = sum(r.phase == "loading" for r in evaluation.records)
    assert found < 18
    assert missed_holds(plan, evaluation).startswith(f"warning: found {found} of the "
                                                     "schedule's 18 holds")
    assert missed_holds(plan, evaluate_paths([REPO / "bags" / "paper_experiment"],
                                             scene_options(plan))) == ""
