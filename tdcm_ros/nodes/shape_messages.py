"""Build the model node's ROS messages from a :class:`SolveResult`, as CDR bytes.

All poses are in the frame given as ``frame_id`` (``tdcm_base`` by default, see doc/explanation/frames.md),
positions in m, orientations as quaternions of the body frame (z axis = midline tangent), the
planar shape turned by the roll (rad) about the base +z axis (:mod:`tdcm_ros.model.roll`).
The model node does this for every input (see bench_latency.py), so the pose messages
(``Path``, ``PoseArray``, ``PoseStamped``) and the markers (``visualization_msgs/Marker``,
:func:`write_marker`) are written as CDR straight from the arrays
(:class:`~tdcm_ros.bagio.CdrWriter`, the bytes rosbags would give), one ``pose_at`` call per
result.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import CdrWriter, cdr_header, cdr_string
from tdcm_ros.model import SolveResult, offset_points, roll_poses

Array = NDArray[np.float64]


def header(stamp_ns: int, frame_id: str) -> dict[str, Any]:
    """A ``std_msgs/Header`` dict for ``stamp_ns`` (ns since the epoch)."""
    return {"stamp": {"sec": stamp_ns // 1_000_000_000, "nanosec": stamp_ns % 1_000_000_000},
            "frame_id": frame_id}


def stamp_ns_of(message: Any) -> int:
    """The header stamp of ``message`` (ns since the epoch; 0 when never set)."""
    return int(message.header.stamp.sec) * 1_000_000_000 + int(message.header.stamp.nanosec)


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


LINE_STRIP, SPHERE_LIST, TRIANGLE_LIST = 4, 7, 11  #: ``visualization_msgs/Marker`` types
_IDS = struct.Struct("<3i")  # id, type, action (ADD: 0)
_POSE_SCALE = struct.Struct("<10d")  # pose (identity), scale
_LOOK = struct.Struct("<4fiI?")  # color, lifetime (0: forever), frame_locked
_IDENTITY = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def _empty_marker_tail() -> bytes:
    """A ``Marker``'s fields after ``points``, all empty, at a 4-aligned position (they align
    to 4 at most, so the bytes are the same at any such position)."""
    writer = CdrWriter()
    writer.uint32(0)  # colors
    writer.raw(cdr_string(""))  # texture_resource
    writer.header(0, "")  # texture (sensor_msgs/CompressedImage): header,
    writer.raw(cdr_string(""))  # format
    writer.uint32(0)  # and data
    writer.uint32(0)  # uv_coordinates
    writer.raw(cdr_string(""))  # text
    writer.raw(cdr_string(""))  # mesh_resource
    writer.raw(cdr_string(""))  # mesh_file (visualization_msgs/MeshFile): filename
    writer.uint32(0)  # and data
    writer.raw(b"\x00", 1)  # mesh_use_embedded_materials
    return writer.data()[4:]


_MARKER_TAIL = _empty_marker_tail()


@dataclass(frozen=True)
class MarkerStyle:
    """What a ``visualization_msgs/Marker`` of the model node keeps from one message to the
    next: namespace, id, type (e.g. :data:`LINE_STRIP`), scale (m) and color (RGBA, 0..1)."""

    ns: str
    marker_id: int
    marker_type: int
    scale: tuple[float, float, float]
    color: tuple[float, float, float, float]


def write_marker(writer: CdrWriter, hdr: bytes, style: MarkerStyle, points: Array) -> None:
    """A ``visualization_msgs/Marker`` (Jazzy) to ``writer``: header ``hdr``
    (:func:`cdr_header`), ``style``, action ADD, identity pose, lifetime 0, frame locked, the
    ``points`` (k, 3) m; no per-point colors, texture, uv coordinates, text or mesh."""
    writer.raw(hdr)
    writer.raw(cdr_string(style.ns))
    writer.raw(_IDS.pack(style.marker_id, style.marker_type, 0))
    writer.raw(_POSE_SCALE.pack(*_IDENTITY, *style.scale), 8)
    writer.raw(_LOOK.pack(*style.color, 0, 0, True))
    writer.uint32(len(points))
    writer.records(b"", points)
    writer.raw(_MARKER_TAIL)


def marker_cdr(hdr: bytes, style: MarkerStyle, points: Array) -> bytes:
    """CDR of one ``visualization_msgs/Marker`` (see :func:`write_marker`)."""
    writer = CdrWriter()
    write_marker(writer, hdr, style, points)
    return writer.data()


def marker_array_cdr(hdr: bytes, markers: list[tuple[MarkerStyle, Array]]) -> bytes:
    """CDR of a ``visualization_msgs/MarkerArray``: a marker of header ``hdr`` per
    ``(style, points)`` (see :func:`write_marker`)."""
    writer = CdrWriter()
    writer.uint32(len(markers))
    for style, points in markers:
        write_marker(writer, hdr, style, points)
    return writer.data()


#: The predicted markers as spheres (``body_markers``' second marker).
PREDICTED_MARKERS = MarkerStyle("tdcm_predicted_markers", 1, SPHERE_LIST, (0.002, 0.002, 0.002),
                                (1.0, 0.2, 0.8, 1.0))


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
    body = MarkerStyle("tdcm_body", 0, LINE_STRIP, (2.0 * result.design.R_outer, 0.0, 0.0),
                       (0.85, 0.85, 0.9, 0.8))
    yield "body_markers", marker_array_cdr(hdr, [(body, poses[:samples, :3]),
                                                 (PREDICTED_MARKERS, poses[samples:-1, :3])])
