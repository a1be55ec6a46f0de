"""CDR written directly, for hot paths: the bytes :func:`~tdcm_ros.bagio.serialize` gives for
the same message, without building message objects.

Little-endian plain CDR (XCDR1) as rosbags and the rmw layers write it: a 4-byte encapsulation
header, then each primitive aligned to its size counted from the end of that header, padding
bytes zero. :class:`CdrWriter` appends the pieces a message is made of; a run of records that
each end in float64 fields (``geometry_msgs/Pose``, ``PoseStamped``, ``TransformStamped``)
is written with NumPy in one go (:meth:`CdrWriter.records`). :class:`PayloadRows` holds payloads
of one length read from a bag as the rows of one array.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from functools import lru_cache
from typing import overload

import numpy as np
from numpy.typing import NDArray

#: Encapsulation header of little-endian plain CDR (``CDR_LE``, options 0).
ENCAPSULATION = b"\x00\x01\x00\x00"
#: First two bytes of the little-endian encapsulations (``CDR_LE``, ``PL_CDR_LE``).
CDR_LITTLE_ENDIAN = (b"\x00\x01", b"\x00\x03")
_U32 = struct.Struct("<I")
_STAMP = struct.Struct("<iI")


def cdr_align(pos: int, size: int) -> int:
    """Round ``pos`` (bytes after the encapsulation header) up to a multiple of ``size``."""
    return pos + (-pos) % size


def cdr_string(text: str) -> bytes:
    """A CDR ``string`` at a 4-aligned position: byte length with the NUL (uint32), UTF-8, NUL."""
    data = text.encode("utf-8")
    return _U32.pack(len(data) + 1) + data + b"\x00"


@lru_cache(maxsize=64)
def cdr_strings(texts: tuple[str, ...]) -> bytes:
    """A CDR ``string[]`` at a 4-aligned position: its length (uint32), then each string 4-aligned
    (see :func:`cdr_string`); cached: a node sends the same names with every message."""
    parts, pos = [_U32.pack(len(texts))], 4
    for text in texts:
        if padding := (-pos) % 4:
            parts.append(bytes(padding))
            pos += padding
        parts.append(item := cdr_string(text))
        pos += len(item)
    return b"".join(parts)


def cdr_header(stamp_ns: int, frame_id: str) -> bytes:
    """A ``std_msgs/Header`` at a 4-aligned position: ``stamp`` (sec int32, nanosec uint32) of
    ``stamp_ns`` (ns since the epoch) and ``frame_id``."""
    return _STAMP.pack(*divmod(stamp_ns, 1_000_000_000)) + cdr_string(frame_id)


class CdrWriter:
    """Appends CDR pieces after the encapsulation header; :meth:`data` gives the message."""

    def __init__(self) -> None:
        self._parts = [ENCAPSULATION]
        self._pos = 0  # bytes after the encapsulation header

    def _pad(self, size: int) -> None:
        padding = (-self._pos) % size
        if padding:
            self._parts.append(bytes(padding))
            self._pos += padding

    def raw(self, data: bytes, alignment: int = 4) -> None:
        """``data`` (a run of pieces starting with a ``alignment``-byte field) after padding."""
        self._pad(alignment)
        self._parts.append(data)
        self._pos += len(data)

    def header(self, stamp_ns: int, frame_id: str) -> None:
        """A ``std_msgs/Header`` (see :func:`cdr_header`)."""
        self.raw(cdr_header(stamp_ns, frame_id))

    def uint32(self, value: int) -> None:
        """A ``uint32`` (a sequence's length, too)."""
        self.raw(_U32.pack(value))

    def records(self, prefix: bytes | Sequence[bytes], values: NDArray[np.float64]) -> None:
        """A sequence's ``k`` elements (its length is the caller's), element ``i`` made of
        ``prefix`` (one for all, or ``prefix[i]``; pieces of 4-byte alignment, e.g. a header)
        then the float64 row ``values[i]`` (shape (k, m), aligned to 8)."""
        rows = np.ascontiguousarray(values, dtype="<f8")
        if not isinstance(prefix, bytes):
            for head, row in zip(prefix, rows, strict=True):
                self.raw(head)
                self.raw(row.tobytes(), 8)
            return
        if not len(rows):
            return
        self.raw(prefix)
        self.raw(rows[0].tobytes(), 8)  # the rest start 8-aligned: one layout for all
        if len(rows) > 1:
            lead = prefix + bytes((-len(prefix)) % 8)
            block = np.empty((len(rows) - 1, len(lead) + rows.shape[1] * 8), dtype=np.uint8)
            block[:, :len(lead)] = np.frombuffer(lead, dtype=np.uint8)
            block[:, len(lead):] = rows[1:].view(np.uint8)
            self._parts.append(block.tobytes())
            self._pos += block.size

    def data(self) -> bytes:
        """The message's bytes, encapsulation header first."""
        return b"".join(self._parts)


class PayloadRows(Sequence[bytes]):
    """CDR payloads of one length as the rows of an (n, length) uint8 array, as a bag reader
    gives a chunk's messages of one topic (``BagReader.raw_blocks`` of
    ``tdcm_ros.bagio.reader``): a sequence of bytes (each made when asked for) whose ``rows``
    NumPy decoders read at once."""

    def __init__(self, rows: NDArray[np.uint8]) -> None:
        if rows.ndim != 2:
            raise ValueError(f"payload rows of shape {rows.shape}; allowed: (n, length)")
        self.rows = rows

    def __len__(self) -> int:
        return len(self.rows)

    @overload
    def __getitem__(self, index: int) -> bytes: ...

    @overload
    def __getitem__(self, index: slice) -> PayloadRows: ...

    def __getitem__(self, index: int | slice) -> bytes | PayloadRows:
        if isinstance(index, slice):
            return PayloadRows(self.rows[index])
        return self.rows[index].tobytes()


def joint_state_cdr(stamp_ns: int, names: Sequence[str], position: Sequence[float],
                    velocity: Sequence[float], effort: Sequence[float], frame_id: str = ""
                    ) -> bytes:
    """The CDR :func:`~tdcm_ros.bagio.serialize` gives for a ``sensor_msgs/msg/JointState`` of
    these fields (rad or m, rad/s or m/s, N m or N), stamped ``stamp_ns`` (ns since the epoch)."""
    cdr = CdrWriter()
    cdr.header(stamp_ns, frame_id)
    cdr.raw(cdr_strings(tuple(names)))
    for values in (position, velocity, effort):
        array = np.asarray(values, dtype="<f8")
        cdr.uint32(array.size)
        if array.size:
            cdr.raw(array.tobytes(), 8)
    return cdr.data()
