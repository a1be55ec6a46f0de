"""Read rosbag2 bags (MCAP or sqlite3 storage) and bare ``.mcap`` files.

``open_bag(path)`` accepts a rosbag2 folder (with ``metadata.yaml``, or without one when the
writer was killed: its ``.mcap`` files are read) or one ``.mcap`` file. Message types come from
the Jazzy typestore plus ``msg_defs/``; a type the store does not know is registered from the
definition the bag embeds (MCAP schema encoding ``ros2msg`` or ``ros2idl``, as ``ros2 bag record``
writes). An MCAP file without a usable summary (writer killed: no footer, a half-written last
chunk) is read up to its last complete record, and the loss is reported in ``warnings``. A
chunk that fails its CRC, size or record checks (a flipped byte) is skipped: every file is
checked when it is opened, so ``warnings`` (what ``tdcm bag info`` prints) names each skipped
chunk before any message is read, and reading leaves the same chunks out.

:meth:`BagReader.raw_blocks` reads a complete MCAP file by its chunks' message indexes rather than
record by record: a chunk's messages of a topic at a time, each index entry checked against the
record it points to (no CRC covers the indexes; a chunk whose index does not match is walked).

Topic arguments may omit the leading ``/`` (``tension`` = ``/tension``). Times are ns since the
UNIX epoch. Every failure is a :class:`~tdcm_ros.bagio.errors.BagError` naming the file.
"""

from __future__ import annotations

import heapq
import io
import itertools
import os
import struct
import zlib
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from operator import itemgetter
from pathlib import Path
from typing import IO, Any

import lz4.frame
import numpy as np
import yaml
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, ChunkIndex, Schema
from mcap.summary import Summary
from rosbags.typesys import TypesysError, get_types_from_idl, get_types_from_msg

from tdcm_ros.bagio.cdr import PayloadRows
from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.qos import parse_profiles, recorded_qos
from tdcm_ros.bagio.typestore import typestore
from tdcm_ros.bagio.writer import OfferedQos
from tdcm_ros.yamlio import load_yaml

MCAP_MAGIC = b"\x89MCAP0\r\n"
SQLITE_MAGIC = b"SQLite format 3\x00"
METADATA_FILE = "metadata.yaml"

RawMessage = tuple[str, int, bytes]  # (topic, log time ns, CDR bytes)
RawBlock = tuple[str, np.ndarray, Sequence[bytes]]  # topic, log times ns (int64), CDR payloads


@dataclass(frozen=True)
class _TopicInfo:
    """A topic as one storage file declares it: type and embedded definition (may be empty)."""

    msgtype: str
    encoding: str
    definition: str


def _canonical_type(name: str) -> str:
    """``pkg/Name`` -> ``pkg/msg/Name``; other names unchanged."""
    parts = name.strip().split("/")
    return f"{parts[0]}/msg/{parts[1]}" if len(parts) == 2 else name.strip()


def _describe(error: BaseException) -> str:
    text = str(error).strip()
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


_RECORD = struct.Struct("<BQ")  # opcode, record length
_MESSAGE = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
_MESSAGE_HEAD = struct.Struct("<BQHIQ")  # a message record's opcode, length, channel, sequence, log
_CHUNK = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length
_INDEX = struct.Struct("<HI")  # message index: channel id, byte length of its (time, offset) pairs
_FOOTER = struct.Struct("<BQQQI")  # opcode, length, summary start, summary offset start, crc
_OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK, _OP_INDEX, _OP_DATA_END = \
    2, 3, 4, 5, 6, 7, 15

Unit = list[tuple[int, int, bytes]]  # (log time ns, channel id, data) of one chunk or record
_HEAD_BYTES = np.arange(_RECORD.size + _MESSAGE.size)  # a message record's head, from its start


class _Damaged(Exception):
    """A record of the data section is cut short or fails its check."""


#: Largest uncompressed chunk (bytes) believed from a file; writers use chunks of a few MB.
MAX_CHUNK_BYTES = 1 << 30
#: Bytes decompressed per step from a zstd or lz4 frame that does not declare its size.
_PIECE = 1 << 20
# What record parsers and decompressors raise on damaged bytes (lz4 raises RuntimeError).
_DAMAGE = (_Damaged, McapError, struct.error, ValueError, KeyError, IndexError, EOFError,
           RuntimeError, OverflowError, zstandard.ZstdError)


class _FileBytes:
    """An open file read by byte ranges on demand (``os.pread``): only the ranges asked for are
    in memory, where every page of a memory map that was read would count in the process's
    resident size until it is unmapped."""

    def __init__(self, stream: IO[bytes]) -> None:
        self._fd = stream.fileno()
        self._size = os.fstat(self._fd).st_size

    def __len__(self) -> int:
        return self._size

    def __getitem__(self, span: slice) -> bytes:
        start, stop, _ = span.indices(self._size)
        parts: list[bytes] = []
        while start < stop and (part := os.pread(self._fd, stop - start, start)):
            parts.append(part)
            start += len(part)
        return b"".join(parts)

    def unpack(self, layout: struct.Struct, pos: int) -> tuple[Any, ...]:
        """``layout`` at byte ``pos``; struct.error when the file ends first."""
        return layout.unpack(self[pos:pos + layout.size])


