"""Read rosbag2 bags (MCAP or sqlite3 storage) and bare ``.mcap`` files.

``open_bag(path)`` accepts a rosbag2 folder (with ``metadata.yaml``, or without one when the
writer was killed: its ``.mcap`` files are read) or one ``.mcap`` file. Message types come from
the Jazzy typestore plus ``msg_defs/``; a type the store does not know is registered from the
definition the bag embeds (MCAP schema encoding ``ros2msg`` or ``ros2idl``, as ``ros2 bag record``
writes). An MCAP file without a usable summary (writer killed: no footer, a half-written last
chunk) is read up to its last complete record, and the loss is reported in ``warnings``.

Topic arguments may omit the leading ``/`` (``tension`` = ``/tension``). Times are ns since the
UNIX epoch. Every failure is a :class:`~tdcm_ros.bagio.errors.BagError` naming the file.
"""

from __future__ import annotations

import heapq
import struct
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import yaml
import zstandard
from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Footer, Message, Schema
from mcap.stream_reader import StreamReader
from mcap.summary import Summary
from rosbags.typesys import TypesysError, get_types_from_idl, get_types_from_msg

from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.typestore import deserialize, typestore

MCAP_MAGIC = b"\x89MCAP0\r\n"
SQLITE_MAGIC = b"SQLite format 3\x00"
METADATA_FILE = "metadata.yaml"

RawMessage = tuple[int, str, bytes]  # (log time ns, topic, CDR bytes)


class _Truncated(Exception):
    """The file ended inside a record."""


# What a cut or damaged MCAP file raises inside ``mcap`` (lz4 raises RuntimeError).
_READ_ERRORS = (McapError, _Truncated, struct.error, ValueError, KeyError, IndexError, EOFError,
                OSError, RuntimeError, zstandard.ZstdError)


class _ExactStream:
    """A read-only view of a file whose ``read(n)`` returns n bytes or raises :class:`_Truncated`.

    ``mcap``'s stream reader accepts short reads at the end of a file, which would turn a
    half-written record into a partial message; this wrapper makes the cut explicit.
    """

    def __init__(self, stream: IO[bytes]) -> None:
        self._stream = stream

    def read(self, size: int = -1) -> bytes:
        data = self._stream.read(size)
        if size > 0 and len(data) != size:
            raise _Truncated(f"{size - len(data)} bytes missing")
        return data


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


