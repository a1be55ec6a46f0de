"""Build the model node's ROS messages from a :class:`SolveResult`, as CDR bytes.

All poses are in the frame given as ``frame_id`` (``tdcm_base`` by default, see doc/explanation/frames.md),
positions in m, orientations as quaternions of the body frame (z axis = midline tangent), the
planar shape turned by the roll (rad) about the base +z axis (:mod:`tdcm_ros.model.roll`).
The model node does this for every input (see bench_latency.py), so the pose messages
(``Path``, ``PoseArray``, ``PoseStamped``) are written as CDR straight from the pose arrays
(:class:`~tdcm_ros.bagio.CdrWriter`, the bytes rosbags would give), one ``pose_at`` call per
result; the marker messages are built from the typestore classes (not through ``from_dict``)
and serialised.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import CdrWriter, cdr_header, from_dict, msg_class, serialize
from tdcm_ros.model import SolveResult, offset_points, roll_poses

Array = NDArray[np.float64]


def header(stamp_ns: int, frame_id: str) -> dict[str, Any]:
    """A ``std_msgs/Header`` dict for ``stamp_ns`` (ns since the epoch)."""
    return {"stamp": {"sec": stamp_ns // 1_000_000_000, "nanosec": stamp_ns % 1_000_000_000},
            "frame_id": frame_id}


def stamp_ns_of(message: Any) -> int:
    """The header stamp of ``message`` (ns since the epoch; 0 when never set)."""
    return int(message.header.stamp.sec) * 1_000_000_000 + int(message.header.stamp.nanosec)


def header_msg(stamp_ns: int, frame_id: str) -> Any:
    """A ``std_msgs/Header`` message object for ``stamp_ns`` (ns since the epoch)."""
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return msg_class("std_msgs/msg/Header")(
        stamp=msg_class("builtin_interfaces/msg/Time")(sec=sec, nanosec=nanosec),
        frame_id=frame_id)


def _pose_rows(positions: Array, quats: Array) -> Array:
    """``geometry_msgs/Pose`` fields in CDR order (k, 7): position (m), then quaternion xyzw."""
    return np.hstack([positions, quats])


def pose_stamped_cdr(hdr: bytes, pose: Array) -> bytes:
    """CDR of a ``geometry_msgs/PoseStamped``: header ``hdr`` (:func:`cdr_header`), ``pose`` (7,)
    as :func:`_pose_rows` orders it."""
    writer = CdrWriter()
    writer.records(hdr, pose[None])
    return writer.data()


def path_cdr(hdr: bytes, poses: Array) -> bytes:
    """CDR of a ``nav_msgs/Path``: header ``hdr``, one ``PoseStamped`` of that header per row of
    ``poses`` (k, 7)."""
    writer = CdrWriter()
    writer.raw(hdr)
    writer.uint32(len(poses))
    writer.records(hdr, poses)
    return writer.data()


def pose_array_cdr(hdr: bytes, poses: Array) -> bytes:
    """CDR of a ``geometry_msgs/PoseArray``: header ``hdr``, a pose per row of ``poses`` (k, 7)."""
    writer = CdrWriter()
    writer.raw(hdr)
    writer.uint32(len(poses))
    writer.records(b"", poses)
    return writer.data()


def _points(poses: Array) -> list[Any]:
    """``geometry_msgs/Point`` objects of the positions (m) of ``poses`` (k, 7)."""
    point = msg_class("geometry_msgs/msg/Point")
    return [point(x=x, y=y, z=z) for x, y, z in poses[:, :3].tolist()]


@lru_cache(maxsize=16)
def _marker_template(ns: str, marker_id: int, marker_type: int, scale: tuple[float, float, float],
                     color: tuple[float, float, float, float]) -> Any:
    return from_dict("visualization_msgs/msg/Marker", {
        "ns": ns, "id": marker_id, "type": marker_type, "action": 0,
        "pose": {"orientation": {"w": 1.0}}, "scale": dict(zip("xyz", scale, strict=True)),
        "color": dict(zip("rgba", color, strict=True)), "frame_locked": True})


def marker_msg(hdr: Any, ns: str, marker_id: int, marker_type: int,
            scale: tuple[float, float, float], color: tuple[float, float, float, float],
            points: list[Any]) -> Any:
    """A ``visualization_msgs/Marker``: a cached template with this header and points."""
    return replace(_marker_template(ns, marker_id, marker_type, scale, color), header=hdr,
                   points=points)


def midline_messages(result: SolveResult, *, stamp_ns: int, frame_id: str, samples: int,
                     marker_s: Array, marker_radius: float, marker_side_rad: float,
                     roll: float = 0.0, drawn: bool = True) -> Iterator[tuple[str, bytes]]:
    """``(topic, CDR bytes)`` for ``midline``, ``midline_poses``, ``tip_pose``,
    ``predicted_markers`` and ``body_markers``, in that order, each built when the previous one
    has been taken (so ``midline`` can be sent before the rest exist), the shape rolled by
    ``roll`` (rad); ``drawn=False``: ``tip_pose`` alone (nothing else is built)."""
    hdr = cdr_header(stamp_ns, frame_id)
    if not drawn:
        position, quat = roll_poses(result.tip_position[None], result.tip_quaternion[None], roll)
        yield "tip_pose", pose_stamped_cdr(hdr, _pose_rows(position, quat)[0])
        return
    s = np.linspace(0.0, result.design.length, samples)
    planar, planar_quats = result.pose_at(np.concatenate([s, np.asarray(marker_s, dtype=float)]))
    planar[samples:] = offset_points(planar[samples:], planar_quats[samples:], marker_radius,
                                     marker_side_rad)
    # midline, markers and tip turned in one call: rows [0, samples), [samples, -1), -1
    poses = _pose_rows(*roll_poses(np.vstack([planar, result.tip_position]),
                                   np.vstack([planar_quats, result.tip_quaternion]), roll))
    yield "midline", path_cdr(hdr, poses[:samples])
    yield "midline_poses", pose_array_cdr(hdr, poses[:samples])
    yield "tip_pose", pose_stamped_cdr(hdr, poses[-1])
    yield "predicted_markers", pose_array_cdr(hdr, poses[samples:-1])
    header_object = header_msg(stamp_ns, frame_id)
    body = marker_msg(header_object, "tdcm_body", 0, 4, (2.0 * result.design.R_outer, 0.0, 0.0),
                      (0.85, 0.85, 0.9, 0.8), _points(poses[:samples]))
    spheres = marker_msg(header_object, "tdcm_predicted_markers", 1, 7, (0.002, 0.002, 0.002),
                         (1.0, 0.2, 0.8, 1.0), _points(poses[samples:-1]))
    yield "body_markers", serialize(msg_class("visualization_msgs/msg/MarkerArray")(
        markers=[body, spheres]), "visualization_msgs/msg/MarkerArray")