def _zstd(data: bytes, size: int) -> bytes:
    """The zstd frame ``data`` holding the chunk's ``size`` bytes. Memory follows what the data
    holds, never what a damaged field claims: a frame that declares its size (every writer's)
    must declare ``size`` and is decompressed at once; one that does not is read in pieces of
    :data:`_PIECE` bytes, up to ``size``. (Trusting the claim allocated up to
    :data:`MAX_CHUNK_BYTES` for a flipped byte: a MemoryError on a busy machine.)"""
    declared = zstandard.frame_content_size(data)
    if declared >= 0:
        if declared != size:
            raise _Damaged(f"chunk claims {size} bytes; its zstd frame holds {declared}")
        return zstandard.ZstdDecompressor().decompress(data, max_output_size=size)
    reader = zstandard.ZstdDecompressor().stream_reader(data, read_across_frames=True)
    parts: list[bytes] = []
    total = 0
    while piece := reader.read(_PIECE):
        total += len(piece)
        if total > size:
            raise _Damaged(f"chunk claims {size} bytes; its zstd data holds more")
        parts.append(piece)
    return b"".join(parts)


def _lz4(data: bytes, size: int) -> bytes:
    """The lz4 frame ``data`` holding the chunk's ``size`` bytes, by the rule of :func:`_zstd`:
    a frame that declares its content size must declare ``size``; one that does not is read in
    pieces of :data:`_PIECE` bytes, up to ``size``."""
    declared = int(lz4.frame.get_frame_info(data)["content_size"])  # 0: not declared
    if declared and declared != size:
        raise _Damaged(f"chunk claims {size} bytes; its lz4 frame holds {declared}")
    decompressor = lz4.frame.LZ4FrameDecompressor()
    parts = [decompressor.decompress(data, max_length=_PIECE)]
    total = len(parts[0])
    while not (decompressor.eof or decompressor.needs_input) and total <= size:
        parts.append(decompressor.decompress(b"", max_length=_PIECE))
        total += len(parts[-1])
    if total > size:
        raise _Damaged(f"chunk claims {size} bytes; its lz4 data holds more")
    if not decompressor.eof:
        raise _Damaged("the chunk's lz4 frame is cut short")
    return b"".join(parts)


def _decompress(compression: str, data: bytes, size: int) -> bytes:
    if not compression:
        return data
    if not 0 <= size <= MAX_CHUNK_BYTES:
        raise _Damaged(f"chunk claims {size} bytes uncompressed; allowed: 0..{MAX_CHUNK_BYTES}")
    if compression == "zstd":
        return _zstd(data, size)
    if compression == "lz4":
        return _lz4(data, size)
    raise _Damaged(f"unsupported chunk compression {compression!r}")


def _may_hold(index: ChunkIndex, wanted: set[int] | None) -> bool:
    """Whether the chunk of ``index`` may hold messages of the ``wanted`` channels (None: any).
    Its index lists a message index for each channel the chunk holds, when the writer wrote
    them (every writer here does; none listed: unknown, so it may); the summary holding the
    list is checked by its CRC at open. Reading one sparse topic (``/tf_static``) then
    decompresses and walks only its chunks, not every chunk of the bag."""
    offsets = index.message_index_offsets
    return wanted is None or not offsets or not wanted.isdisjoint(offsets)


def _payloads(content: bytes, data: np.ndarray, start: np.ndarray, end: np.ndarray
              ) -> Sequence[bytes]:
    """The payloads ``content[start:end]`` (``data``: its bytes as an array): the rows of one
    array when they have one length, else bytes each."""
    lengths = end - start
    if len(lengths) and np.all(lengths == lengths[0]):
        return PayloadRows(data[start[:, None] + np.arange(int(lengths[0]))])
    return [content[a:b] for a, b in zip(start.tolist(), end.tolist(), strict=True)]


def _unit_blocks(unit: Unit, names: dict[int, str]) -> list[RawBlock]:
    """The messages of a walked chunk, a block per topic, in log-time order."""
    unit.sort(key=itemgetter(0))
    parts: dict[str, list[tuple[int, bytes]]] = {}
    for log_time, channel, data in unit:
        parts.setdefault(names[channel], []).append((log_time, data))
    return [(topic, np.fromiter((t for t, _ in part), np.int64, len(part)),
             [data for _, data in part]) for topic, part in parts.items()]


