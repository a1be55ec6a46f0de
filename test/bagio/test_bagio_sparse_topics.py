"""Reading a topic decompresses only the chunks whose index lists it (a sparse ``/tf_static`` no
longer costs a walk through every chunk), and every chunk when the file has no message
indexes."""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.writer import IndexType

from tdcm_ros.bagio import serialize, to_dict
from tdcm_ros.bagio.reader import _McapSource, open_bag
from tdcm_ros.bagio.writer import BagWriter
from test.bagio.bagio_samples import Message, sample_messages, write_mcap

MESSAGES = sample_messages(300, 50)  # 6 Markers among 300 tensions: markers in few chunks
MARKERS = [(t, s, to_dict(m)) for t, s, _, m in MESSAGES if t == "/markers"]


def chunks_read(monkeypatch: pytest.MonkeyPatch, path: Path, topics: list[str] | None
                ) -> tuple[int, list[tuple[str, int, object]]]:
    """How many chunks reading ``topics`` (None: all) decompresses, and the messages read."""
    calls = []
    original = _McapSource._chunk

    def counted(self: _McapSource, body: bytes, wanted: set[int] | None) -> object:
        calls.append(wanted)
        return original(self, body, wanted)

    monkeypatch.setattr(_McapSource, "_chunk", counted)
    got = [(t, s, to_dict(m)) for t, s, m in open_bag(path).messages(topics)]
    return len(calls), got


def test_a_sparse_topic_reads_only_the_chunks_holding_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "bag"
    with BagWriter(path, chunk_size=1024, compression="zstd") as writer:
        for topic, stamp, msgtype, message in MESSAGES:
            writer.add_topic(topic, msgtype)
            writer.write(topic, stamp, serialize(message, msgtype))
    every, _ = chunks_read(monkeypatch, path, None)
    sparse, got = chunks_read(monkeypatch, path, ["/markers"])
    assert got == MARKERS
    assert 1 <= sparse <= len(MARKERS) < every


def write_without_message_indexes(path: Path, messages: list[Message]) -> Path:
    """An MCAP in 1 KiB chunks with chunk indexes but no message indexes."""
    return write_mcap(path, messages, chunk_size=1024, index_types=IndexType.CHUNK)


def test_without_message_indexes_every_chunk_is_read(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = write_without_message_indexes(tmp_path / "plain.mcap", MESSAGES)
    every, _ = chunks_read(monkeypatch, path, None)
    sparse, got = chunks_read(monkeypatch, path, ["/markers"])
    assert got == MARKERS
    assert sparse == every > len(MARKERS)
