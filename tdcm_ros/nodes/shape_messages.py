"""Build the model node's ROS messages (rosbags objects) from a :class:`SolveResult`.

All poses are in the frame given as ``frame_id`` (``tdcm_base`` by default, see README Frames),
positions in m, orientations as quaternions of the body frame (z axis = midline tangent).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import SolveResult

Array = NDArray[np.float64]


def header(stamp_ns: int, frame_id: str) -> dict[str, Any]:
    """A ``std_msgs/Header`` dict for ``stamp_ns`` (ns since the epoch)."""
    return {"stamp": {"sec": stamp_ns // 1_000_000_000, "nanosec": stamp_ns % 1_000_000_000},
            "frame_id": frame_id}


def _poses(positions: Array, quats: Array) -> list[dict[str, Any]]:
    return [{"position": {"x": float(p[0]), "y": float(p[1]), "z": float(p[2])},
             "orientation": {"x": float(q[0]), "y": float(q[1]), "z": float(q[2]),
                             "w": float(q[3])}}
            for p, q in zip(positions, quats, strict=True)]


def surface_points(result: SolveResult, s: Array, radius: float, side_rad: float
                   ) -> tuple[Array, Array]:
    """Points at arc lengths ``s`` (m), ``radius`` (m) off the midline at angle ``side_rad``
    around the body z axis from the body x axis (0 = tendon side); with their orientations."""
    positions, quats = result.pose_at(s)
    theta = 2.0 * np.arctan2(quats[:, 1], quats[:, 3])
    body_x = np.stack([np.cos(theta), np.zeros_like(theta), -np.sin(theta)], axis=1)
    body_y = np.array([0.0, 1.0, 0.0])
    offset = radius * (np.cos(side_rad) * body_x + np.sin(side_rad) * body_y)
    return positions + offset, quats


def midline_messages(result: SolveResult, *, stamp_ns: int, frame_id: str, samples: int,
                     marker_s: Array, marker_radius: float, marker_side_rad: float
                     ) -> dict[str, Any]:
    """Messages keyed by topic: ``midline``, ``midline_poses``, ``tip_pose``,
    ``predicted_markers`` and ``body_markers``."""
    hdr = header(stamp_ns, frame_id)
    s = np.linspace(0.0, result.design.length, samples)
    positions, quats = result.pose_at(s)
    poses = _poses(positions, quats)
    markers_xyz, markers_q = surface_points(result, marker_s, marker_radius, marker_side_rad)
    tip = _poses(result.tip_position[None, :], result.tip_quaternion[None, :])[0]
    diameter = 2.0 * result.design.R_outer
    body = {
        "header": hdr, "ns": "tdcm_body", "id": 0, "type": 4, "action": 0,
        "pose": {"orientation": {"w": 1.0}}, "scale": {"x": diameter},
        "color": {"r": 0.85, "g": 0.85, "b": 0.9, "a": 0.8}, "frame_locked": True,
        "points": [pose["position"] for pose in poses],
    }
    spheres = {
        "header": hdr, "ns": "tdcm_predicted_markers", "id": 1, "type": 7, "action": 0,
        "pose": {"orientation": {"w": 1.0}}, "scale": {"x": 0.002, "y": 0.002, "z": 0.002},
        "color": {"r": 1.0, "g": 0.2, "b": 0.8, "a": 1.0}, "frame_locked": True,
        "points": [p["position"] for p in _poses(markers_xyz, markers_q)],
    }
    return {
        "midline": from_dict("nav_msgs/msg/Path", {
            "header": hdr, "poses": [{"header": hdr, "pose": pose} for pose in poses]}),
        "midline_poses": from_dict("geometry_msgs/msg/PoseArray", {"header": hdr, "poses": poses}),
        "tip_pose": from_dict("geometry_msgs/msg/PoseStamped", {"header": hdr, "pose": tip}),
        "predicted_markers": from_dict("geometry_msgs/msg/PoseArray", {
            "header": hdr, "poses": _poses(markers_xyz, markers_q)}),
        "body_markers": from_dict("visualization_msgs/msg/MarkerArray",
                                  {"markers": [body, spheres]}),
    }
