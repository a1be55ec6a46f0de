"""The tracking demo's plan and its live loop (:func:`follow`) against a fake graph: the nodes
it starts, what it records, the options it refuses; on a :class:`MemoryPort`'s simulated time,
the exact times it publishes the targets at and the controller modes it sets at lap starts."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict
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
from tdcm_ros.demo.trajectory import TipTrajectory, tip_trajectory
from tdcm_ros.errors import InputError
from tdcm_ros.nodes import shape_controller
from tdcm_ros.runtime import RuntimePortError
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.param_services import from_value
from tdcm_ros.runtime.registry import NODES
from tdcm_ros.scenes import load_scene
from tdcm_ros.scenes.trajectory import (
    FEEDBACK,
    FEEDFORWARD,
    CircleTrajectory,
    parse_trajectory,
)


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


class Graph:
    """The demo's port and context on simulated time: a :class:`MemoryPort` (its clock starts at
    0 ns and is the loop's clock; it keeps what is published, with the time) standing in for
    the shape controller's ``set_parameters``, which records each mode with its time and
    accepts it unless it is ``refuse``."""

    def __init__(self, refuse: str = "") -> None:
        self.port = MemoryPort(name="_tdcm_demo", start_ns=0)
        self.modes: list[tuple[int, str]] = []
        self.refuse = refuse
        self.port.add_remote_service("/shape_controller/set_parameters",
                                     "rcl_interfaces/srv/SetParameters", self.set_parameters)

    def set_parameters(self, request: Any) -> Any:
        (parameter,) = request.parameters
        assert parameter.name == "mode"
        value = from_value(parameter.value)
        self.modes.append((self.port.now_ns(), value))
        ok = value != self.refuse
        return from_dict("rcl_interfaces/srv/SetParameters_Response", {"results": [
            {"successful": ok, "reason": "" if ok else "no estimate"}]})

    def turn(self, deadline: float, late: Callable[[], str], seconds: float) -> None:
        """The demo's wait: fail past ``deadline``, else move the clock ``seconds``."""
        assert self.port.now_ns() / 1e9 <= deadline, late()
        self.port.advance(seconds)

    def follow(self, circle: CircleTrajectory, say: Callable[[str], None] = lambda line: None,
               progress_period: float = 10.0) -> TipTrajectory:
        targets = tip_trajectory(circle, load_scene("tracking").design, tension_max=20.0)
        follow(targets, self.port, self.port, self.turn, say=say,
               progress_period=progress_period, margin_s=5.0, clock=self.port.now_ns)
        return targets


PERIOD_NS = 50_000_000  # 20 Hz


def test_follow_publishes_a_target_on_every_tick_and_switches_mode_at_lap_starts() -> None:
    circle = parse_trajectory({"centre_m": [0.009, 0.0], "radius_m": 0.003, "period_s": 1.0,
                               "approach_s": 0.5, "feedforward_laps": 1, "feedback_laps": 1,
                               "settle_s": 0.2, "rate_hz": 20.0})
    graph = Graph()
    targets = graph.follow(circle)
    ticks = round(circle.duration * circle.rate)  # 2.5 s at 20 Hz: 50 ticks, 0 to 2.45 s
    assert ticks == 50
    # the run ends on the first tick at or past the trajectory's end, not one tick later
    assert graph.port.now_ns() == ticks * PERIOD_NS
    points = graph.port.sent(TARGET_TOPIC)
    laps = graph.port.sent(LAP_TOPIC)
    assert [t for t, _ in points] == [t for t, _ in laps] == [k * PERIOD_NS
                                                              for k in range(ticks)]
    # the approach 0 to 0.5 s, lap 1 from 0.5 s, lap 2 (feedback) from 1.5 s
    assert [m.data for _, m in laps] == [0] * 10 + [1] * 20 + [2] * 20
    for t, message in points:
        assert message.header.frame_id == "tdcm_base"
        assert (message.header.stamp.sec, message.header.stamp.nanosec) == divmod(t, 10**9)
        x, y, z = message.point.x, message.point.y, message.point.z
        assert math.hypot(x - 0.009, y) == pytest.approx(0.003, rel=1e-9)
        # published where the circle is at that moment, exactly
        assert (x, y, z) == pytest.approx(targets.point(t / 1e9), rel=1e-12, abs=1e-15)
    # feed-forward from the start, feedback set at the first feedback tick, before its target
    assert graph.modes == [(0, FEEDFORWARD), (1_500_000_000, FEEDBACK)]
    assert graph.port.messages(LAP_TOPIC)[30].data == 2


