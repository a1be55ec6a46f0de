"""Roll (:mod:`tdcm_ros.model.roll`): a solved planar shape turned rigidly about the base +z
axis, identity at zero roll, composing, frames consistent with the rolled midline, base-frame
loads projected into the rolled plane, bad angles refused."""

import functools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tdcm_ros.errors import InputError
from tdcm_ros.model import (
    InvalidRollError,
    Loading,
    RollHistory,
    check_roll,
    depends_on_roll,
    offset_points,
    preset,
    roll_loading,
    roll_points,
    roll_poses,
    roll_quaternions,
    solve,
)

PAPER = preset("paper-experiment")
ANGLES = st.floats(-2.0 * math.pi, 2.0 * math.pi)
TENSIONS = st.sampled_from([0.0, 3.0, 9.0, 15.0, 20.0])
SAMPLES = np.linspace(0.0, PAPER.length, 201)


@functools.cache
def planar(tension):
    """Positions (k, 3) m and quaternions (k, 4) of the paper design at ``tension`` (N)."""
    return solve(PAPER, tension).pose_at(SAMPLES)


@settings(max_examples=30)
@given(tension=TENSIONS)
def test_zero_roll_is_the_identity_bit_for_bit(tension):
    positions, quats = planar(tension)
    rolled, turned = roll_poses(positions, quats, 0.0)
    assert rolled.tobytes() == positions.tobytes()
    assert turned.tobytes() == quats.tobytes()
    signed = np.array([[-0.0, -0.0, 1.0], [np.nan, 2.0, -3.0]])
    assert roll_points(signed, -0.0).tobytes() == signed.tobytes()


@settings(max_examples=50)
@given(tension=TENSIONS, roll=ANGLES)
def test_a_planar_point_x_0_z_becomes_x_cos_x_sin_z(tension, roll):
    positions, _ = planar(tension)
    rolled = roll_points(positions, roll)
    expected = np.stack([positions[:, 0] * math.cos(roll), positions[:, 0] * math.sin(roll),
                         positions[:, 2]], axis=1)
    np.testing.assert_allclose(rolled, expected, rtol=0.0, atol=1e-15)
    assert np.array_equal(rolled[:, 2], positions[:, 2])


@settings(max_examples=50)
@given(tension=TENSIONS, roll=ANGLES)
def test_roll_preserves_distances_and_arc_length(tension, roll):
    positions, _ = planar(tension)
    rolled = roll_points(positions, roll)
    np.testing.assert_allclose(np.linalg.norm(rolled, axis=1), np.linalg.norm(positions, axis=1),
                               rtol=1e-14, atol=1e-16)
    chords = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    np.testing.assert_allclose(np.linalg.norm(np.diff(rolled, axis=0), axis=1), chords,
                               rtol=1e-12, atol=1e-16)
    assert abs(chords.sum() - PAPER.length) < 1e-6  # the polyline spans the body's length


@settings(max_examples=50)
@given(tension=TENSIONS, first=ANGLES, second=ANGLES)
def test_rolls_compose(tension, first, second):
    positions, quats = planar(tension)
    twice = roll_poses(*roll_poses(positions, quats, first), second)
    once = roll_poses(positions, quats, first + second)
    np.testing.assert_allclose(twice[0], once[0], rtol=0.0, atol=1e-15)
    np.testing.assert_allclose(twice[1], once[1], rtol=0.0, atol=1e-14)


@settings(max_examples=50)
@given(tension=TENSIONS, roll=ANGLES)
def test_frames_stay_unit_and_follow_the_rolled_midline(tension, roll):
    quats = planar(tension)[1]
    turned = roll_quaternions(quats, roll)
    np.testing.assert_allclose(np.linalg.norm(turned, axis=1), 1.0, rtol=0.0, atol=1e-15)
    frames = Rotation.from_quat(turned)
    expected = Rotation.from_rotvec([0.0, 0.0, roll]) * Rotation.from_quat(quats)
    np.testing.assert_allclose(frames.as_matrix(), expected.as_matrix(), rtol=0.0, atol=1e-14)
    # the body z axis is the planar tangent (sin theta, 0, cos theta), rolled
    theta = 2.0 * np.arctan2(quats[:, 1], quats[:, 3])
    planar_tangent = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=1)
    np.testing.assert_allclose(frames.apply([0.0, 0.0, 1.0]),
                               roll_points(planar_tangent, roll), rtol=0.0, atol=1e-15)
    # the body x axis (tendon side) stays in the rolled bending plane
    plane_normal = np.array([-math.sin(roll), math.cos(roll), 0.0])
    np.testing.assert_allclose(frames.apply([1.0, 0.0, 0.0]) @ plane_normal, 0.0, atol=1e-15)


