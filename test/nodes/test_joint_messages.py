"""JointState written as CDR directly: the bytes rosbags gives for the same message."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.bagio import deserialize, from_dict, serialize
from tdcm_ros.nodes.joint_messages import JOINT_STATE, joint_state_cdr, tendon_states

NAMES = st.lists(st.text(max_size=9), max_size=4)
VALUES = st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4)


def reference(stamp_ns: int, names: list[str], position: list[float], velocity: list[float],
              effort: list[float], frame_id: str) -> bytes:
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return serialize(from_dict(JOINT_STATE, {
        "header": {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame_id},
        "name": names, "position": position, "velocity": velocity, "effort": effort}))


@settings(max_examples=200, deadline=None)
@given(stamp=st.integers(0, 2**62), names=NAMES, position=VALUES, velocity=VALUES,
       effort=VALUES, frame_id=st.text(max_size=7))
def test_the_bytes_are_rosbags_bytes(stamp: int, names: list[str], position: list[float],
                                     velocity: list[float], effort: list[float],
                                     frame_id: str) -> None:
    """Every padding case: names and a frame of any length (UTF-8 too), empty and non-empty
    arrays, NaN and infinities."""
    stamp %= 2**31 * 1_000_000_000  # int32 seconds
    got = joint_state_cdr(stamp, names, position, velocity, effort, frame_id)
    assert got == reference(stamp, names, position, velocity, effort, frame_id)


def test_model_nodes_tendon_states_read_back() -> None:
    data = tendon_states(1_700_000_000_123_456_789, ["flexor", "extensor"], [0.0012, -0.0003],
                         [14.5, 0.25])
    message = deserialize(data, JOINT_STATE)
    assert list(message.name) == ["flexor", "extensor"] and message.header.frame_id == ""
    assert message.header.stamp.sec == 1_700_000_000
    assert message.header.stamp.nanosec == 123_456_789
    assert np.array_equal(message.position, [0.0012, -0.0003]) and not len(message.velocity)
    assert np.array_equal(message.effort, [14.5, 0.25])
