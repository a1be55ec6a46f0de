"""Decoding of the evaluation's CDR payloads: ``geometry_msgs/msg/WrenchStamped`` vectorised (1 kHz
tension bags), ``mocap4r2_msgs/msg/Markers`` (vectorised over frames of one layout,
:func:`markers_groups`), ``std_msgs/msg/Float64`` and, of
``sensor_msgs/msg/JointState``, the tendon efforts and one joint's position (the roll).

WrenchStamped messages of equal length share one layout (same ``frame_id`` length), so each group is decoded
with one NumPy view: encapsulation header (4 bytes), ``stamp.sec`` (int32), ``stamp.nanosec``
(uint32), ``frame_id`` (uint32 length + bytes), then six float64 aligned to 8 bytes from the end
of the encapsulation header. Big-endian payloads go through the typestore.
"""

from __future__ import annotations

import struct
from collections import Counter
from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import (
    CDR_LITTLE_ENDIAN,
    BagError,
    PayloadRows,
    cdr_align,
    deserialize,
)

_TYPE = "geometry_msgs/msg/WrenchStamped"


def wrench_force_z(payloads: Sequence[bytes]) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Header stamps (ns) and ``wrench.force.z`` (N) of WrenchStamped CDR payloads."""
    stamps = np.zeros(len(payloads), dtype=np.int64)
    force = np.zeros(len(payloads))
    for rows, raw in _groups(payloads):
        if raw is None or not _decode_group(raw, rows, stamps, force):
            for i in rows.tolist():
                msg = deserialize(payloads[i], _TYPE)
                stamps[i] = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
                force[i] = msg.wrench.force.z
    return stamps, force


def _groups(payloads: Sequence[bytes]
            ) -> Iterator[tuple[NDArray[np.int64], NDArray[np.uint8] | None]]:
    """Indices of the payloads of each length with their bytes (a row each), little-endian
    ones; the rest in one group without bytes. A batch of one length, all little-endian (a
    recorder's), is one group found without a Python pass over the payloads (nor a copy:
    :class:`~tdcm_ros.bagio.PayloadRows` are read as they are)."""
    raw = payloads.rows if isinstance(payloads, PayloadRows) else None
    if raw is None:
        sizes = np.fromiter(map(len, payloads), np.int64, len(payloads))
        if sizes.size and sizes[0] >= 2 and np.all(sizes == sizes[0]):
            raw = np.frombuffer(b"".join(payloads), dtype=np.uint8).reshape(sizes.size, -1)
    if raw is not None and len(raw) and raw.shape[1] >= 2 and np.all(
            (raw[:, 0] == 0) & ((raw[:, 1] == 1) | (raw[:, 1] == 3))):  # CDR_LITTLE_ENDIAN
        yield np.arange(len(raw)), raw
        return
    groups: dict[int, list[int]] = {}
    for i, data in enumerate(payloads):
        groups.setdefault(len(data) if data[:2] in CDR_LITTLE_ENDIAN else -1, []).append(i)
    for size, rows in groups.items():
        yield np.asarray(rows), None if size < 0 else np.frombuffer(
            b"".join(payloads[i] for i in rows), dtype=np.uint8).reshape(-1, size)


def _decode_group(raw: NDArray[np.uint8], rows: NDArray[np.int64], stamps: NDArray[np.int64],
                  force: NDArray[np.float64]) -> bool:
    """Decode little-endian payloads of one length (``raw``: a row each, payloads ``rows``);
    False when their layout disagrees."""
    size = raw.shape[1]
    if size < 16:
        raise BagError(f"{_TYPE} payload of {size} bytes is too short")
    name_len = raw[:, 12:16].copy().view("<u4")[:, 0]
    if np.any(name_len != name_len[0]):
        return False
    body = 12 + int(name_len[0])  # end of frame_id, relative to the CDR body
    start = 4 + cdr_align(body, 8) + 16  # force.z: third float64 after alignment
    if start + 8 > size:
        return False
    stamps[rows] = _header_stamps(raw)
    force[rows] = raw[:, start:start + 8].copy().view("<f8")[:, 0]
    return True


def _header_stamps(raw: NDArray[np.uint8]) -> NDArray[np.int64]:
    """The header stamps (ns since the epoch) of little-endian payloads of one length (a row
    each) that start with a ``std_msgs/Header``."""
    sec = raw[:, 4:8].copy().view("<i4")[:, 0].astype(np.int64)
    nsec = raw[:, 8:12].copy().view("<u4")[:, 0].astype(np.int64)
    return sec * 1_000_000_000 + nsec


_MARKERS_TYPE = "mocap4r2_msgs/msg/Markers"
_U32 = struct.Struct("<I")
_XYZ = struct.Struct("<3d")


def _string(data: bytes, pos: int) -> tuple[str, int]:
    pos = cdr_align(pos, 4)
    (length,) = _U32.unpack_from(data, 4 + pos)
    start = 4 + pos + 4
    return data[start:start + max(length - 1, 0)].decode("utf-8"), pos + 4 + length


def _markers_le(data: bytes) -> tuple[MarkersFrame, list[int]]:
    """The frame of a little-endian Markers payload and the byte offset of each marker's
    position in it."""
    sec, nsec = struct.unpack_from("<iI", data, 4)
    frame_id, pos = _string(data, 8)
    pos = cdr_align(pos, 4) + 4  # frame_number
    (count,) = _U32.unpack_from(data, 4 + pos)
    pos += 4
    names: list[str] = []
    xyz: list[tuple[float, float, float]] = []
    offsets: list[int] = []
    for _ in range(count):
        pos = cdr_align(pos + 1, 4) + 4  # id_type (int8), marker_index (int32)
        name, pos = _string(data, pos)
        pos = cdr_align(pos, 8)
        offsets.append(4 + pos)
        xyz.append(_XYZ.unpack_from(data, 4 + pos))
        names.append(name)
        pos += 24
    if 4 + pos > len(data):
        raise BagError(f"{_MARKERS_TYPE} payload shorter than its content")
    return (sec * 1_000_000_000 + nsec, frame_id, names, xyz), offsets


MarkersFrame = tuple[int, str, list[str], list[tuple[float, float, float]]]
"""Header stamp (ns), frame id, marker names and positions (m) of one Markers message."""
MarkersGroup = tuple[NDArray[np.int64], NDArray[np.int64], str, list[str], NDArray[np.float64]]
"""Indices of Markers payloads sharing one layout (frame id, marker names, order), their
header stamps (ns), the frame id, the marker names and the positions (payloads, markers, 3) m."""


def markers_frame(data: bytes) -> MarkersFrame:
    """Decode a ``mocap4r2_msgs/msg/Markers`` CDR payload (little-endian fast path)."""
    if data[:2] in CDR_LITTLE_ENDIAN:
        try:
            return _markers_le(data)[0]
        except (struct.error, UnicodeDecodeError, BagError):
            pass
    msg = deserialize(data, _MARKERS_TYPE)
    return (msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec, msg.header.frame_id,
            [m.marker_name for m in msg.markers],
            [(m.translation.x, m.translation.y, m.translation.z) for m in msg.markers])


def markers_groups(payloads: Sequence[bytes]) -> Iterator[MarkersGroup]:
    """Markers payloads decoded a group at a time (:data:`MarkersGroup`): little-endian
    payloads of one length whose bytes differ only in the stamp, the frame number and the
    positions (a motion capture stream's frames with the same markers seen) are read with NumPy
    views; a big-endian payload, or one the fast path cannot parse, is a group of its own
    (:func:`markers_frame`)."""
    for rows, raw in _groups(payloads):
        if raw is None:
            yield from (_markers_one(payloads, i) for i in rows.tolist())
            continue
        while rows.size:  # each pass takes the first payload's layout
            found = _layout(payloads[int(rows[0])])
            if found is None:
                yield _markers_one(payloads, int(rows[0]))
                same = np.arange(rows.size) == 0
            else:
                layout, (_, frame, names, _), offsets = found
                same = np.all(raw[:, layout] == raw[0, layout], axis=1)
                yield _markers_group(rows[same], raw[same], frame, names, offsets)
            rows, raw = rows[~same], raw[~same]


def _markers_one(payloads: Sequence[bytes], i: int) -> MarkersGroup:
    """The group of payload ``i`` alone (:func:`markers_frame`)."""
    stamp, frame, names, xyz = markers_frame(payloads[i])
    return (np.array([i]), np.array([stamp], dtype=np.int64), frame, names,
            np.array(xyz, dtype=float).reshape(1, len(names), 3))


def _layout(first: bytes) -> tuple[NDArray[np.bool_], MarkersFrame, list[int]] | None:
    """Mask of the bytes of the little-endian Markers payload ``first`` that are neither the
    stamp, the frame number nor a position, its frame and its positions' offsets; None when
    the fast path cannot parse it."""
    try:
        frame, offsets = _markers_le(first)
    except (struct.error, UnicodeDecodeError, BagError):
        return None
    layout = np.ones(len(first), dtype=bool)
    layout[4:12] = False  # header stamp
    frame_number = 4 + cdr_align(_string(first, 8)[1], 4)
    layout[frame_number:frame_number + 4] = False
    for offset in offsets:
        layout[offset:offset + 24] = False
    return layout, frame, offsets


def _markers_group(rows: NDArray[np.int64], raw: NDArray[np.uint8], frame: str,
                   names: list[str], offsets: list[int]) -> MarkersGroup:
    """The group of the payloads ``raw`` (a row each, payloads ``rows``) of one layout: frame
    id ``frame``, markers ``names`` with their positions at byte ``offsets``."""
    xyz = np.stack([raw[:, o:o + 24].copy().view("<f8") for o in offsets], axis=1) \
        if offsets else np.zeros((len(rows), 0, 3))
    return rows, _header_stamps(raw), frame, names, xyz


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
                    ) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]:
    """Header stamps (ns), the position of ``joint`` (rad for the roll; NaN where a message
    names it without a position) and whether each message names ``joint`` at all, in
    ``sensor_msgs/msg/JointState`` CDR payloads (a robot's ``joint_states`` has publishers of
    other joints: their messages are not about this one)."""
    stamps = np.zeros(len(payloads), dtype=np.int64)
    positions = np.full(len(payloads), np.nan)
    named = np.zeros(len(payloads), dtype=bool)
    for i, data in enumerate(payloads):
        msg = deserialize(data, "sensor_msgs/msg/JointState")
        stamps[i] = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        names = list(msg.name)
        if joint in names:
            named[i] = True
            if (k := names.index(joint)) < len(msg.position):
                positions[i] = float(msg.position[k])
    return stamps, positions, named
