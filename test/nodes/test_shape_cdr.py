"""The model node's CDR written directly (shape_messages, band_messages, tf_messages) is byte for
byte what rosbags serialises from message objects built the way the node built them before (the
oracle below: rosbags classes, field by field), over tensions, rolls, frame ids of every padding,
stamps, sample counts, markers, band confidences, NaN and infinities, and TF stations."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.bagio import cdr_header, msg_class, serialize
from tdcm_ros.model import (
    offset_points,
    preset,
    roll_points,
    roll_poses,
    roll_quaternions,
    solve,
)
from tdcm_ros.nodes.band_messages import ShapeSpread, band_edges, uncertainty_messages
from tdcm_ros.nodes.shape_messages import (
    MarkerStyle,
    marker_array_cdr,
    marker_cdr,
    midline_messages,
    pose_array_cdr,
)
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
#: Values whose bits must survive: NaN, infinities, -0, subnormals.
ODD = (math.nan, math.inf, -math.inf, -0.0, 1e-300, 5e-324)
DRAWN_STAMPS = st.integers(-(2**31) * 10**9, (2**31 - 1) * 10**9 + 999_999_999)
DRAWN_FRAMES = st.one_of(st.sampled_from(FRAMES), st.text(max_size=17))
DRAWN_ROLLS = st.one_of(st.sampled_from(ROLLS), st.floats(-2.0 * math.pi, 2.0 * math.pi))


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


def marker(hdr: Any, ns: str, marker_id: int, marker_type: int, scale: tuple[float, ...],
           color: tuple[float, ...], points: np.ndarray) -> Any:
    """A ``visualization_msgs/Marker`` as the node sent it: every Jazzy field, those it does
    not use empty."""
    point, vector = msg_class("geometry_msgs/msg/Point"), msg_class("geometry_msgs/msg/Vector3")
    return msg_class("visualization_msgs/msg/Marker")(
        header=hdr, ns=ns, id=marker_id, type=marker_type, action=0,
        pose=poses(np.zeros((1, 3)), np.array([[0.0, 0.0, 0.0, 1.0]]))[0],
        scale=vector(x=scale[0], y=scale[1], z=scale[2]),
        color=msg_class("std_msgs/msg/ColorRGBA")(r=color[0], g=color[1], b=color[2],
                                                  a=color[3]),
        lifetime=msg_class("builtin_interfaces/msg/Duration")(sec=0, nanosec=0),
        frame_locked=True, points=[point(x=x, y=y, z=z) for x, y, z in points.tolist()],
        colors=[], texture_resource="",
        texture=msg_class("sensor_msgs/msg/CompressedImage")(
            header=header(0, ""), format="", data=np.zeros(0, dtype=np.uint8)),
        uv_coordinates=[], text="", mesh_resource="",
        mesh_file=msg_class("visualization_msgs/msg/MeshFile")(
            filename="", data=np.zeros(0, dtype=np.uint8)),
        mesh_use_embedded_materials=False)


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
                                   poses=poses(positions[samples:-1], turned[samples:-1])),
        "body_markers": msg_class("visualization_msgs/msg/MarkerArray")(markers=[
            marker(hdr, "tdcm_body", 0, 4, (2.0 * result.design.R_outer, 0.0, 0.0),
                   (0.85, 0.85, 0.9, 0.8), positions[:samples]),
            marker(hdr, "tdcm_predicted_markers", 1, 7, (0.002, 0.002, 0.002),
                   (1.0, 0.2, 0.8, 1.0), positions[samples:-1])])}
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
        assert direct == expected, (index, stamp, frame, roll)
        tip_only = dict(midline_messages(result, stamp_ns=stamp, frame_id=frame,
                                         samples=samples, marker_s=marker_s, marker_radius=radius,
                                         marker_side_rad=side, roll=roll, drawn=False))
        assert tip_only == {"tip_pose": expected["tip_pose"]}


@pytest.mark.filterwarnings("ignore:invalid value:RuntimeWarning")  # NaN drawn
@settings(max_examples=150)
@given(index=st.integers(0, len(RESULTS) - 1), stamp=DRAWN_STAMPS, frame=DRAWN_FRAMES,
       roll=DRAWN_ROLLS, samples=st.integers(2, 80),
       arcs=st.lists(st.floats(0.0, DESIGN.length), max_size=6),
       radius=st.one_of(st.floats(0.0, 0.01), st.sampled_from(ODD)),
       side=st.floats(-math.pi, math.pi))
def test_drawn_shapes_bytes_equal_the_objects_serialised(
        index: int, stamp: int, frame: str, roll: float, samples: int, arcs: list[float],
        radius: float, side: float) -> None:
    """Any sample and marker count (none too); a radius of NaN or infinity puts NaN and
    infinities into the marker points."""
    marker_s = np.array(arcs, dtype=float)
    direct = dict(midline_messages(RESULTS[index], stamp_ns=stamp, frame_id=frame,
                                   samples=samples, marker_s=marker_s, marker_radius=radius,
                                   marker_side_rad=side, roll=roll))
    assert direct == oracle_shape(RESULTS[index], stamp, frame, samples, marker_s, radius, side,
                                  roll)


def oracle_band(spread: ShapeSpread, result: Any, stamp_ns: int, frame_id: str, roll: float,
                confidence: float) -> list[tuple[str, bytes]]:
    """The tip with covariance and the band as objects (the node's former builders)."""
    hdr = header(stamp_ns, frame_id)
    turn = roll_points(np.eye(3), roll).T
    covariance = np.zeros((6, 6))
    covariance[:3, :3] = turn @ spread.covariances[-1] @ turn.T
    normal = turn @ np.array([0.0, 1.0, 0.0])
    covariance[3:, 3:] = spread.tip_angle_variance * np.outer(normal, normal)
    tip = poses(roll_points(result.tip_position, roll)[None],
                roll_quaternions(result.tip_quaternion, roll)[None])[0]
    outer, inner = (roll_points(edge, roll) for edge in band_edges(spread, confidence))
    corners = np.stack([outer[:-1], inner[:-1], outer[1:], inner[:-1], inner[1:], outer[1:]],
                       axis=1).reshape(-1, 3)
    return [("tip_pose_with_covariance", serialize(
                msg_class("geometry_msgs/msg/PoseWithCovarianceStamped")(
                    header=hdr, pose=msg_class("geometry_msgs/msg/PoseWithCovariance")(
                        pose=tip, covariance=covariance.ravel())))),
            ("shape_band", serialize(marker(hdr, "tdcm_band", 0, 11, (1.0, 1.0, 1.0),
                                            (0.2, 0.5, 1.0, 0.35), corners)))]


@pytest.mark.filterwarnings("ignore:invalid value:RuntimeWarning")  # NaN drawn
@settings(max_examples=150)
@given(index=st.integers(0, len(RESULTS) - 1), stamp=DRAWN_STAMPS, frame=DRAWN_FRAMES,
       roll=DRAWN_ROLLS, samples=st.integers(2, 60), seed=st.integers(0, 2**32 - 1),
       spread_m=st.one_of(st.floats(0.0, 1e-2), st.sampled_from(ODD)),
       tip_variance=st.one_of(st.floats(0.0, 1e-2), st.sampled_from(ODD)),
       confidence=st.floats(1e-6, 1.0 - 1e-9))
def test_band_bytes_equal_the_objects_serialised(
        index: int, stamp: int, frame: str, roll: float, samples: int, seed: int,
        spread_m: float, tip_variance: float, confidence: float) -> None:
    """Covariances of any size (NaN and infinities too) and confidences."""
    result = RESULTS[index]
    s = np.linspace(0.0, result.design.length, samples)
    root = np.random.default_rng(seed).normal(size=(samples, 3, 3)) * spread_m
    spread = ShapeSpread(s, result.pose_at(s)[0], root @ root.transpose(0, 2, 1), tip_variance)
    direct = list(uncertainty_messages(spread, result, stamp_ns=stamp, frame_id=frame, roll=roll,
                                       confidence=confidence))
    assert direct == oracle_band(spread, result, stamp, frame, roll, confidence)


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


@pytest.mark.parametrize("frame", FRAMES)
def test_markers_of_no_points_and_of_non_finite_values(frame: str) -> None:
    """Markers of any namespace padding, no points, NaN, infinities, -0 and subnormals, alone
    and as an array."""
    hdr = header(STAMPS[2], frame)
    odd = np.array([ODD[:3], ODD[3:]] * 2)
    for count, ns in enumerate(FRAMES):
        style = MarkerStyle(ns, count - 3, count + 4, (ODD[count % 6:] + (0.1,) * 3)[:3],
                            (0.1, 0.2, 0.3, 0.4))
        for points in (np.zeros((0, 3)), odd[:1], odd[count % 4:]):
            expected = marker(hdr, ns, count - 3, count + 4, style.scale, style.color, points)
            direct = marker_cdr(cdr_header(STAMPS[2], frame), style, points)
            assert direct == serialize(expected)
            pair = marker_array_cdr(cdr_header(STAMPS[2], frame), [(style, points)] * 2)
            assert pair == serialize(msg_class("visualization_msgs/msg/MarkerArray")(
                markers=[expected, expected]))
    empty = serialize(msg_class("visualization_msgs/msg/MarkerArray")(markers=[]))
    assert marker_array_cdr(cdr_header(STAMPS[2], frame), []) == empty
