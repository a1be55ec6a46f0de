"""Decoding of the evaluation's CDR payloads: ``geometry_msgs/msg/WrenchStamped`` vectorised (1 kHz
tension bags), ``mocap4r2_msgs/msg/Markers``, ``std_msgs/msg/Float64`` and, of
``sensor_msgs/msg/JointState``, the tendon efforts and one joint's position (the roll).

WrenchStamped messages of equal length share one layout (same ``frame_id`` length), so each group is decoded
with one NumPy view: encapsulation header (4 bytes), ``stamp.sec`` (int32), ``stamp.nanosec``
(uint32), ``frame_id`` (uint32 length + bytes), then six float64 aligned to 8 bytes from the end
of the encapsulation header. Big-endian payloads go through the typestore.
"""

from __future__ import annotations

import struct
from collections import Counter
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import CDR_LITTLE_ENDIAN, BagError, cdr_align, deserialize

_TYPE = "geometry_msgs/msg/WrenchStamped"


def wrench_force_z(payloads: Sequence[bytes]) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Header stamps (ns) and ``wrench.force.z`` (N) of WrenchStamped CDR payloads."""
    stamps = np.zeros(len(payloads), dtype=np.int64)
    force = np.zeros(len(payloads))
    groups: dict[int, list[int]] = {}
    for i, data in enumerate(payloads):
        groups.setdefault(len(data) if data[:2] in CDR_LITTLE_ENDIAN else -1, []).append(i)
    for size, rows in groups.items():
        idx = np.asarray(rows)
        if size < 0 or not _decode_group(payloads, idx, size, stamps, force):
            for i in rows:
                msg = deserialize(payloads[i], _TYPE)
                stamps[i] = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
                force[i] = msg.wrench.force.z
    return stamps, force


def _decode_group(payloads: Sequence[bytes], rows: NDArray[np.int64], size: int,
                  stamps: NDArray[np.int64], force: NDArray[np.float64]) -> bool:
    """Decode little-endian payloads of one ``size``; False when their layout disagrees."""
    if size < 16:
        raise BagError(f"{_TYPE} payload of {size} bytes is too short")
    raw = np.frombuffer(b"".join(payloads[i] for i in rows), dtype=np.uint8).reshape(-1, size)
    name_len = raw[:, 12:16].copy().view("<u4")[:, 0]
    if np.any(name_len != name_len[0]):
        return False
    body = 12 + int(name_len[0])  # end of frame_id, relative to the CDR body
    start = 4 + ((body + 7) // 8) * 8 + 16  # force.z: third float64 after alignment
    if start + 8 > size:
        return False
    sec = raw[:, 4:8].copy().view("<i4")[:, 0].astype(np.int64)
    nsec = raw[:, 8:12].copy().view("<u4")[:, 0].astype(np.int64)
    stamps[rows] = sec * 1_000_000_000 + nsec
    force[rows] = raw[:, start:start + 8].copy().view("<f8")[:, 0]
    return True


_MARKERS_TYPE = "mocap4r2_msgs/msg/Markers"
_U32 = struct.Struct("<I")
_I32 = struct.Struct("<i")
_XYZ = struct.Struct("<3d")


def _string(data: bytes, pos: int) -> tuple[str, int]:
    pos = cdr_align(pos, 4)
    (length,) = _U32.unpack_from(data, 4 + pos)
    start = 4 + pos + 4
    return data[start:start + max(length - 1, 0)].decode("utf-8"), pos + 4 + length


def _markers_le(data: bytes) -> MarkersFrame:
    sec, nsec = struct.unpack_from("<iI", data, 4)
    frame_id, pos = _string(data, 8)
    pos = cdr_align(pos, 4) + 4  # frame_number
    (count,) = _U32.unpack_from(data, 4 + pos)
    pos += 4
    names: list[str] = []
    xyz: list[tuple[float, float, float]] = []
    for _ in range(count):
        pos = cdr_align(pos + 1, 4) + 4  # id_type (int8), marker_index (int32)
        name, pos = _string(data, pos)
        pos = cdr_align(pos, 8)
        xyz.append(_XYZ.unpack_from(data, 4 + pos))
        names.append(name)
        pos += 24
    if 4 + pos > len(data):
        raise BagError(f"{_MARKERS_TYPE} payload shorter than its content")
    return sec * 1_000_000_000 + nsec, frame_id, names, xyz


MarkersFrame = tuple[int, str, list[str], list[tuple[float, float, float]]]
"""Header stamp (ns), frame id, marker names and positions (m) of one Markers message."""


def markers_frame(data: bytes) -> MarkersFrame:
    """Decode a ``mocap4r2_msgs/msg/Markers`` CDR payload (little-endian fast path)."""
    if data[:2] in CDR_LITTLE_ENDIAN:
        try:
            return _markers_le(data)
        except (struct.error, UnicodeDecodeError, BagError):
            pass
    msg = deserialize(data, _MARKERS_TYPE)
    return (msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec, msg.header.frame_id,
            [m.marker_name for m in msg.markers],
            [(m.translation.x, m.translation.y, m.translation.z) for m in msg.markers])


def float64_data(payloads: Sequence[bytes]) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Zero stamps (a ``std_msgs/msg/Float64`` has no header: the caller takes the log times)
    and ``data`` (N) of Float64 CDR payloads."""
    values = np.array([float(deserialize(data, "std_msgs/msg/Float64").data)
                       for data in payloads])
    return np.zeros(len(payloads), dtype=np.int64), values


def joint_efforts(payloads: Sequence[bytes], names: Sequence[str], present: Counter[str]
                  ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Header stamps (ns) and the efforts (n, J) N of the joints ``names`` in
    ``sensor_msgs/msg/JointState`` CDR payloads (NaN where a message has no effort for one);
    each joint name a message gives an effort for is counted in ``present``."""
    column = {name: j for j, name in enumerate(names)}
    stamps = np.zeros(len(payloads), dtype=np.int64)
    efforts = np.full((len(payloads), len(names)), np.nan)
    for i, data in enumerate(payloads):
        msg = deserialize(data, "sensor_msgs/msg/JointState")
        stamps[i] = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        for name, effort in zip(msg.name, np.asarray(msg.effort, dtype=float).tolist(),
                                strict=False):  # a name past the efforts has none
            present[name] += 1
            if (j := column.get(name)) is not None:
                efforts[i, j] = effort
    return stamps, efforts


def joint_positions(payloads: Sequence[bytes], joint: str
                    ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Header stamps (ns) and the position of ``joint`` (rad for the roll; NaN where a message
    does not name it or gives it no position) in ``sensor_msgs/msg/JointState`` CDR
    payloads."""
    stamps = np.zeros(len(payloads), dtype=np.int64)
    positions = np.full(len(payloads), np.nan)
    for i, data in enumerate(payloads):
        msg = deserialize(data, "sensor_msgs/msg/JointState")
        stamps[i] = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        names = list(msg.name)
        if joint in names and (k := names.index(joint)) < len(msg.position):
            positions[i] = float(msg.position[k])
    return stamps, positions