@settings(max_examples=30)
@given(tension=TENSIONS, roll=ANGLES, side=st.floats(-math.pi, math.pi),
       radius=st.floats(0.0, 0.01))
def test_markers_rolled_with_the_body_sit_on_the_rolled_frames(tension, roll, side, radius):
    positions, quats = planar(tension)
    rolled, turned = roll_poses(positions, quats, roll)
    frames = Rotation.from_quat(turned)
    on_rolled_frames = rolled + radius * frames.apply([math.cos(side), math.sin(side), 0.0])
    np.testing.assert_allclose(roll_points(offset_points(positions, quats, radius, side), roll),
                               on_rolled_frames, rtol=0.0, atol=1e-15)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, "0.1", True, None,
                                 np.array([0.1, 0.2])])
def test_a_bad_roll_names_the_parameter_value_and_range(bad):
    with pytest.raises(InvalidRollError) as caught:
        roll_points([[1.0, 0.0, 0.0]], bad)
    assert isinstance(caught.value, InputError)
    assert caught.value.parameter == "roll"
    assert "finite" in caught.value.allowed and "rad" in str(caught.value)
    with pytest.raises(InvalidRollError, match="joint_states.position"):
        check_roll(bad, "joint_states.position")


def test_check_roll_takes_real_numbers():
    assert check_roll(np.float32(0.5)) == pytest.approx(0.5)
    assert check_roll(-3) == -3.0


@settings(max_examples=50)
@given(roll=ANGLES, fx=st.floats(-10.0, 10.0), fz=st.floats(-10.0, 10.0),
       moment=st.floats(-1.0, 1.0))
def test_base_frame_loads_keep_their_part_in_the_rolled_plane(roll, fx, fz, moment):
    loading = Loading(tip_force=(fx, fz), tip_moment=moment, body_force_density=(2.0 * fx, fz))
    rolled = roll_loading(loading, roll)
    in_plane_x = roll_points([1.0, 0.0, 0.0], roll)
    plane_normal = roll_points([0.0, 1.0, 0.0], roll)
    assert rolled.tip_force == pytest.approx((np.dot([fx, 0.0, fz], in_plane_x), fz), abs=1e-15)
    assert rolled.body_force_density == pytest.approx(
        (np.dot([2.0 * fx, 0.0, fz], in_plane_x), fz), abs=1e-15)
    assert rolled.tip_moment == pytest.approx(np.dot([0.0, moment, 0.0], plane_normal),
                                              abs=1e-15)


def test_loads_along_the_roll_axis_do_not_depend_on_it():
    along_z = Loading(body_force_density=(0.0, -9.8e3))
    assert not depends_on_roll(along_z) and not depends_on_roll(None)
    assert roll_loading(along_z, 1.0) is along_z and roll_loading(None, 1.0) is None
    sideways = Loading(body_force_density=(9.8e3, 0.0))
    assert depends_on_roll(sideways) and roll_loading(sideways, 0.0) is sideways
    assert roll_loading(sideways, math.pi / 2).body_force_density[0] == pytest.approx(0.0,
                                                                                      abs=1e-9)


def test_roll_history_pairs_a_stamp_with_the_roll_current_then() -> None:
    history = RollHistory(size=3)
    assert history.at(5.0) == 0.0                       # none yet
    for stamp, roll in ((1.0, 0.1), (2.0, 0.2), (2.0, 0.25), (3.0, 0.3)):
        assert history.add(stamp, roll)
    assert len(history) == 3                            # (1.0, 0.1) fell out
    assert history.at(2.0) == 0.25 and history.at(2.9) == 0.25
    assert history.at(3.0) == 0.3 and history.at(1e9) == 0.3
    assert history.at(0.0) == 0.2                       # older than all: the oldest kept
    assert not history.add(2.5, 0.9) and history.at(2.6) == 0.25  # out of order: ignored
    with pytest.raises(InvalidRollError, match="joint_states"):
        history.add(4.0, math.nan, "joint_states")
    assert history.at(5.0) == 0.3
    with pytest.raises(InputError, match="size"):
        RollHistory(size=0)
