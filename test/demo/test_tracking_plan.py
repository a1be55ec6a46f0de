"""The tracking demo's plan and its live loop (:func:`follow`) against a fake graph: the nodes
it starts, what it records, the options it refuses, the targets it publishes in real time and
the controller modes it sets at lap starts."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.demo.follow import follow
from tdcm_ros.demo.plan import (
    NODE_ORDER,
    RECORDED_TOPICS,
    TRACKING_NODE_ORDER,
    TRACKING_TOPICS,
    make_plan,
)
from tdcm_ros.demo.tracking_report import LAP_TOPIC, REPORTED_TOPICS, TARGET_TOPIC
from tdcm_ros.demo.trajectory import tip_trajectory
from tdcm_ros.errors import InputError
from tdcm_ros.nodes import shape_controller
from tdcm_ros.runtime import RuntimePortError
from tdcm_ros.runtime.param_services import from_value
from tdcm_ros.runtime.registry import NODES
from tdcm_ros.scenes import load_scene
from tdcm_ros.scenes.trajectory import FEEDBACK, FEEDFORWARD, parse_trajectory


def test_a_tracking_scene_starts_the_controller_and_records_what_the_report_reads(
        tmp_path: Path) -> None:
    plan = make_plan(load_scene("tracking"), "tracking", tmp_path)
    assert plan.targets is not None
    assert plan.node_order == TRACKING_NODE_ORDER
    assert "metrics_node" not in plan.node_order and "shape_controller" in plan.node_order
    overrides = plan.node_overrides()
    assert list(overrides) == list(TRACKING_NODE_ORDER)
    assert overrides["shape_controller"]["mode"] == FEEDFORWARD
    assert set(overrides["shape_controller"]) <= set(shape_controller.PARAMETERS)
    assert set(plan.node_order) <= set(NODES)
    assert overrides["shape_controller"]["design.E"] == pytest.approx(plan.scene.design.E)
    assert overrides["tension_driver"]["port"] == overrides["device_twin"]["link"]
    assert plan.recorded_topics == TRACKING_TOPICS
    assert set(REPORTED_TOPICS) <= set(plan.recorded_topics)


def test_a_staircase_scene_plans_as_before(tmp_path: Path) -> None:
    plan = make_plan(load_scene("paper_experiment"), "paper_experiment", tmp_path)
    assert plan.targets is None
    assert plan.node_order == NODE_ORDER and plan.recorded_topics == RECORDED_TOPICS


def test_a_tracking_run_refuses_to_record_without_the_reported_topics(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="controller/measured_tip"):
        make_plan(load_scene("tracking"), "tracking", tmp_path,
                  recorded_topics=("tension", "markers", "/tf_static"))


@pytest.mark.parametrize("option", [["--trials", "1"], ["--hold", "2"], ["--set", "x=1"]])
def test_staircase_options_are_refused_for_a_tracking_scene(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], option: list[str]) -> None:
    assert main(["demo", "--scene", "tracking", "--out", str(tmp_path / "x"), *option]) == 2
    assert f"{option[0]} applies to a scene's tension schedule" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


class FakeGraph:
    """The demo's port and context: publishers that keep what they send (with the time) and
    parameter services that accept (or refuse) every ``set``."""

    def __init__(self, refuse: str = "") -> None:
        self.sent: list[tuple[str, float, Any]] = []
        self.modes: list[tuple[float, str]] = []
        self.refuse = refuse

    def create_publisher(self, topic: str, type_name: str) -> Any:
        return SimpleNamespace(publish=lambda message: self.sent.append(
            (topic, time.monotonic(), message)))

    def create_subscription(self, *args: Any) -> None:
        return None

    def now_ns(self) -> int:
        return time.time_ns()

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = 5.0) -> Any:
        assert name == "/shape_controller/set_parameters"
        parameter = request.parameters[0]
        assert parameter.name == "mode"
        value = from_value(parameter.value)
        self.modes.append((time.monotonic(), value))
        ok = value != self.refuse
        return SimpleNamespace(results=[SimpleNamespace(successful=ok,
                                                        reason="" if ok else "no estimate")])


def _sleep(deadline: float, late: Callable[[], str], seconds: float) -> None:
    assert time.monotonic() <= deadline, late()
    time.sleep(seconds)


def test_follow_publishes_the_targets_in_real_time_and_switches_mode_at_lap_starts() -> None:
    circle = parse_trajectory({"centre_m": [0.009, 0.0], "radius_m": 0.003, "period_s": 1.0,
                               "approach_s": 0.5, "feedforward_laps": 1, "feedback_laps": 1,
                               "settle_s": 0.2, "rate_hz": 20.0})
    targets = tip_trajectory(circle, load_scene("tracking").design, tension_max=20.0)
    graph = FakeGraph()
    started = time.monotonic()
    follow(targets, graph, graph, _sleep, say=lambda line: None, progress_period=10.0,
           margin_s=5.0)
    assert time.monotonic() - started == pytest.approx(circle.duration, abs=0.3)
    points = [(t - started, m) for topic, t, m in graph.sent if topic == TARGET_TOPIC]
    laps = [m.data for topic, _, m in graph.sent if topic == LAP_TOPIC]
    assert len(points) == len(laps) == pytest.approx(circle.duration * circle.rate, abs=3)
    assert laps == sorted(laps) and set(laps) == {0, 1, 2}
    for elapsed, message in points:
        assert message.header.frame_id == "tdcm_base"
        x, y, z = message.point.x, message.point.y, message.point.z
        assert math.hypot(x - 0.009, y) == pytest.approx(0.003, rel=1e-9)
        # published where the circle is at that moment (within the loop's timing)
        expected = targets.point(elapsed)
        assert np.linalg.norm(np.subtract((x, y, z), expected)) < 0.003 * 2 * math.pi * 0.05
    assert [mode for _, mode in graph.modes] == [FEEDFORWARD, FEEDBACK]
    switched = graph.modes[1][0] - started
    assert switched == pytest.approx(circle.approach + circle.period, abs=0.1)
    first_feedback_lap = next(t for topic, t, m in graph.sent
                              if topic == LAP_TOPIC and m.data == 2) - started
    assert switched <= first_feedback_lap


def test_a_refused_mode_ends_the_run_with_the_controllers_reason() -> None:
    circle = parse_trajectory({"period_s": 1.0, "approach_s": 0.1, "settle_s": 0.1})
    targets = tip_trajectory(circle, load_scene("tracking").design, tension_max=20.0)
    with pytest.raises(RuntimePortError, match="refused mode = 'feedback': no estimate"):
        follow(targets, FakeGraph(refuse=FEEDBACK), FakeGraph(), _sleep, say=lambda line: None,
               progress_period=10.0, margin_s=5.0)


def test_follow_switches_back_to_feedforward_for_the_learned_laps() -> None:
    circle = parse_trajectory({"centre_m": [0.009, 0.0], "radius_m": 0.003, "period_s": 1.0,
                               "approach_s": 0.3, "feedforward_laps": 1, "feedback_laps": 1,
                               "learned_feedforward_laps": 1, "settle_s": 0.1,
                               "rate_hz": 20.0})
    targets = tip_trajectory(circle, load_scene("tracking").design, tension_max=20.0)
    graph = FakeGraph()
    said: list[str] = []
    started = time.monotonic()
    follow(targets, graph, graph, _sleep, say=said.append, progress_period=10.0, margin_s=5.0)
    assert [mode for _, mode in graph.modes] == [FEEDFORWARD, FEEDBACK, FEEDFORWARD]
    back = graph.modes[2][0] - started
    assert back == pytest.approx(circle.approach + 2 * circle.period, abs=0.1)
    laps = [(t, m.data) for topic, t, m in graph.sent if topic == LAP_TOPIC]
    assert [lap for _, lap in laps] == sorted(lap for _, lap in laps)
    assert {lap for _, lap in laps} == {0, 1, 2, 3}
    assert graph.modes[2][0] <= next(t for t, lap in laps if lap == 3)
    assert any("controller mode -> feedforward (feedforward_learned phase)" in line
               for line in said)
