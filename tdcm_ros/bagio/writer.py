"""Write a rosbag2 bag: one MCAP file plus ``metadata.yaml`` (version 9, as Jazzy writes).

The MCAP file carries the ROS 2 profile, a ``ros2msg`` schema (the full message definition) per
type and ``offered_qos_profiles``/``topic_type_hash`` channel metadata, so ``ros2 bag`` and
Foxglove read it without our message packages. Messages are grouped in small chunks; a chunk
is handed to the operating system as soon as it is full (``chunk_size`` bytes) or
``flush_period_s`` old, so a writer killed outright loses only the chunk in progress.
``metadata.yaml`` is written by :meth:`BagWriter.close`; the reader copes without it.

A failed write (the disk or the user's quota full, the file-size limit, an I/O error) ends the
recording cleanly: the MCAP file is cut back to its last whole chunk (what a reader can read, as
after a kill), later messages are counted in :attr:`BagWriter.lost` instead of written, and
:meth:`BagWriter.close` writes ``metadata.yaml`` for the messages kept, in the space a small
reserve file (:data:`RESERVE_BYTES`, removed at the close) held back from the start.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import TracebackType
from typing import Protocol, Self

import yaml
from mcap.writer import CompressionType, Writer

from tdcm_ros.bagio.errors import BagError
from tdcm_ros.bagio.typestore import normalize_type_name, type_hash, typestore

METADATA_VERSION = 9
DEFAULT_CHUNK_SIZE = 256 * 1024  # bytes of uncompressed records per chunk
DEFAULT_FLUSH_PERIOD_S = 0.1  # oldest unflushed message age (s) before the chunk is written
# rmw's "infinite" duration as rosbag2 (Jazzy) writes it in metadata.yaml
_INFINITE = {"sec": 9223372036, "nsec": 854775807}
_COMPRESSION = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
                "none": CompressionType.NONE}
#: Bytes held back in the bag folder from the start, freed to close the bag on a full disk.
RESERVE_BYTES = 256 * 1024
RESERVE_NAME = ".tdcm_reserve"


class QosLike(Protocol):
    """What a topic's offered QoS needs (``tdcm_ros.runtime.port.QoS`` fits); read only."""

    @property
    def depth(self) -> int: ...
    @property
    def reliability(self) -> str: ...
    @property
    def durability(self) -> str: ...


@dataclass(frozen=True)
class OfferedQos:
    """Keep-last QoS recorded for a topic (depth in messages)."""

    depth: int = 10
    reliability: str = "reliable"
    durability: str = "volatile"


def qos_profile(qos: QosLike) -> dict[str, object]:
    """One ``offered_qos_profiles`` entry in rosbag2's version-9 layout."""
    return {"history": "keep_last", "depth": int(qos.depth), "reliability": qos.reliability,
            "durability": qos.durability, "deadline": dict(_INFINITE),
            "lifespan": dict(_INFINITE), "liveliness": "automatic",
            "liveliness_lease_duration": dict(_INFINITE),
            "avoid_ros_namespace_conventions": False}


class _DirectFile:
    """Unbuffered file for ``mcap.Writer``: every write reaches the OS at once (survives kill)."""

    def __init__(self, path: Path) -> None:
        self._fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        self.written = 0

    def write(self, data: bytes) -> int:
        view = memoryview(data)
        while view:
            view = view[os.write(self._fd, view):]
        self.written += len(data)
        return len(data)

    def tell(self) -> int:
        return self.written

    def flush(self) -> None:
        """Nothing is buffered here."""

    def truncate(self, size: int) -> None:
        """Cut the file back to ``size`` bytes and write on from there."""
        os.ftruncate(self._fd, size)
        os.lseek(self._fd, size, os.SEEK_SET)
        self.written = size

    def close(self) -> None:
        os.close(self._fd)


@dataclass
class _Topic:
    name: str
    msgtype: str
    channel_id: int
    qos: dict[str, object]
    count: int = 0
    first_ns: int = field(default=-1)
    last_ns: int = field(default=-1)


