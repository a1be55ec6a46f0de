"""The 3D tip targets of a scene's circle: each one a point the estimator's model reaches
through a roll and a bend, and an unreachable circle refused with the model's typed error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdcm_ros.demo.trajectory import tip_trajectory
from tdcm_ros.model import UnreachableTargetError, solve, solve_inverse
from tdcm_ros.scenes import load_scene
from tdcm_ros.scenes.trajectory import parse_trajectory


def test_every_target_is_a_roll_and_a_bend_the_model_reaches() -> None:
    scene = load_scene("tracking")
    assert scene.trajectory is not None
    targets = tip_trajectory(scene.trajectory, scene.design, tension_max=20.0)
    rng = np.random.default_rng(7)
    for t in rng.uniform(0.0, scene.trajectory.duration, 12):
        x, y, z = targets.point(float(t))
        deflection = math.hypot(x, y)
        inverse = solve_inverse(scene.design, tip_deflection=deflection, tension_max=20.0)
        tip = solve(scene.design, inverse.tension_n).tip_position
        roll = math.atan2(y, x)
        assert abs(roll) < math.pi / 2
        # the model's tip rotated by the roll is the target: interpolation within 1e-7 m
        assert np.linalg.norm([tip[0] * math.cos(roll) - x, tip[0] * math.sin(roll) - y,
                               tip[2] - z]) < 1e-7


def test_the_circle_is_tilted_by_the_bend() -> None:
    scene = load_scene("tracking")
    assert scene.trajectory is not None
    targets = tip_trajectory(scene.trajectory, scene.design, tension_max=20.0)
    circle = scene.trajectory
    far = targets.point(circle.approach)                       # angle 0: largest deflection
    near = targets.point(circle.approach + circle.period / 2)  # angle pi: smallest
    assert far[2] < near[2] - 1e-3                             # bending more lowers the tip
    points = targets.points(np.linspace(0.0, circle.duration, 50))
    assert points.shape == (50, 3)


def test_a_circle_beyond_the_tension_limit_is_refused_with_the_reachable_range() -> None:
    scene = load_scene("tracking")
    circle = parse_trajectory({"centre_m": [0.02, 0.0], "radius_m": 0.003})
    with pytest.raises(UnreachableTargetError, match="reachable|spans"):
        tip_trajectory(circle, scene.design, tension_max=20.0)


def test_a_lap_starts_exactly_at_the_approach_plus_whole_periods() -> None:
    # 2.3 - 0.3 is 1.9999999999999998 in floats: the third lap still starts at 2.3 s, not a tick
    # later, and the instant before each start is still the lap before
    circle = parse_trajectory({"period_s": 1.0, "approach_s": 0.3, "feedforward_laps": 1,
                               "feedback_laps": 1, "learned_feedforward_laps": 1,
                               "settle_s": 0.1})
    assert [circle.lap_at(k / 20) for k in range(5, 8)] == [0, 1, 1]
    assert [circle.lap_at(t) for t in (1.299999999, 1.3, 2.299999999, 2.3, 3.3, 9.0)] == \
        [1, 2, 2, 3, 3, 3]