class _McapSource:
    """One MCAP file: indexed reading through its summary, else a linear scan to the cut."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.warnings: list[str] = []
        self.topics: dict[str, _TopicInfo] = {}
        self.counts: dict[str, int] = {}
        self._channels: dict[int, Channel] = {}
        self._schemas: dict[int, Schema] = {}
        self._types: dict[int, str] = {}
        self._size = path.stat().st_size
        self._indexed = False
        self._sorted = True
        with path.open("rb") as stream:
            if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
                raise BagError(f"{path}: not an MCAP file (no MCAP magic at the start)")
            summary = self._summary(stream)
        if summary is not None:
            self._indexed = True
            self._schemas, self._channels = dict(summary.schemas), dict(summary.channels)
            counts = summary.statistics.channel_message_counts if summary.statistics else {}
            for channel_id, channel in self._channels.items():
                self._declare(channel)
                self.counts[channel.topic] += counts.get(channel_id, 0)
        else:
            self._scan_all()

    def _summary(self, stream: IO[bytes]) -> Summary | None:
        """The summary when it indexes every message (chunk indexes and statistics), else None."""
        if self._size < 2 * len(MCAP_MAGIC) + 29:
            return None
        try:
            stream.seek(0)
            summary = SeekingReader(stream, validate_crcs=True,
                                    record_size_limit=self._size).get_summary()
        except _READ_ERRORS:  # no footer, bad footer or summary: the linear scan decides
            return None
        if summary is None or summary.statistics is None or (
                summary.statistics.message_count and not summary.chunk_indexes):
            return None
        return summary

    def _declare(self, channel: Channel) -> None:
        schema = self._schemas.get(channel.schema_id)
        info = _TopicInfo(_canonical_type(schema.name) if schema else "",
                          schema.encoding if schema else "",
                          schema.data.decode("utf-8", "replace") if schema else "")
        self._types[channel.id] = info.msgtype
        known = self.topics.setdefault(channel.topic, info)
        self.counts.setdefault(channel.topic, 0)
        if known.msgtype != info.msgtype:
            self.warnings.append(f"{self.path}: topic {channel.topic} has several types "
                                 f"({known.msgtype}, {info.msgtype}); reading {known.msgtype}")

    def _records(self, stream: IO[bytes]) -> Iterator[Any]:
        reader = StreamReader(_ExactStream(stream), validate_crcs=True,  # type: ignore[arg-type]
                              record_size_limit=self._size)
        return iter(reader.records)

    def _scan_all(self) -> None:
        """Learn topics and counts by reading every complete record; note where the file stops."""
        messages = 0
        last_time = -1
        ended = False
        with self.path.open("rb") as stream:
            try:
                for record in self._records(stream):
                    if isinstance(record, Schema):
                        self._schemas[record.id] = record
                    elif isinstance(record, Channel):
                        if record.id not in self._channels:
                            self._channels[record.id] = record
                            self._declare(record)
                    elif isinstance(record, Message) and record.channel_id in self._channels:
                        messages += 1
                        self.counts[self._channels[record.channel_id].topic] += 1
                        self._sorted = self._sorted and record.log_time >= last_time
                        last_time = record.log_time
                    elif isinstance(record, Footer):
                        ended = True
            except _READ_ERRORS as error:  # a cut or damaged record ends the readable part
                if not messages:
                    raise BagError(f"{self.path}: truncated or corrupt before the first complete "
                                   f"chunk ({_describe(error)}); no message can be "
                                   f"recovered") from error
                self.warnings.append(
                    f"{self.path}: truncated after {messages} messages (last complete chunk); "
                    f"the rest of the file ({self._size} bytes) is unreadable: "
                    f"{_describe(error)}")
                return
        if not ended:
            self.warnings.append(f"{self.path}: no MCAP footer; read {messages} messages")

    def raw(self, topics: set[str]) -> Iterator[RawMessage]:
        """Messages of ``topics`` as (log time, topic, bytes), in log-time order."""
        wanted = {cid for cid, ch in self._channels.items()
                  if ch.topic in topics and self._types[cid] == self.topics[ch.topic].msgtype}
        if not wanted:
            return
        with self.path.open("rb") as stream:
            if self._indexed:
                yield from self._raw_indexed(stream, wanted)
            elif self._sorted:
                yield from self._raw_scanned(stream, wanted)
            else:
                yield from sorted(self._raw_scanned(stream, wanted), key=lambda m: m[0])

    def _raw_indexed(self, stream: IO[bytes], wanted: set[int]) -> Iterator[RawMessage]:
        topics = sorted({self._channels[c].topic for c in wanted})
        reader = SeekingReader(stream, validate_crcs=True, record_size_limit=self._size)
        try:
            for _, channel, message in reader.iter_messages(topics=topics, log_time_order=True):
                if channel.id in wanted:
                    yield message.log_time, channel.topic, message.data
        except _READ_ERRORS as error:  # damaged chunk behind an intact summary
            raise BagError(f"{self.path}: corrupt data section ({_describe(error)})") from error

    def _raw_scanned(self, stream: IO[bytes], wanted: set[int]) -> Iterator[RawMessage]:
        records = self._records(stream)
        while True:
            try:
                record = next(records)
            except StopIteration:
                return
            except _READ_ERRORS:  # the cut found by _scan_all; its messages were counted already
                return
            if isinstance(record, Message) and record.channel_id in wanted:
                yield record.log_time, self._channels[record.channel_id].topic, record.data


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
        for connection in self._reader.connections:
            fmt = connection.msgdef.format.name.lower() if connection.msgdef else "none"
            encoding = {"msg": "ros2msg", "idl": "ros2idl"}.get(fmt, "")
            self.topics.setdefault(connection.topic, _TopicInfo(
                _canonical_type(connection.msgtype), encoding,
                connection.msgdef.data if connection.msgdef else ""))
            self.counts[connection.topic] = self.counts.get(connection.topic, 0) + \
                connection.msgcount

    def raw(self, topics: set[str]) -> Iterator[RawMessage]:
        """Messages of ``topics`` as (log time, topic, bytes), in log-time order."""
        connections = [c for c in self._reader.connections if c.topic in topics]
        if not connections:
            return
        try:
            for connection, stamp, data in self._reader.messages(connections=connections):
                yield stamp, connection.topic, bytes(data)
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
        for source in self._sources:
            self.warnings.extend(source.warnings)
            for topic, info in source.topics.items():
                self.topics.setdefault(topic, info.msgtype)
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
        merged = streams[0] if len(streams) == 1 else heapq.merge(*streams, key=lambda m: m[0])
        for stamp, topic, data in merged:
            yield topic, stamp, data

    def messages(self, topics: Sequence[str] | None = None) -> Iterator[tuple[str, int, Any]]:
        """(topic, log time ns, rosbags message) of ``topics`` (default all), in log-time order."""
        for topic, stamp, data in self.raw_messages(topics):
            try:
                message = deserialize(data, self.topics[topic])
            except BagError as error:
                raise BagError(f"{self.path}: message on {topic} at {stamp} ns: {error}") from error
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
            info = yaml.safe_load(meta.read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
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
