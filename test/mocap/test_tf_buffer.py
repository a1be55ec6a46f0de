"""TransformBuffer against homogeneous 4x4 matrices composed by hand (quaternion -> matrix by
its closed form, chains by matrix products), interpolation against rotations about one axis."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.bagio import from_dict
from tdcm_ros.mocap.tf_buffer import (
    ExtrapolationError,
    TransformBuffer,
    TransformLookupError,
)


def matrix(translation: tuple[float, ...], q: tuple[float, ...]) -> np.ndarray:
    """4x4 pose from a translation and a unit-normalised quaternion (x, y, z, w)."""
    x, y, z, w = np.asarray(q) / np.linalg.norm(q)
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = translation
    return m


def pose_matrix(buffer: TransformBuffer, target: str, source: str, stamp: float) -> np.ndarray:
    pose = buffer.lookup(target, source, stamp)
    return matrix(pose.translation, pose.quaternion)


def about_z(angle: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


finite = st.floats(-2.0, 2.0, allow_nan=False)
quaternions = st.tuples(finite, finite, finite, finite).filter(
    lambda q: float(np.linalg.norm(q)) > 0.1)
edges = st.tuples(st.tuples(finite, finite, finite), quaternions)


@settings(max_examples=60, deadline=None)
@given(st.lists(edges, min_size=5, max_size=5), st.lists(st.booleans(), min_size=5, max_size=5))
def test_a_lookup_is_the_product_of_the_edge_matrices(poses: list, static: list[bool]) -> None:
    """Tree: map -> mocap; map -> world -> tool0 -> tdcm_base -> tip; each edge static or
    dynamic with one sample at the stamp. mocap -> tip is inv(M_map_mocap) M_map_world ..."""
    names = [("map", "mocap"), ("map", "world"), ("world", "tool0"), ("tool0", "tdcm_base"),
             ("tdcm_base", "tip")]
    buffer = TransformBuffer()
    m = {}
    for (parent, child), (t, q), is_static in zip(names, poses, static, strict=True):
        buffer.set_transform(parent, child, 3.0, t, q, static=is_static)
        m[child] = matrix(t, q)
    in_map = m["world"] @ m["tool0"] @ m["tdcm_base"] @ m["tip"]
    expected = np.linalg.inv(m["mocap"]) @ in_map
    np.testing.assert_allclose(pose_matrix(buffer, "mocap", "tip", 3.0), expected, atol=1e-9)
    np.testing.assert_allclose(pose_matrix(buffer, "tip", "mocap", 3.0),
                               np.linalg.inv(expected), atol=1e-9)
    np.testing.assert_allclose(pose_matrix(buffer, "tool0", "tip", 3.0),
                               m["tdcm_base"] @ m["tip"], atol=1e-9)
    assert buffer.is_static("mocap", "tip") == all(static)
    assert buffer.is_static("tool0", "tip") == all(static[3:])


def test_a_dynamic_edge_is_interpolated_linearly_and_by_the_shorter_arc() -> None:
    buffer = TransformBuffer()
    buffer.set_transform("world", "tool0", 1.0, (0.0, 0.0, 0.0), about_z(0.2), static=False)
    buffer.set_transform("world", "tool0", 2.0, (1.0, -2.0, 0.5), about_z(1.4), static=False)
    for f in (0.0, 0.25, 0.5, 0.9, 1.0):
        got = pose_matrix(buffer, "world", "tool0", 1.0 + f)
        np.testing.assert_allclose(got, matrix((f, -2 * f, 0.5 * f), about_z(0.2 + 1.2 * f)),
                                   atol=1e-12)
    # 350 degrees apart one way is 10 degrees the other: the midpoint is 5 degrees past 0
    buffer.set_transform("world", "arm", 0.0, (0, 0, 0), about_z(math.radians(-5)), static=False)
    buffer.set_transform("world", "arm", 1.0, (0, 0, 0), about_z(math.radians(5)), static=False)
    np.testing.assert_allclose(pose_matrix(buffer, "world", "arm", 0.5), np.eye(4), atol=1e-12)


def test_a_dynamic_edge_is_not_extrapolated_and_keeps_its_cache() -> None:
    buffer = TransformBuffer(cache_s=5.0)
    for stamp in np.arange(0.0, 20.5, 0.5):
        buffer.set_transform("world", "tool0", float(stamp), (stamp, 0, 0), about_z(0), static=False)
    with pytest.raises(ExtrapolationError, match=r"after the last sample .*from 15\.0+ to 20\.0+"
                       ) as late:
        buffer.lookup("world", "tool0", 20.01)
    with pytest.raises(ExtrapolationError, match="before the first sample") as early:
        buffer.lookup("world", "tool0", 14.99)
    assert late.value.future and not early.value.future
    assert buffer.lookup("world", "tool0", 15.0).translation[0] == 15.0
    # a sample older than the cache changes nothing
    buffer.set_transform("world", "tool0", 3.0, (99, 0, 0), about_z(0), static=False)
    assert buffer.lookup("world", "tool0", 17.25).translation[0] == pytest.approx(17.25)


def test_only_edges_below_the_common_ancestor_are_read() -> None:
    """An extrapolated edge above the common ancestor does not matter (as in tf2)."""
    buffer = TransformBuffer()
    buffer.set_transform("earth", "mocap", 0.0, (0, 0, 0), about_z(0), static=False)
    buffer.set_transform("mocap", "base", 0.0, (1, 2, 3), about_z(0.5), static=True)
    buffer.set_transform("base", "tip", 0.0, (0, 0, 0.1), about_z(0), static=True)
    assert buffer.lookup("mocap", "tip", 50.0).translation == pytest.approx((1, 2, 3.1))
    with pytest.raises(TransformLookupError, match="after the last sample"):
        buffer.lookup("earth", "tip", 50.0)


def test_a_new_edge_into_a_frame_replaces_its_parent() -> None:
    buffer = TransformBuffer()
    buffer.set_transform("tool0", "base", 0.0, (0, 0, 1), about_z(0), static=True)
    buffer.set_transform("mocap", "base", 0.0, (0, 0, 2), about_z(0), static=True)
    assert buffer.lookup("mocap", "base", 7.0).translation == (0.0, 0.0, 2.0)
    with pytest.raises(TransformLookupError, match="'tool0' is in no TF edge"):
        buffer.lookup("tool0", "base", 7.0)
    buffer.set_transform("world", "tool0", 0.0, (0, 0, 0), about_z(0), static=True)
    with pytest.raises(TransformLookupError, match="unconnected TF trees"):
        buffer.lookup("tool0", "base", 7.0)


@pytest.mark.parametrize(("call", "match"), [
    (lambda b: b.lookup("mocap", "nowhere", 0.0), r"frame 'nowhere' is in no TF edge"),
    (lambda b: b.lookup("mocap", "", 0.0), r"source frame = ''"),
    (lambda b: b.set_transform("a", "a", 0.0, (0, 0, 0), (0, 0, 0, 1), static=True),
     r"TF edge 'a' -> 'a'"),
    (lambda b: b.set_transform("a", "b", 0.0, (0, math.nan, 0), (0, 0, 0, 1), static=True),
     r"TF edge 'a' -> 'b': translation"),
    (lambda b: b.set_transform("a", "b", 0.0, (0, 0, 0), (0, 0, 0, 0), static=True),
     r"TF edge 'a' -> 'b': quaternion"),
    (lambda b: b.set_transform("a", "b", math.inf, (0, 0, 0), (0, 0, 0, 1), static=False),
     r"stamp = inf"),
])
def test_bad_edges_and_frames_raise_errors_that_name_them(call, match: str) -> None:
    buffer = TransformBuffer()
    buffer.set_transform("mocap", "base", 0.0, (0, 0, 0), (0, 0, 0, 1), static=True)
    with pytest.raises(TransformLookupError, match=match):
        call(buffer)


def test_a_loop_is_an_error_not_a_hang() -> None:
    buffer = TransformBuffer()
    buffer.set_transform("a", "b", 0.0, (0, 0, 0), (0, 0, 0, 1), static=True)
    buffer.set_transform("b", "c", 0.0, (0, 0, 0), (0, 0, 0, 1), static=True)
    buffer.set_transform("c", "a", 0.0, (0, 0, 0), (0, 0, 0, 1), static=True)
    buffer.set_transform("x", "y", 0.0, (0, 0, 0), (0, 0, 0, 1), static=True)
    with pytest.raises(TransformLookupError, match="loop"):
        buffer.lookup("y", "a", 0.0)
    assert not buffer.is_static("y", "a")


def _tf(parent: str, child: str, xyz: tuple[float, ...], quat: tuple[float, ...],
        stamp_s: float = 0.0) -> dict:
    ns = round(stamp_s * 1e9)
    return {"header": {"frame_id": parent, "stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}},
            "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", xyz, strict=True)),
                          "rotation": dict(zip("xyzw", quat, strict=True))}}


def test_a_message_s_edges_go_in_and_a_point_goes_up_and_down_the_tree() -> None:
    """A TFMessage read as a tf2 listener reads it (a leading '/' dropped); the camera's origin
    by hand: in world (0, 0, 3); in mocap R^T (p - t) = (0, 1, 3); in the base (0, -1, 3)."""
    buffer = TransformBuffer()
    problems = buffer.add_message(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [
        _tf("/world", "mocap", (1.0, 0.0, 0.0), about_z(math.pi / 2)),
        _tf("mocap", "tdcm_base", (0.0, 2.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
        _tf("world", "camera", (0.0, 0.0, 3.0), (0.0, 0.0, 0.0, 1.0))]}), static=True)
    assert problems == []
    camera_origin = buffer.lookup("camera", "tdcm_base", None).to_base(np.zeros(3))
    assert camera_origin == pytest.approx((0.0, -1.0, 3.0))
    assert buffer.lookup("camera", "camera", None).to_base([1.0, 2.0, 3.0]) == pytest.approx(
        (1.0, 2.0, 3.0))


def test_a_message_s_dynamic_edges_carry_their_stamps_and_none_reads_the_newest() -> None:
    buffer = TransformBuffer()
    buffer.add_message(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [
        _tf("world", "tool0", (1.0, 0.0, 0.0), about_z(0), stamp_s=1.5),
        _tf("world", "tool0", (3.0, 0.0, 0.0), about_z(0), stamp_s=2.5)]}), static=False)
    assert buffer.lookup("world", "tool0", 2.0).translation == pytest.approx((2.0, 0.0, 0.0))
    assert buffer.lookup("world", "tool0", None).translation == (3.0, 0.0, 0.0)


def test_a_bad_transform_in_a_message_is_skipped_with_a_reason() -> None:
    buffer = TransformBuffer()
    problems = buffer.add_message(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [
        _tf("mocap", "tdcm_base", (math.nan, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))]}), static=True)
    assert len(problems) == 1 and "TF edge 'mocap' -> 'tdcm_base': translation" in problems[0]
    assert buffer.frames() == []
