"""The model node's CDR written directly (shape_messages, tf_messages) is byte for byte what
rosbags serialises from message objects built the way the node built them before (the oracle
below: rosbags classes, field by field), over tensions, rolls, frame ids of every padding,
stamps, sample counts, markers and TF stations."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import cdr_header, msg_class, serialize
from tdcm_ros.model import offset_points, preset, roll_poses, solve
from tdcm_ros.nodes.shape_messages import midline_messages, pose_array_cdr
from tdcm_ros.nodes.tf_messages import TF_TYPE, body_tf, station_lengths, tendon_tf

TYPES = {"midline": "nav_msgs/msg/Path", "midline_poses": "geometry_msgs/msg/PoseArray",
         "tip_pose": "geometry_msgs/msg/PoseStamped",
         "predicted_markers": "geometry_msgs/msg/PoseArray",
         "body_markers": "visualization_msgs/msg/MarkerArray"}
#: Frame ids of every length mod 8 (so every padding after a header), one not ASCII.
FRAMES = ("", "a", "tdcm_base", "robot1/tdcm_base", "ab", "abc", "abcdef", "frame_ü")
STAMPS = (0, 1, 999_999_999, 1_700_000_000_123_456_789, (2**31 - 1) * 10**9 + 5)
ROLLS = (0.0, 0.7, -2.5, math.pi)
DESIGN = preset("paper-experiment")
RESULTS = [solve(DESIGN, tension) for tension in (0.0, 4.0, 12.0, 25.0)]


def header(stamp_ns: int, frame_id: str) -> Any:
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return msg_class("std_msgs/msg/Header")(
        stamp=msg_class("builtin_interfaces/msg/Time")(sec=sec, nanosec=nanosec),
        frame_id=frame_id)


def poses(positions: np.ndarray, quats: np.ndarray) -> list[Any]:
    point, quaternion = msg_class("geometry_msgs/msg/Point"), msg_class(
        "geometry_msgs/msg/Quaternion")
    return [msg_class("geometry_msgs/msg/Pose")(
        position=point(x=p[0], y=p[1], z=p[2]),
        orientation=quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))
        for p, q in zip(positions.tolist(), quats.tolist(), strict=True)]


def oracle_shape(result: Any, stamp_ns: int, frame_id: str, samples: int, marker_s: np.ndarray,
                 radius: float, side: float, roll: float) -> dict[str, bytes]:
    """Path, PoseArrays and PoseStamped as objects, serialised by rosbags."""
    s = np.linspace(0.0, result.design.length, samples)
    planar, quats = result.pose_at(np.concatenate([s, marker_s]))
    planar[samples:] = offset_points(planar[samples:], quats[samples:], radius, side)
    positions, turned = roll_poses(np.vstack([planar, result.tip_position]),
                                   np.vstack([quats, result.tip_quaternion]), roll)
    hdr = header(stamp_ns, frame_id)
    stamped, array = (msg_class("geometry_msgs/msg/PoseStamped"),
                      msg_class("geometry_msgs/msg/PoseArray"))
    line = poses(positions[:samples], turned[:samples])
    objects = {
        "midline": msg_class("nav_msgs/msg/Path")(
            header=hdr, poses=[stamped(header=hdr, pose=pose) for pose in line]),
        "midline_poses": array(header=hdr, poses=line),
        "tip_pose": stamped(header=hdr, pose=poses(positions[-1:], turned[-1:])[0]),
        "predicted_markers": array(header=hdr,
                                   poses=poses(positions[samples:-1], turned[samples:-1]))}
    return {topic: serialize(message, TYPES[topic]) for topic, message in objects.items()}


def oracle_tf(stamp_ns: int, parent: str, children: list[str], positions: np.ndarray,
              quats: np.ndarray) -> bytes:
    vector, quaternion = (msg_class("geometry_msgs/msg/Vector3"),
                          msg_class("geometry_msgs/msg/Quaternion"))
    transform = msg_class("geometry_msgs/msg/Transform")
    stamped = msg_class("geometry_msgs/msg/TransformStamped")
    return serialize(msg_class(TF_TYPE)(transforms=[
        stamped(header=header(stamp_ns, parent), child_frame_id=child,
                transform=transform(translation=vector(x=p[0], y=p[1], z=p[2]),
                                    rotation=quaternion(x=q[0], y=q[1], z=q[2], w=q[3])))
        for child, p, q in zip(children, positions.tolist(), quats.tolist(), strict=True)]),
        TF_TYPE)


CASES = list(itertools.product(range(len(RESULTS)), STAMPS, FRAMES, ROLLS))


@pytest.mark.parametrize("samples,arcs", [(2, [0.0]), (3, [0.015, 0.033]),
                                          (54, [0.015, 0.033, 0.053])])
def test_shape_bytes_equal_the_objects_serialised(samples: int, arcs: list[float]) -> None:
    marker_s = np.array(arcs)
    for k, (index, stamp, frame, roll) in enumerate(CASES):
        result = RESULTS[index]
        radius, side = (0.0, 0.0) if k % 2 else (result.design.R_outer + 0.001, 0.3 * k)
        direct = dict(midline_messages(result, stamp_ns=stamp, frame_id=frame, samples=samples,
                                       marker_s=marker_s, marker_radius=radius,
                                       marker_side_rad=side, roll=roll))
        expected = oracle_shape(result, stamp, frame, samples, marker_s, radius, side, roll)
        for topic, data in expected.items():
            assert direct[topic] == data, (topic, index, stamp, frame, roll)
        assert set(direct) == set(TYPES)
        tip_only = dict(midline_messages(result, stamp_ns=stamp, frame_id=frame,
                                         samples=samples, marker_s=marker_s, marker_radius=radius,
                                         marker_side_rad=side, roll=roll, drawn=False))
        assert tip_only == {"tip_pose": expected["tip_pose"]}


@pytest.mark.parametrize("stations", [0, 1, 3])
def test_tf_bytes_equal_the_objects_serialised(stations: int) -> None:
    for index, stamp, frame, roll in CASES:
        result = RESULTS[index]
        children = ["tdcm_tip", *(f"{frame}st_{k}" for k in range(1, stations + 1))]
        positions, quats = result.tip_position[None], result.tip_quaternion[None]
        if stations:
            at, turn = result.pose_at(station_lengths(result.design.length, stations))
            positions, quats = np.vstack([positions, at]), np.vstack([quats, turn])
        direct = body_tf(result, stamp_ns=stamp, parent=frame, tip="tdcm_tip",
                         station_prefix=f"{frame}st_", stations=stations, roll=roll)
        assert direct == oracle_tf(stamp, frame, children, *roll_poses(positions, quats, roll))
    static = tendon_tf(DESIGN, stamp_ns=STAMPS[3], parent="tdcm_base", child="tdcm_tendon")
    assert static == oracle_tf(STAMPS[3], "tdcm_base", ["tdcm_tendon"],
                               np.array([[DESIGN.R_c, 0.0, 0.0]]), np.array([[1.0, 0, 0, 0]]))


@pytest.mark.parametrize("frame", FRAMES)
def test_pose_arrays_of_no_poses_and_of_non_finite_values(frame: str) -> None:
    """An empty sequence writes its length alone; NaN, infinities, -0 and subnormals keep
    their bits."""
    odd = np.array([[np.nan, np.inf, -np.inf, -0.0, 1e-300, 5e-324, 1.0]] * 3)
    for rows in (np.zeros((0, 7)), odd[:1], odd):
        message = msg_class("geometry_msgs/msg/PoseArray")(
            header=header(STAMPS[3], frame), poses=poses(rows[:, :3], rows[:, 3:]))
        assert pose_array_cdr(cdr_header(STAMPS[3], frame), rows) == serialize(message)