class BagWriter:
    """Context manager writing the rosbag2 MCAP bag folder ``path`` (which must not exist).

    Topics are stored fully qualified (``tension`` -> ``/tension``); times are ns since the
    UNIX epoch; ``write`` takes CDR bytes as the runtimes carry them.
    """

    def __init__(self, path: str | Path, *, chunk_size: int = DEFAULT_CHUNK_SIZE,
                 flush_period_s: float = DEFAULT_FLUSH_PERIOD_S,
                 compression: str = "zstd") -> None:
        self.path = Path(path)
        if compression not in _COMPRESSION:
            raise BagError(f"compression = {compression!r} is invalid; allowed: "
                           f"{', '.join(_COMPRESSION)}", parameter="compression",
                           value=compression, allowed=", ".join(_COMPRESSION))
        if not 1024 <= chunk_size <= 64 * 2**20:
            raise BagError(f"chunk_size = {chunk_size} bytes is out of range; allowed: "
                           f"[1024, {64 * 2**20}]", parameter="chunk_size", value=chunk_size)
        if not flush_period_s > 0:
            raise BagError(f"flush_period_s = {flush_period_s} s must be > 0",
                           parameter="flush_period_s", value=flush_period_s, allowed="> 0 s")
        if self.path.exists() or self.path.is_symlink():
            raise BagError(f"{self.path} exists; refusing to overwrite it (choose another "
                           f"name or remove it)", parameter="bag", value=str(self.path))
        try:
            self.path.mkdir(parents=True)
        except OSError as error:
            raise BagError(f"cannot create bag folder {self.path}: {error}", parameter="bag",
                           value=str(self.path)) from error
        self.file_name = f"{self.path.name}_0.mcap"
        self._reserve = self.path / RESERVE_NAME
        try:
            with open(self._reserve, "wb") as reserve:
                os.posix_fallocate(reserve.fileno(), 0, RESERVE_BYTES)
        except OSError as error:
            raise BagError(f"cannot hold {RESERVE_BYTES} bytes in {self.path} for a clean close: "
                           f"{error.strerror}", parameter="bag", value=str(self.path)) from error
        self._file = _DirectFile(self.path / self.file_name)
        self._writer = Writer(self._file, chunk_size=chunk_size,  # type: ignore[arg-type]
                              compression=_COMPRESSION[compression])
        self._writer.start(profile="ros2", library="tdcm_ros")
        self._schemas: dict[str, int] = {}
        self._topics: dict[str, _Topic] = {}
        self.flush_period_s = flush_period_s
        self._flush_period_ns = int(flush_period_s * 1e9)
        self._pending = 0
        self._written_at_flush = self._file.written
        self._oldest_pending_ns = 0
        self._kept: dict[str, _Topic] = {}  # the topics as of the last whole chunk on disk
        self.failure = ""  #: why writing stopped ("" while it goes on)
        self.lost = 0      #: messages given to :meth:`write` that the bag does not keep
        self.closed = False

    @staticmethod
    def _qualified(topic: str) -> str:
        return "/" + topic.strip().lstrip("/")

    @property
    def counts(self) -> dict[str, int]:
        """Messages written per topic."""
        return {name: t.count for name, t in self._topics.items()}

    @property
    def topics(self) -> dict[str, str]:
        """Topic -> message type."""
        return {name: t.msgtype for name, t in self._topics.items()}

    def add_topic(self, topic: str, msgtype: str, qos: QosLike | None = None) -> None:
        """Declare ``topic`` of ``msgtype`` offered with ``qos``; again with the same type: no-op."""
        self._check_open()
        name, msgtype = self._qualified(topic), normalize_type_name(msgtype)
        if name in self._topics:
            if self._topics[name].msgtype != msgtype:
                raise BagError(f"topic {name} is already in the bag as "
                               f"{self._topics[name].msgtype}, not {msgtype}", parameter="msgtype",
                               value=msgtype, allowed=self._topics[name].msgtype)
            return
        if msgtype not in self._schemas:
            definition = typestore().generate_msgdef(msgtype, ros_version=2)[0]
            self._schemas[msgtype] = self._writer.register_schema(
                msgtype, "ros2msg", definition.encode("utf-8"))
        profile = qos_profile(qos or OfferedQos())
        channel = self._writer.register_channel(
            name, "cdr", self._schemas[msgtype],
            {"offered_qos_profiles": yaml.safe_dump([profile], sort_keys=False),
             "topic_type_hash": type_hash(msgtype)})
        self._topics[name] = _Topic(name, msgtype, channel, profile)

    def write(self, topic: str, log_time_ns: int, cdr: bytes, *, publish_time_ns: int | None = None,
              sequence: int = 0) -> None:
        """Append one message (CDR bytes) received at ``log_time_ns`` on a declared topic."""
        self._check_open()
        entry = self._topics.get(topic) or self._topics.get(self._qualified(topic))
        if entry is None:
            raise BagError(f"topic {topic!r} was not added to the bag; add_topic() first",
                           parameter="topic", value=topic, allowed=", ".join(self._topics))
        if self.failure:
            self.lost += 1
            return
        entry.count += 1
        entry.first_ns = log_time_ns if entry.first_ns < 0 else min(entry.first_ns, log_time_ns)
        entry.last_ns = max(entry.last_ns, log_time_ns)
        try:
            self._writer.add_message(entry.channel_id, log_time_ns, cdr,
                                     publish_time_ns if publish_time_ns is not None
                                     else log_time_ns, sequence & 0xFFFFFFFF)
        except OSError as error:
            self._fail(error)
            return
        if self._file.written != self._written_at_flush:  # mcap wrote a full chunk just now
            self._chunk_written()
            return
        if not self._pending:
            self._oldest_pending_ns = time.monotonic_ns()
        self._pending += 1
        self.poll()

    def poll(self) -> None:
        """Write the chunk in progress if its oldest message is ``flush_period_s`` old."""
        if self._pending and time.monotonic_ns() - self._oldest_pending_ns >= self._flush_period_ns:
            self.flush()

    def flush(self) -> None:
        """Hand every message written so far to the operating system (ends the chunk)."""
        self._check_open()
        if self.failure:
            return
        try:
            self._writer.flush()
        except OSError as error:
            self._fail(error)
            return
        self._chunk_written()

    def _chunk_written(self) -> None:
        """Every message given so far is on disk in whole chunks: remember that state."""
        self._written_at_flush, self._pending = self._file.written, 0
        self._kept = {name: replace(t) for name, t in self._topics.items()}

    def _fail(self, error: OSError) -> None:
        """A write failed: free the reserve, cut the file back to its last whole chunk, keep
        the counts of what it holds, and write nothing more."""
        given = sum(t.count for t in self._topics.values())
        self._topics = {name: self._kept.get(name, replace(t, count=0, first_ns=-1, last_ns=-1))
                        for name, t in self._topics.items()}
        self.lost = given - sum(t.count for t in self._topics.values())
        self.failure = (f"writing {self.path / self.file_name} failed after "
                        f"{self._written_at_flush} bytes: {error.strerror or error}")
        self._reserve.unlink(missing_ok=True)
        self._file.truncate(self._written_at_flush)

    def _check_open(self) -> None:
        if self.closed:
            raise BagError(f"bag {self.path} is closed")

    def metadata(self) -> dict[str, object]:
        """The ``metadata.yaml`` content (rosbag2 version 9) for what was written so far."""
        topics = list(self._topics.values())
        written = [t for t in topics if t.count]
        start = min((t.first_ns for t in written), default=0)
        duration = max((t.last_ns for t in written), default=0) - start
        count = sum(t.count for t in topics)
        return {"rosbag2_bagfile_information": {
            "version": METADATA_VERSION,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": duration},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": count,
            "topics_with_message_count": [
                {"topic_metadata": {"name": t.name, "type": t.msgtype,
                                    "serialization_format": "cdr",
                                    "offered_qos_profiles": [t.qos],
                                    "type_description_hash": type_hash(t.msgtype)},
                 "message_count": t.count} for t in topics],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [self.file_name],
            "files": [{"path": self.file_name,
                       "starting_time": {"nanoseconds_since_epoch": start},
                       "duration": {"nanoseconds": duration},
                       "message_count": count}],
            "custom_data": None,
            "ros_distro": "jazzy",
        }}

    def close(self) -> None:
        """Finish the MCAP file (summary, footer) and write ``metadata.yaml``; idempotent."""
        if self.closed:
            return
        meta = self.metadata()
        text = yaml.safe_dump(meta, sort_keys=False)
        try:
            if not self.failure:
                self._writer.add_metadata("rosbag2", {"serialized_metadata": yaml.safe_dump(
                    meta["rosbag2_bagfile_information"], sort_keys=False)})
                self._writer.finish()
        except OSError as error:  # the summary did not fit: the file ends at its last chunk
            self._fail(error)
            meta = self.metadata()
            text = yaml.safe_dump(meta, sort_keys=False)
        finally:
            self._file.close()
            self.closed = True
            self._reserve.unlink(missing_ok=True)
        partial = self.path / "metadata.yaml.tmp"
        partial.write_text(text, encoding="utf-8")
        partial.replace(self.path / "metadata.yaml")

    def __enter__(self) -> Self:
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        self.close()
