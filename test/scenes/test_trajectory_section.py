"""The scene's ``trajectory`` section: the shipped tracking scene, timing and geometry of the
circle, and typed errors that name the key, the value and the allowed range."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.scenes import InvalidSceneError, load_scene, scene_from_text
from tdcm_ros.scenes.trajectory import (
    FEEDBACK,
    FEEDFORWARD,
    FEEDFORWARD_LEARNED,
    CircleTrajectory,
    parse_trajectory,
)


def test_the_tracking_scene_declares_a_circle_and_a_world_e_not_the_models() -> None:
    scene = load_scene("tracking")
    circle = scene.trajectory
    assert circle is not None
    assert scene.true_design.E != scene.design.E
    assert circle.lap_modes == (FEEDFORWARD, FEEDBACK, FEEDBACK, FEEDFORWARD)
    assert circle.lap_phases == (FEEDFORWARD, FEEDBACK, FEEDBACK, FEEDFORWARD_LEARNED)
    low, high = circle.deflection_range()
    assert 0.0 < low < high
    assert scene.to_dict()["trajectory"]["radius_m"] == circle.radius


def test_a_scene_without_the_section_has_no_trajectory_and_an_empty_one_the_defaults() -> None:
    assert load_scene("paper_experiment").trajectory is None
    assert scene_from_text("{}").trajectory is None
    defaults = scene_from_text("trajectory: {}").trajectory
    assert defaults == parse_trajectory({})
    assert defaults is not None and defaults.centre == (0.009, 0.0)


def _circle(**changes: float) -> CircleTrajectory:
    values = {"centre_m": [0.009, 0.002], "radius_m": 0.003, "period_s": 10.0, "approach_s": 2.0,
              "feedforward_laps": 1, "feedback_laps": 2, "settle_s": 4.0, "rate_hz": 20.0}
    values.update(changes)
    return parse_trajectory(values)


def test_timing_runs_the_approach_then_the_laps_in_order() -> None:
    circle = _circle()
    assert circle.duration == pytest.approx(32.0)
    assert [circle.lap_at(t) for t in (0.0, 1.99, 2.0, 11.99, 12.0, 22.0, 31.9, 40.0)] == \
        [0, 0, 1, 1, 2, 3, 3, 3]
    assert [circle.mode_of_lap(lap) for lap in range(4)] == \
        [FEEDFORWARD, FEEDFORWARD, FEEDBACK, FEEDBACK]
    assert circle.xy(0.0) == pytest.approx((0.012, 0.002))   # the approach holds angle 0
    assert circle.xy(2.0 + 2.5) == pytest.approx((0.009, 0.005))  # a quarter lap: +y
    assert circle.learned_feedforward_laps == 0 and circle.lap_phases == circle.lap_modes


def test_learned_feed_forward_laps_run_last_in_mode_feedforward() -> None:
    circle = _circle(learned_feedforward_laps=2)
    assert circle.laps == 5 and circle.duration == pytest.approx(52.0)
    assert [circle.lap_at(t) for t in (31.9, 32.0, 42.0, 51.9, 60.0)] == [3, 4, 5, 5, 5]
    assert [circle.mode_of_lap(lap) for lap in range(6)] == \
        [FEEDFORWARD, FEEDFORWARD, FEEDBACK, FEEDBACK, FEEDFORWARD, FEEDFORWARD]
    assert [circle.phase_of_lap(lap) for lap in range(6)] == \
        ["", FEEDFORWARD, FEEDBACK, FEEDBACK, FEEDFORWARD_LEARNED, FEEDFORWARD_LEARNED]
    assert parse_trajectory(circle.to_dict()) == circle


@given(st.floats(0.0, 40.0))
def test_every_target_lies_on_the_circle_in_x_above_zero(t: float) -> None:
    circle = _circle()
    x, y = circle.xy(t)
    assert math.hypot(x - 0.009, y - 0.002) == pytest.approx(0.003, rel=1e-9)
    assert x > 0.0 and abs(math.atan2(y, x)) < math.pi / 2
    low, high = circle.deflection_range()
    assert low - 1e-12 <= math.hypot(x, y) <= high + 1e-12


@pytest.mark.parametrize(("changes", "key", "allowed"), [
    ({"centre_m": [0.002, 0.0]}, "trajectory.centre_m", "x > 0.003 m"),
    ({"centre_m": [0.009]}, "trajectory.centre_m", "2 numbers"),
    ({"radius_m": 0.0}, "trajectory.radius_m", "(0, 0.5] m"),
    ({"period_s": 0.5}, "trajectory.period_s", "[1, 3600] s"),
    ({"feedback_laps": 0}, "trajectory.feedback_laps", "integer in [1, 1000]"),
    ({"feedforward_laps": 1.5}, "trajectory.feedforward_laps", "integer in [1, 1000]"),
    ({"settle_s": 10.0}, "trajectory.settle_s", "[0, 10) s"),
    ({"learned_feedforward_laps": -1}, "trajectory.learned_feedforward_laps",
     "integer in [0, 1000]"),
    ({"learned_feedforward_laps": 0.5}, "trajectory.learned_feedforward_laps",
     "integer in [0, 1000]"),
    ({"learned_feedforward_laps": "one"}, "trajectory.learned_feedforward_laps",
     "integer in [0, 1000]"),
    # the learned phase is the shortest: settle_s must leave some of it
    ({"feedforward_laps": 2, "learned_feedforward_laps": 1, "settle_s": 10.0},
     "trajectory.settle_s", "[0, 10) s"),
    ({"rate_hz": -1.0}, "trajectory.rate_hz", "[0.1, 1000] Hz"),
])
def test_bad_values_name_the_key_and_the_allowed_range(changes: dict[str, object], key: str,
                                                       allowed: str) -> None:
    with pytest.raises(InvalidSceneError) as info:
        _circle(**changes)  # type: ignore[arg-type]
    assert info.value.parameter == key
    assert key in str(info.value) and allowed in str(info.value)


def test_no_learned_laps_leave_the_settle_limit_to_the_other_phases() -> None:
    # 0 learned laps is no phase: settle_s may take 19.9 s of two 10 s laps of each
    circle = _circle(feedforward_laps=2, settle_s=19.9)
    assert circle.learned_feedforward_laps == 0 and circle.settle == 19.9


def test_an_unknown_key_lists_the_valid_ones() -> None:
    with pytest.raises(InvalidSceneError, match="radius_m"):
        scene_from_text("trajectory: {radius: 0.003}")
