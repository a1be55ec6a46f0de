"""``tdcm demo --scene tracking`` end to end on a shortened circle, on zenoh: the shape
controller on the device twin with simulated motion capture, in a world whose E is not the
model's. Feedback must correct the model to the measured tip, the controller must keep the gain
feedback learned (the world's) through the last feed-forward lap, and metrics.json must hold
what the bag gives. How close the live tip comes
to the moving target is the graph's latency, i.e. the machine's load: the controller's
accuracy against the target is checked on simulated time in test/control/test_closed_loop.py.

On rclpy the same graph runs in test_demo.py (the ideal scene) and the controller's feedback loop
in test/nodes/test_shape_controller_node.py; the scene itself is runtime-neutral (the demo's
follow loop and phase switches run on simulated time in test_tracking_plan.py), so its 60-70 s
run is not repeated there."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.demo.tracking_report import REPORTED_TOPICS, phase_errors, read_tracking
from tdcm_ros.scenes import load_scene
from tdcm_ros.scenes.paths import shipped_scenes
from tdcm_ros.scenes.trajectory import FEEDBACK, FEEDFORWARD, FEEDFORWARD_LEARNED
from test.demo.test_demo import _runtime_env

REPO = Path(__file__).resolve().parents[2]
#: The shipped scene, four 10 s laps (one feed-forward, two feedback, one feed-forward with the
#: learned gain) after a 2 s approach.
SHORT = {"period_s": 10.0, "approach_s": 2.0, "feedforward_laps": 1, "feedback_laps": 2,
         "learned_feedforward_laps": 1, "settle_s": 4.0}


def _short_scene(folder: Path) -> Path:
    data = yaml.safe_load(shipped_scenes()["tracking"].read_text(encoding="utf-8"))
    data["trajectory"].update(SHORT)
    data["name"] = "tracking_short"
    path = folder / "tracking_short.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


@pytest.mark.demo
def test_feedback_learns_the_world_and_feed_forward_keeps_what_it_learned(tmp_path: Path
                                                                         ) -> None:
    runtime = "zenoh"
    scene_path = _short_scene(tmp_path)
    env = {**os.environ, **_runtime_env(runtime), "PYTHONPATH": os.pathsep.join(
        [str(REPO), *filter(None, [os.environ.get("PYTHONPATH")])])}
    env.pop("TDCM_ZENOH_ENDPOINT", None)
    out = tmp_path / "run"
    done = subprocess.run([sys.executable, "-m", "tdcm_ros", "demo", "--scene", str(scene_path),
                           "--out", str(out), "--runtime", runtime], env=env, cwd=REPO, capture_output=True, text=True,
                          timeout=300, check=False)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert f"graph up on {runtime}" in done.stdout
    assert "controller mode -> feedback" in done.stdout
    bag = open_bag(out / "bag")
    for topic in REPORTED_TOPICS:
        assert bag.counts["/" + topic] > 0, topic
    circle = load_scene(str(scene_path)).trajectory
    assert circle is not None
    results = json.loads((out / "metrics.json").read_text())["tracking"]
    # the numbers written are the ones the bag gives
    recomputed = {e.phase: e.to_json() for e in phase_errors(read_tracking(out / "bag"), circle)}
    assert results == json.loads(json.dumps(recomputed))
    feedforward, feedback = results[FEEDFORWARD], results[FEEDBACK]
    assert feedback["samples"] > 100 and feedforward["samples"] > 100
    # the model's E is 10 % too stiff: feed-forward alone misses by most of a millimetre, and
    # its model does not explain the measured tip; with the stiffness the feedback estimates, it
    # does. (The feedback laps' tip vs target is the live commands' lag behind the circle: 0.64
    # mm quiet, 1.45 mm beside a compile, against feed-forward's 0.98 mm, so not asserted here.)
    said = done.stdout[-3000:]  # the phases' errors and the controller's final gain
    assert 0.5e-3 < feedforward["rmse_m"], said
    assert feedback["model_rmse_m"] < 0.5 * feedforward["model_rmse_m"], said
    # back in feed-forward, the controller keeps the gain it learned: the feed-forward improved
    assert "controller mode -> feedforward (feedforward_learned phase)" in done.stdout
    learned = results[FEEDFORWARD_LEARNED]
    assert learned["mode"] == FEEDFORWARD and learned["samples"] > 100
    # the gain kept to the end (after the learned lap) is the world's, within 2 % (1.1043 and
    # 1.1059 seen for 1.1057; 1.0, the model's own, if it had been reset). How well the model
    # explains the tip in a feed-forward lap depends on the live lag behind the commands: 0.16
    # mm quiet, 0.62 mm beside a CPU hog against feed-forward's 1.0 mm, so it is not asserted.
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["final_gain"] == pytest.approx(metrics["world_gain"], rel=0.02), said
    for name in ("tracking_paths.png", "tracking_error.png"):
        assert (out / "plots" / name).stat().st_size > 0