def test_a_late_tick_publishes_where_the_target_is_then_and_skips_the_missed_ticks() -> None:
    circle = parse_trajectory({"period_s": 1.0, "approach_s": 0.1, "feedforward_laps": 1,
                               "feedback_laps": 1, "settle_s": 0.0, "rate_hz": 20.0})
    graph = Graph()
    turns = 0

    def slow_turn(deadline: float, late: Callable[[], str], seconds: float) -> None:
        nonlocal turns
        turns += 1
        graph.turn(deadline, late, seconds + (0.12 if turns == 3 else 0.0))  # one stall

    targets = tip_trajectory(circle, load_scene("tracking").design, tension_max=20.0)
    follow(targets, graph.port, graph.port, slow_turn, say=lambda line: None,
           progress_period=10.0, margin_s=5.0, clock=graph.port.now_ns)
    times = [t for t, _ in graph.port.sent(TARGET_TOPIC)]
    # 0, 50, 100 ms on time; the wait after 100 ms ends at 270 ms: published there, then the
    # ticks 300 ms, 350 ms ... (250 ms was missed and is skipped, not sent twice)
    assert times[:5] == [0, 50_000_000, 100_000_000, 270_000_000, 300_000_000]
    assert times[5:] == [k * PERIOD_NS for k in range(7, 42)]  # to 2.05 s of 2.1 s
    late = graph.port.messages(TARGET_TOPIC)[3].point
    assert (late.x, late.y, late.z) == pytest.approx(targets.point(0.27), rel=1e-12, abs=1e-15)


def test_a_refused_mode_ends_the_run_with_the_controllers_reason() -> None:
    circle = parse_trajectory({"period_s": 1.0, "approach_s": 0.1, "settle_s": 0.1})
    graph = Graph(refuse=FEEDBACK)
    with pytest.raises(RuntimePortError, match="refused mode = 'feedback': no estimate"):
        graph.follow(circle)
    # refused at the first feedback lap's start, before anything of that lap was published
    switch_ns = round((circle.approach + circle.phase_laps[FEEDFORWARD] * circle.period) * 1e9)
    assert graph.modes[-1] == (switch_ns, FEEDBACK)
    assert graph.port.now_ns() == switch_ns
    assert all(t < switch_ns for t, _ in graph.port.sent(TARGET_TOPIC))


def test_a_controller_that_answers_too_late_ends_the_run_with_the_deadline_message() -> None:
    circle = parse_trajectory({"period_s": 1.0, "approach_s": 0.1, "feedforward_laps": 1,
                               "feedback_laps": 1, "settle_s": 0.0, "rate_hz": 20.0})
    graph = Graph()
    answer = graph.set_parameters

    def slow(request: Any) -> Any:  # the switch to feedback takes 6.5 s
        if from_value(request.parameters[0].value) == FEEDBACK:
            graph.port.advance(6.5)
        return answer(request)

    graph.port.add_remote_service("/shape_controller/set_parameters",
                                  "rcl_interfaces/srv/SetParameters", slow)
    with pytest.raises(AssertionError, match="did not finish within 2.1 s \\+ 5 s"):
        graph.follow(circle)
    # asked at 1.1 s, answered at 7.6 s: the wait after it is past 2.1 s + 5 s and fails
    assert graph.modes[-1] == (7_600_000_000, FEEDBACK)
    assert graph.port.now_ns() == 7_600_000_000


def test_follow_switches_back_to_feedforward_for_the_learned_laps_and_says_so() -> None:
    circle = parse_trajectory({"centre_m": [0.009, 0.0], "radius_m": 0.003, "period_s": 1.0,
                               "approach_s": 0.3, "feedforward_laps": 1, "feedback_laps": 1,
                               "learned_feedforward_laps": 1, "settle_s": 0.1,
                               "rate_hz": 20.0})
    graph = Graph()
    said: list[str] = []
    graph.follow(circle, say=said.append, progress_period=1.0)
    assert graph.modes == [(0, FEEDFORWARD), (1_300_000_000, FEEDBACK),
                           (2_300_000_000, FEEDFORWARD)]
    laps = [m.data for m in graph.port.messages(LAP_TOPIC)]
    assert laps == [0] * 6 + [1] * 20 + [2] * 20 + [3] * 20
    assert "  t =   2.3 s  controller mode -> feedforward (feedforward_learned phase)" in said
    # a progress line at 0, 1, 2 and 3 s
    assert [line[:13] for line in said if "tip error" in line] == [
        "  t =   0.0 s", "  t =   1.0 s", "  t =   2.0 s", "  t =   3.0 s"]


def test_the_progress_line_shows_the_controllers_latest_tracking_error() -> None:
    circle = parse_trajectory({"period_s": 1.0, "approach_s": 0.1, "feedforward_laps": 1,
                               "feedback_laps": 1, "settle_s": 0.0, "rate_hz": 20.0})
    graph = Graph()
    said: list[str] = []

    def turn(deadline: float, late: Callable[[], str], seconds: float) -> None:
        if graph.port.now_ns() == 400_000_000:
            graph.port.deliver("controller/tracking_error", from_dict(
                "geometry_msgs/msg/Vector3Stamped", {"vector": {"x": 3e-4, "y": 4e-4}}))
        graph.turn(deadline, late, seconds)

    targets = tip_trajectory(circle, load_scene("tracking").design, tension_max=20.0)
    follow(targets, graph.port, graph.port, turn, say=said.append, progress_period=0.5,
           margin_s=5.0, clock=graph.port.now_ns)
    lines = [line for line in said if "tip error" in line]
    assert lines[0].endswith("tip error -") and lines[1].endswith("tip error  0.500 mm")
