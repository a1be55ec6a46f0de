"""Build the model node's ROS messages (rosbags objects) from a :class:`SolveResult`.

All poses are in the frame given as ``frame_id`` (``tdcm_base`` by default, see doc/explanation/frames.md),
positions in m, orientations as quaternions of the body frame (z axis = midline tangent), the
planar shape turned by the roll (rad) about the base +z axis (:mod:`tdcm_ros.model.roll`).
Messages are built from the typestore classes directly (not through ``from_dict``), one
``pose_at`` call per result: the model node does this for every input (see bench_latency.py).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import from_dict, msg_class
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


def _poses(positions: Array, quats: Array) -> list[Any]:
    """``geometry_msgs/Pose`` objects for positions (k, 3) m and quaternions (k, 4) xyzw."""
    point = msg_class("geometry_msgs/msg/Point")
    quaternion = msg_class("geometry_msgs/msg/Quaternion")
    pose = msg_class("geometry_msgs/msg/Pose")
    return [pose(position=point(x=p[0], y=p[1], z=p[2]),
                 orientation=quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))
            for p, q in zip(positions.tolist(), quats.tolist(), strict=True)]


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
                     roll: float = 0.0, drawn: bool = True) -> Iterator[tuple[str, Any]]:
    """``(topic, message)`` for ``midline``, ``midline_poses``, ``tip_pose``,
    ``predicted_markers`` and ``body_markers``, in that order, each built when the previous one
    has been taken (so ``midline`` can be sent before the rest exist), the shape rolled by
    ``roll`` (rad); ``drawn=False``: ``tip_pose`` alone (nothing else is built). The messages
    share sub-objects (header, poses): serialise them, do not modify them."""
    if not drawn:
        position, quat = roll_poses(result.tip_position[None], result.tip_quaternion[None], roll)
        yield "tip_pose", msg_class("geometry_msgs/msg/PoseStamped")(
            header=header_msg(stamp_ns, frame_id), pose=_poses(position, quat)[0])
        return
    s = np.linspace(0.0, result.design.length, samples)
    planar, planar_quats = result.pose_at(np.concatenate([s, np.asarray(marker_s, dtype=float)]))
    planar[samples:] = offset_points(planar[samples:], planar_quats[samples:], marker_radius,
                                     marker_side_rad)
    # midline, markers and tip turned in one call: rows [0, samples), [samples, -1), -1
    positions, quats = roll_poses(np.vstack([planar, result.tip_position]),
                                  np.vstack([planar_quats, result.tip_quaternion]), roll)
    hdr = header_msg(stamp_ns, frame_id)
    pose_stamped = msg_class("geometry_msgs/msg/PoseStamped")
    pose_array = msg_class("geometry_msgs/msg/PoseArray")
    poses = _poses(positions[:samples], quats[:samples])
    yield "midline", msg_class("nav_msgs/msg/Path")(
        header=hdr, poses=[pose_stamped(header=hdr, pose=pose) for pose in poses])
    yield "midline_poses", pose_array(header=hdr, poses=poses)
    tip = _poses(positions[-1:], quats[-1:])[0]
    yield "tip_pose", pose_stamped(header=hdr, pose=tip)
    markers = _poses(positions[samples:-1], quats[samples:-1])
    yield "predicted_markers", pose_array(header=hdr, poses=markers)
    body = marker_msg(hdr, "tdcm_body", 0, 4, (2.0 * result.design.R_outer, 0.0, 0.0),
                   (0.85, 0.85, 0.9, 0.8), [p.position for p in poses])
    spheres = marker_msg(hdr, "tdcm_predicted_markers", 1, 7, (0.002, 0.002, 0.002),
                      (1.0, 0.2, 0.8, 1.0), [p.position for p in markers])
    yield "body_markers", msg_class("visualization_msgs/msg/MarkerArray")(
        markers=[body, spheres])
