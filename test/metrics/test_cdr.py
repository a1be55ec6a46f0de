"""The JointState fast path of the bag reader: a roll joint among other joints' messages."""

from __future__ import annotations

import math

import numpy as np

from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.metrics.cdr import joint_positions


def joint_state(sec: int, names: list[str], positions: list[float]) -> bytes:
    return serialize(from_dict("sensor_msgs/msg/JointState", {
        "header": {"stamp": {"sec": sec, "nanosec": 5}}, "name": names, "position": positions}))


def test_messages_of_other_joints_are_not_about_the_roll() -> None:
    """A robot's joint_states mixes publishers: the driver's roll and model_node's body joints.
    Only messages naming the joint are its samples; one naming it without a position is a bad
    sample (NaN), not another joint's."""
    payloads = [joint_state(1, ["roll"], [0.25]), joint_state(2, ["notch_1", "notch_2"], [0.1, 0.2]),
                joint_state(3, ["notch_1", "roll"], [0.1, -0.5]), joint_state(4, ["roll"], []),
                joint_state(5, ["roll"], [math.inf])]
    stamps, positions, named = joint_positions(payloads, "roll")
    assert stamps.tolist() == [k * 10**9 + 5 for k in range(1, 6)]
    assert named.tolist() == [True, False, True, True, True]
    assert positions[[0, 2]].tolist() == [0.25, -0.5]
    assert np.isnan(positions[1]) and np.isnan(positions[3]) and positions[4] == math.inf