class _McapSource:
    """One MCAP file, read by a linear pass over its data section (chunks checked by CRC).

    With a summary (footer, statistics, chunk indexes) the file is complete: damage found
    while reading is an error. Without one (writer killed), :meth:`_scan` finds at open where
    the readable part ends; reading stops there and ``warnings`` says how much survived.
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self.warnings: list[str] = []
        self.topics: dict[str, _TopicInfo] = {}
        self.counts: dict[str, int] = {}
        self.profiles: dict[str, list[Any]] = {}
        self._channels: dict[int, Channel] = {}
        self._schemas: dict[int, Schema] = {}
        self._types: dict[int, str] = {}
        self._size = path.stat().st_size
        self._last_end = -1
        self._chunks: list[ChunkIndex] = []
        self._skipped: set[int] = set()  # byte offsets of the chunks left out as damaged
        self._channel_counts: dict[int, int] = {}  # messages per channel, by the statistics
        self.ordered = True  # units (chunks, loose messages) do not overlap in time
        self.time_range: tuple[int, int] | None = None  # first and last log time (ns) read
        with path.open("rb") as stream:
            if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
                raise BagError(f"{path}: not an MCAP file (no MCAP magic at the start)")
            summary = self._summary(stream)
        self.complete = summary is not None
        if summary is not None:
            self._schemas = dict(summary.schemas)
            counts = summary.statistics.channel_message_counts if summary.statistics else {}
            for channel in summary.channels.values():
                self._declare(channel)
                self.counts[channel.topic] += counts.get(channel.id, 0)
            self._channel_counts = dict(counts)
            self._chunks = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
            for index in self._chunks:
                self._note_range(index.message_start_time, index.message_end_time)
            self._check_chunks()
        else:
            self._scan()

    def _summary(self, stream: IO[bytes]) -> Summary | None:
        """The summary when it indexes every message (chunk indexes and statistics), else None."""
        try:
            stream.seek(0)
            summary = SeekingReader(stream, validate_crcs=True,
                                    record_size_limit=self._size).get_summary()
        except (*_DAMAGE, OSError):  # no footer, bad footer or summary: the linear scan decides
            return None
        if summary is None or summary.statistics is None or not self._summary_crc_ok(stream) or (
                summary.statistics.message_count and not summary.chunk_indexes) or any(
                c not in summary.channels for c in summary.statistics.channel_message_counts):
            return None
        return summary

    def _summary_crc_ok(self, stream: IO[bytes]) -> bool:
        """The footer's summary CRC matches the summary section (or the writer left it 0)."""
        stream.seek(self._size - len(MCAP_MAGIC) - _FOOTER.size)
        _, _, start, _, crc = _FOOTER.unpack(stream.read(_FOOTER.size))
        if not crc:
            return True
        stream.seek(start)
        return zlib.crc32(stream.read(self._size - len(MCAP_MAGIC) - 4 - start)) == crc

    def _declare(self, channel: Channel) -> None:
        if channel.id in self._channels:
            return
        self._channels[channel.id] = channel
        schema = self._schemas.get(channel.schema_id)
        info = _TopicInfo(_canonical_type(schema.name) if schema else "",
                          schema.encoding if schema else "",
                          schema.data.decode("utf-8", "replace") if schema else "")
        self._types[channel.id] = info.msgtype
        self.profiles.setdefault(channel.topic, parse_profiles(
            channel.metadata.get("offered_qos_profiles", "")))
        known = self.topics.setdefault(channel.topic, info)
        self.counts.setdefault(channel.topic, 0)
        if known.msgtype != info.msgtype:
            self.warnings.append(f"{self.path}: topic {channel.topic} has several types "
                                 f"({known.msgtype}, {info.msgtype}); reading {known.msgtype}")

    def _note_range(self, start: int, end: int) -> None:
        first, last = self.time_range or (start, end)
        self.time_range = (min(first, start), max(last, end))
        self.ordered = self.ordered and start >= self._last_end
        self._last_end = max(self._last_end, end)

    def _records(self, block: bytes, wanted: set[int] | None) -> Unit:
        """Messages of a block of records (a chunk's content or one top-level record)."""
        out: Unit = []
        append, channels = out.append, self._channels
        head, head_end, data_start = _MESSAGE_HEAD.unpack_from, _MESSAGE_HEAD.size, \
            _RECORD.size + _MESSAGE.size
        pos, end = 0, len(block)
        while pos < end:
            if whole := pos + head_end <= end:  # most records are messages: one unpack
                op, length, channel, _, log_time = head(block, pos)
            else:
                (op, length), channel, log_time = _RECORD.unpack_from(block, pos), 0, 0
            body, after = pos + 9, pos + 9 + length
            if after > end:
                raise _Damaged(f"a record (opcode {op:#x}) runs {after - end} bytes past its chunk")
            if op == _OP_MESSAGE:
                if not whole:  # its head runs past the block: struct.error, as damage
                    channel, _, log_time, _ = _MESSAGE.unpack_from(block, body)
                if channel in channels and (wanted is None or channel in wanted):
                    append((log_time, channel, block[pos + data_start:after]))
            elif op == _OP_SCHEMA:
                schema = Schema.read(ReadDataStream(io.BytesIO(block[body:after])))
                self._schemas.setdefault(schema.id, schema)
            elif op == _OP_CHANNEL:
                self._declare(Channel.read(ReadDataStream(io.BytesIO(block[body:after]))))
            pos = after
        return out

    @staticmethod
    def _content(body: bytes) -> tuple[bytes, bool]:
        """A chunk body's records, decompressed and checked; and whether a CRC checked them."""
        _, _, size, crc, name_length = _CHUNK.unpack_from(body, 0)
        pos = _CHUNK.size + name_length
        compression = body[_CHUNK.size:pos].decode()
        (stored,) = struct.unpack_from("<Q", body, pos)
        if pos + 8 + stored != len(body):
            raise _Damaged("chunk length fields disagree")
        content = _decompress(compression, body[pos + 8:], size)
        if len(content) != size or (crc and zlib.crc32(content) != crc):
            raise _Damaged("chunk CRC or size mismatch")
        return content, bool(crc)

    def _chunk(self, body: bytes, wanted: set[int] | None) -> Unit:
        unit = self._records(self._content(body)[0], wanted)
        unit.sort(key=itemgetter(0))
        return unit

    @staticmethod
    def _chunk_body(buf: _FileBytes, index: ChunkIndex) -> bytes:
        """The body of the chunk record the summary indexes at ``index.chunk_start_offset``."""
        pos, end = index.chunk_start_offset, index.chunk_start_offset + index.chunk_length
        if pos < 0 or end > len(buf) or end < pos + 9:
            raise _Damaged(f"the indexed chunk at byte {pos} lies outside the file")
        op, length = buf.unpack(_RECORD, pos)
        if op != _OP_CHUNK or pos + 9 + length != end:
            raise _Damaged(f"no chunk record of {index.chunk_length} bytes at byte {pos}")
        return buf[pos + 9:end]

    def _check_chunks(self) -> None:
        """Check every indexed chunk (size, CRC; records too where no CRC was written) and
        skip the damaged ones, before any message is read."""
        with self.path.open("rb") as stream:
            buf = _FileBytes(stream)
            for index in self._chunks:
                try:
                    content, crc_checked = self._content(self._chunk_body(buf, index))
                    if not crc_checked:
                        self._records(content, set())
                except _DAMAGE as error:
                    self._skip(index.chunk_start_offset, error, self._indexed_counts(buf, index))

    def _indexed_counts(self, buf: _FileBytes, index: ChunkIndex) -> dict[str, int] | None:
        """Messages per topic of a chunk from its message index records; None if unreadable."""
        lost: dict[str, int] = {}
        try:
            for channel, offset in index.message_index_offsets.items():
                op, _ = buf.unpack(_RECORD, offset)
                found, size = buf.unpack(_INDEX, offset + _RECORD.size)
                if op != _OP_INDEX or found != channel or channel not in self._channels:
                    return None
                topic = self._channels[channel].topic
                lost[topic] = lost.get(topic, 0) + size // 16  # (u64 time, u64 offset) pairs
        except struct.error:
            return None
        return lost

    def _skip(self, offset: int, error: BaseException, lost: dict[str, int] | None) -> None:
        """Leave the chunk at byte ``offset`` out and say so; ``lost`` (messages per topic, if
        known) comes off the topic counts."""
        self._skipped.add(offset)
        if lost is None:
            what = "its messages (how many is unknown) are" if self.complete else \
                "its messages are"
        else:
            for topic, n in lost.items():
                self.counts[topic] = max(0, self.counts[topic] - n)
            what = f"{sum(lost.values())} messages " + \
                f"({', '.join(f'{t} {n}' for t, n in sorted(lost.items()))}) are"
        self.warnings.append(f"{self.path}: corrupt chunk at byte {offset} skipped "
                             f"({_describe(error)}); {what} left out, the rest is read")

    def _checked_chunk(self, pos: int, body: bytes, wanted: set[int] | None) -> Unit:
        """A chunk found by the linear pass; damaged ones are skipped (see :meth:`_skip`)."""
        if pos in self._skipped:
            return []
        try:
            return self._chunk(body, wanted)
        except _DAMAGE as error:
            self._skip(pos, error, None)
            return []

    def _units(self, buf: _FileBytes, wanted: set[int] | None) -> Iterator[Unit]:
        """Messages chunk by chunk, each unit complete and checked, up to the data end: the
        summary's chunks (checked at open) if the file is complete, less those whose index
        lists none of the ``wanted`` channels (:func:`_may_hold`), else a linear pass."""
        if self.complete:
            for index in self._chunks:
                if index.chunk_start_offset not in self._skipped and _may_hold(index, wanted):
                    yield self._chunk(self._chunk_body(buf, index), wanted)
            return
        pos, end = len(MCAP_MAGIC), len(buf)
        while pos < end:
            if pos + 9 > end:
                raise _Damaged(f"the file ends inside a record header at byte {pos}")
            op, length = buf.unpack(_RECORD, pos)
            body, after = pos + 9, pos + 9 + length
            if after > end:
                raise _Damaged(f"the record (opcode {op:#x}) at byte {pos} needs {length} "
                               f"bytes; the file ends {end - body} bytes later")
            if op == _OP_CHUNK:
                yield self._checked_chunk(pos, buf[body:after], wanted)
            elif op in (_OP_MESSAGE, _OP_SCHEMA, _OP_CHANNEL):
                yield self._records(buf[pos:after], wanted)
            elif op in (_OP_DATA_END, _OP_FOOTER):
                return
            pos = after
        raise _Damaged("the file ends without a data end record")

    def _scan(self) -> None:
        """Learn topics and counts from every complete chunk; note where the readable part ends."""
        messages = 0
        with self.path.open("rb") as stream:
            try:
                for unit in self._units(_FileBytes(stream), None):
                    for _, channel, _ in unit:
                        self.counts[self._channels[channel].topic] += 1
                    if unit:
                        messages += len(unit)
                        self._note_range(unit[0][0], unit[-1][0])
            except _DAMAGE as error:
                if not messages:
                    raise BagError(f"{self.path}: truncated or corrupt before the first complete "
                                   f"chunk ({_describe(error)}); no message can be "
                                   f"recovered") from error
                self.warnings.append(
                    f"{self.path}: truncated after {messages} messages (last complete chunk); "
                    f"the rest of the file is unreadable: {_describe(error)}")
                return
        self.warnings.append(f"{self.path}: no usable MCAP summary; all {messages} messages of "
                             f"the data section were read")

    def _wanted(self, topics: set[str]) -> set[int]:
        """The channels of ``topics`` whose type is their topic's."""
        return {cid for cid, ch in self._channels.items()
                if ch.topic in topics and self._types[cid] == self.topics[ch.topic].msgtype}

    def blocks(self, topics: set[str], size: int) -> Iterator[RawBlock] | None:
        """Messages of ``topics`` located by the chunks' message indexes instead of a walk
        through every record: (topic, log times, payloads) blocks of at most ``size`` messages of
        one chunk, each topic's in log-time order (as :meth:`raw` gives them). None where the
        file does not allow it: not complete, with chunks that overlap in time, were skipped or
        list no message index, or indexes that do not list as many messages as the statistics
        count (a chunk whose index does not match its records is walked instead)."""
        wanted = self._wanted(topics)
        if not wanted or not self.complete or not self.ordered or self._skipped:
            return None
        chunks = [index for index in self._chunks if _may_hold(index, wanted)]
        listed = dict.fromkeys(wanted, 0)
        with self.path.open("rb") as stream:
            buf = _FileBytes(stream)
            for index in chunks:
                if not index.message_index_offsets:
                    return None
                for channel in wanted & index.message_index_offsets.keys():
                    if (count := self._index_size(buf, index, channel)) is None:
                        return None
                    listed[channel] += count // 16  # (u64 time, u64 offset) pairs
        if any(listed[c] != self._channel_counts.get(c) for c in wanted):
            return None
        return self._blocks(chunks, wanted, size)

    def _index_size(self, buf: _FileBytes, index: ChunkIndex, channel: int) -> int | None:
        """Bytes of the (time, offset) pairs in ``channel``'s message index record of the chunk
        of ``index``; None if the record is not one."""
        offset = index.message_index_offsets[channel]
        try:
            op, length = buf.unpack(_RECORD, offset)
            found, size = buf.unpack(_INDEX, offset + _RECORD.size)
        except struct.error:
            return None
        good = op == _OP_INDEX and found == channel and size % 16 == 0 and \
            length == _INDEX.size + size
        return size if good else None

    def _blocks(self, chunks: list[ChunkIndex], wanted: set[int], size: int
                ) -> Iterator[RawBlock]:
        names = {cid: self._channels[cid].topic for cid in wanted}
        with self.path.open("rb") as stream:
            buf = _FileBytes(stream)
            try:
                for index in chunks:
                    content = self._content(self._chunk_body(buf, index))[0]
                    found = self._located(buf, index, content, wanted)
                    if found is None:  # the index does not match the records: walk them
                        found = _unit_blocks(self._records(content, wanted), names)
                    for topic, log, payloads in found:
                        for a in range(0, len(log), size):
                            yield topic, log[a:a + size], payloads[a:a + size]
            except _DAMAGE as error:
                raise BagError(f"{self.path}: corrupt data section, changed since it was opened "
                               f"({_describe(error)})") from error

    def _located(self, buf: _FileBytes, index: ChunkIndex, content: bytes, wanted: set[int]
                 ) -> list[RawBlock] | None:
        """The messages of the ``wanted`` channels in a chunk's records ``content``, a block per
        topic, where the chunk's message indexes give them: each entry a message record of its
        channel and log time inside the chunk, no two overlapping; None otherwise."""
        data = np.frombuffer(content, np.uint8)
        found: dict[str, list[tuple[np.ndarray, np.ndarray, np.ndarray]]] = {}
        for channel in sorted(wanted & index.message_index_offsets.keys()):
            entries = self._entries(buf, index, channel, data)
            if entries is None:
                return None
            found.setdefault(self._channels[channel].topic, []).append(entries)
        if not found:
            return []
        starts = np.concatenate([start for parts in found.values() for _, start, _ in parts])
        ends = np.concatenate([end for parts in found.values() for _, _, end in parts])
        order = np.argsort(starts, kind="stable")
        if np.any(ends[order][:-1] > starts[order][1:]):
            return None
        blocks: list[RawBlock] = []
        for topic, parts in found.items():
            log, start, end = (np.concatenate(column) for column in zip(*parts, strict=True))
            order = np.lexsort((start, log))  # by log time, then file order: as the walk sorts
            log, start, end = log[order], start[order], end[order]
            blocks.append((topic, log, _payloads(content, data, start + _HEAD_BYTES.size, end)))
        return blocks

    def _entries(self, buf: _FileBytes, index: ChunkIndex, channel: int, data: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Log times, record starts and record ends (bytes into the chunk's records ``data``)
        of ``channel``'s messages in its message index of the chunk of ``index``; None unless
        each is a whole message record of the channel at that log time."""
        size = self._index_size(buf, index, channel)
        if size is None:
            return None
        at = index.message_index_offsets[channel] + _RECORD.size + _INDEX.size
        if len(listed := buf[at:at + size]) != size:
            return None
        pairs = np.frombuffer(listed, "<u8").reshape(-1, 2)
        if len(pairs) and int(pairs[:, 1].max()) + _HEAD_BYTES.size > len(data):
            return None
        start = pairs[:, 1].astype(np.int64)
        head = data[start[:, None] + _HEAD_BYTES]  # each record's opcode, length, message head
        length = head[:, 1:9].copy().view("<u8")[:, 0]
        if not (np.all(head[:, 0] == _OP_MESSAGE)
                and np.all(head[:, 9:11].copy().view("<u2")[:, 0] == channel)
                and np.all(head[:, 15:23].copy().view("<u8")[:, 0] == pairs[:, 0])
                and np.all(length >= _MESSAGE.size)
                and np.all(length <= len(data))):
            return None
        end = start + _RECORD.size + length.astype(np.int64)
        if np.any(end > len(data)):
            return None
        return pairs[:, 0].astype(np.int64), start, end

    def raw(self, topics: set[str]) -> Iterator[RawMessage]:
        """Messages of ``topics`` as (topic, log time, bytes), in log-time order."""
        wanted = self._wanted(topics)
        if not wanted:
            return
        names = {cid: self._channels[cid].topic for cid in wanted}
        with self.path.open("rb") as stream:
            units = self._units(_FileBytes(stream), wanted)
            if not self.ordered:
                units = iter([sorted(itertools.chain.from_iterable(self._until_cut(units)),
                                     key=itemgetter(0))])
            for unit in self._until_cut(units):
                yield from [(names[channel], stamp, data) for stamp, channel, data in unit]

    def _until_cut(self, units: Iterator[Unit]) -> Iterator[Unit]:
        """``units`` up to the damage; an error if the file claimed to be complete."""
        try:
            yield from units
        except _DAMAGE as error:
            if self.complete:
                raise BagError(f"{self.path}: corrupt data section, changed since it was opened "
                               f"({_describe(error)})") from error


class _RosbagsSource:
    """A rosbag2 folder read through ``rosbags`` (sqlite3 storage)."""

    def __init__(self, path: Path) -> None:
        from rosbags.rosbag2 import Reader

        self.path = path
        self.warnings: list[str] = []
        try:
            self._reader = Reader(path)
            self._reader.open()
        except Exception as error:  # rosbags raises ReaderError and sqlite3 errors
            raise BagError(f"{path}: cannot open rosbag2 bag ({_describe(error)})") from error
        self.topics: dict[str, _TopicInfo] = {}
        self.counts: dict[str, int] = {}
        self.profiles: dict[str, list[Any]] = {}
        for connection in self._reader.connections:
            self.profiles.setdefault(connection.topic, parse_profiles(
                getattr(connection.ext, "offered_qos_profiles", [])))
            fmt = connection.msgdef.format.name.lower() if connection.msgdef else "none"
            encoding = {"msg": "ros2msg", "idl": "ros2idl"}.get(fmt, "")
            self.topics.setdefault(connection.topic, _TopicInfo(
                _canonical_type(connection.msgtype), encoding,
                connection.msgdef.data if connection.msgdef else ""))
            self.counts[connection.topic] = self.counts.get(connection.topic, 0) + \
                connection.msgcount
        self.time_range: tuple[int, int] | None = (
            (self._reader.start_time, self._reader.end_time - 1)
            if self._reader.message_count else None)

    def raw(self, topics: set[str]) -> Iterator[RawMessage]:
        """Messages of ``topics`` as (topic, log time, bytes), in log-time order."""
        connections = [c for c in self._reader.connections if c.topic in topics]
        if not connections:
            return
        try:
            for connection, stamp, data in self._reader.messages(connections=connections):
                yield connection.topic, stamp, bytes(data)
        except Exception as error:  # sqlite3/rosbags errors on a damaged database
            raise BagError(f"{self.path}: corrupt storage ({_describe(error)})") from error


_Source = _McapSource | _RosbagsSource


def _register(msgtype: str, info: _TopicInfo) -> str | None:
    """Make ``msgtype`` decodable; returns why it cannot be, or None."""
    store = typestore()
    if msgtype in store.types:
        return None
    if not info.definition.strip() or info.encoding not in ("ros2msg", "ros2idl"):
        return (f"type {msgtype!r} is not in the Jazzy typestore or msg_defs/ and the bag "
                f"embeds no ros2msg/ros2idl definition of it")
    try:
        types = (get_types_from_msg(info.definition, msgtype) if info.encoding == "ros2msg"
                 else get_types_from_idl(info.definition))
        store.register({name: fields for name, fields in types.items()
                        if name not in store.types})
    except (TypesysError, ValueError, KeyError) as error:  # parser/typesys errors
        return f"the embedded definition of {msgtype!r} does not parse ({_describe(error)})"
    if msgtype not in store.types:
        return f"the embedded {info.encoding} definition does not define {msgtype!r}"
    return None


class BagReader:
    """Topics, types and time-ordered messages of one bag (see :func:`open_bag`)."""

    def __init__(self, path: Path, sources: Sequence[_Source], warnings: Iterable[str]) -> None:
        self.path = path
        self._sources = list(sources)
        self.warnings: list[str] = list(warnings)
        self.topics: dict[str, str] = {}
        self.counts: dict[str, int] = {}
        self._undecodable: dict[str, str] = {}
        self._profiles: dict[str, list[Any]] = {}
        for source in self._sources:
            self.warnings.extend(source.warnings)
            for topic, info in source.topics.items():
                self.topics.setdefault(topic, info.msgtype)
                self._profiles.setdefault(topic, []).extend(source.profiles.get(topic, []))
                self.counts[topic] = self.counts.get(topic, 0) + source.counts.get(topic, 0)
                if topic not in self._undecodable and (why := _register(info.msgtype, info)):
                    self._undecodable[topic] = why
        for topic, why in sorted(self._undecodable.items()):
            self.warnings.append(f"{path}: topic {topic} cannot be decoded: {why}")
        if not sum(self.counts.values()):
            raise BagError(f"{path}: empty bag (no messages"
                           f"{'; topics: ' + ', '.join(sorted(self.topics)) if self.topics else ''})")

    @property
    def message_count(self) -> int:
        """Messages in the readable part of the bag."""
        return sum(self.counts.values())

    def qos(self, topic: str) -> OfferedQos:
        """The QoS the bag's publishers of ``topic`` offered, folded into one profile
        (:func:`tdcm_ros.bagio.qos.recorded_qos`); BagError if the topic is absent."""
        return recorded_qos(self._profiles.get(self.resolve(topic), []))

    @property
    def time_range_ns(self) -> tuple[int, int]:
        """Log times (ns since the epoch) of the first and the last message readable."""
        ranges = [r for source in self._sources if (r := source.time_range) is not None]
        return min(r[0] for r in ranges), max(r[1] for r in ranges)

    @property
    def undecodable(self) -> dict[str, str]:
        """Topic -> why its messages cannot be decoded (also in ``warnings``)."""
        return dict(self._undecodable)

    def resolve(self, topic: str) -> str:
        """The stored name of ``topic`` (``tension`` finds ``/tension``); BagError if absent."""
        for name in (topic, "/" + topic.lstrip("/")):
            if name in self.topics:
                return name
        raise BagError(f"{self.path}: no topic {topic!r}; topics: {self._listing()}")

    def _listing(self) -> str:
        return ", ".join(f"{t} [{m}]" for t, m in sorted(self.topics.items())) or "none"

    def _wanted(self, topics: Sequence[str] | None) -> set[str]:
        if topics is None:
            return set(self.topics) - set(self._undecodable)
        wanted = {self.resolve(t) for t in topics}
        for topic in sorted(wanted & set(self._undecodable)):
            raise BagError(f"{self.path}: topic {topic} cannot be decoded: "
                           f"{self._undecodable[topic]}")
        return wanted

    def raw_messages(self, topics: Sequence[str] | None = None) -> Iterator[tuple[str, int, bytes]]:
        """(topic, log time ns, CDR bytes) of ``topics`` (default all), in log-time order."""
        wanted = self._wanted(topics)
        streams = [source.raw(wanted) for source in self._sources]
        yield from streams[0] if len(streams) == 1 else heapq.merge(*streams, key=itemgetter(1))

    def raw_blocks(self, topics: Sequence[str] | None, size: int) -> Iterator[RawBlock]:
        """(topic, log times ns (int64 array), CDR payloads) of ``topics`` (None: all), at most
        ``size`` messages a block, each topic's messages in the order :meth:`raw_messages`
        gives (topics interleave in no set order). One complete MCAP file is read by its chunks'
        message indexes, not message by message: a chunk's payloads of one topic and one length
        come as :class:`~tdcm_ros.bagio.cdr.PayloadRows`."""
        wanted = self._wanted(topics)
        only = self._sources[0] if len(self._sources) == 1 else None
        if isinstance(only, _McapSource) and (blocks := only.blocks(wanted, size)) is not None:
            yield from blocks
            return
        messages = self.raw_messages(topics)
        while batch := list(itertools.islice(messages, size)):
            parts: dict[str, list[tuple[str, int, bytes]]] = {}
            for message in batch:
                parts.setdefault(message[0], []).append(message)
            for topic, part in parts.items():
                yield (topic, np.fromiter((t for _, t, _ in part), np.int64, len(part)),
                       [data for _, _, data in part])

    def messages(self, topics: Sequence[str] | None = None) -> Iterator[tuple[str, int, Any]]:
        """(topic, log time ns, rosbags message) of ``topics`` (default all), in log-time order."""
        decode = typestore().deserialize_cdr
        for topic, stamp, data in self.raw_messages(topics):
            try:
                message = decode(data, self.topics[topic])
            except Exception as error:  # rosbags raises SerdeError, struct and index errors
                raise BagError(f"{self.path}: cannot decode the message on {topic} at {stamp} "
                               f"ns as {self.topics[topic]}: {_describe(error)}") from error
            yield topic, stamp, message


def require_topic(reader: BagReader, topic: str, allowed_types: Iterable[str] | None = None) -> str:
    """The stored name of ``topic``; BagError when it is absent, of another type or empty."""
    name = reader.resolve(topic)
    allowed = sorted(_canonical_type(t) for t in allowed_types or ())
    if allowed and reader.topics[name] not in allowed:
        raise BagError(f"{reader.path}: topic {name} has type {reader.topics[name]}; "
                       f"expected {' or '.join(allowed)}")
    if not reader.counts.get(name):
        raise BagError(f"{reader.path}: topic {name} has no messages")
    return name


def _folder_files(path: Path, warnings: list[str]) -> tuple[str, list[Path]]:
    """Storage identifier and storage files of a rosbag2 folder."""
    meta = path / METADATA_FILE
    if meta.is_file():
        try:
            info = load_yaml(meta.read_text(encoding="utf-8"), str(meta))["rosbag2_bagfile_information"]
            storage = str(info.get("storage_identifier") or "mcap")
            names = [str(n) for n in info.get("relative_file_paths") or []]
            if str(info.get("compression_mode") or "").upper() == "FILE":
                raise BagError(f"{path}: file-compressed bags "
                               f"({info.get('compression_format')}) are not supported; "
                               f"decompress with `ros2 bag convert` first")
        except (yaml.YAMLError, TypeError, KeyError, AttributeError) as error:
            warnings.append(f"{meta}: unreadable ({_describe(error)}); reading the storage "
                            f"files found in the folder")
        else:
            files = [path / n for n in names]
            if missing := [str(f) for f in files if not f.is_file()]:
                raise BagError(f"{meta} lists storage files that do not exist: "
                               f"{', '.join(missing)}")
            return storage, files
    mcaps, db3s = sorted(path.glob("*.mcap")), sorted(path.glob("*.db3"))
    if not mcaps and not db3s:
        raise BagError(f"{path}: not a bag (no {METADATA_FILE}, no .mcap or .db3 files)")
    if not mcaps:
        raise BagError(f"{path}: sqlite3 storage without {METADATA_FILE} is not supported")
    warnings.append(f"{path}: no {METADATA_FILE} (writer stopped before closing?); reading "
                    f"{', '.join(f.name for f in mcaps)}")
    return "mcap", mcaps


def open_bag(path: str | Path) -> BagReader:
    """Open a rosbag2 folder or a bare ``.mcap`` file for reading (see the module docstring)."""
    path = Path(path)
    if not path.exists():
        raise BagError(f"{path}: no such bag (file or folder)", parameter="bag", value=str(path))
    warnings: list[str] = []
    if path.is_dir():
        storage, files = _folder_files(path, warnings)
        if storage == "sqlite3":
            return BagReader(path, [_RosbagsSource(path)], warnings)
        if storage != "mcap":
            raise BagError(f"{path}: storage {storage!r} is not supported; allowed: mcap, sqlite3")
        return BagReader(path, [_McapSource(f) for f in files], warnings)
    with path.open("rb") as stream:
        head = stream.read(len(SQLITE_MAGIC))
    if head.startswith(MCAP_MAGIC):
        return BagReader(path, [_McapSource(path)], warnings)
    if head == SQLITE_MAGIC:
        if (path.parent / METADATA_FILE).is_file():
            return open_bag(path.parent)
        raise BagError(f"{path}: a sqlite3 file without {METADATA_FILE} beside it; open the "
                       f"bag folder")
    raise BagError(f"{path}: not a bag (neither MCAP nor a rosbag2 folder)")


__all__ = ["BagReader", "open_bag", "require_topic"]
