"""``BagReader.raw_blocks``: each topic's messages in blocks, read by the chunks' message indexes
where the file allows it (one complete MCAP whose indexes list every message), else walked
message by message; either way the messages ``raw_messages`` gives, in its order."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import SeekingReader
from mcap.writer import IndexType

from tdcm_ros.bagio import PayloadRows
from tdcm_ros.bagio.reader import open_bag
from test.bagio.bagio_samples import (
    blocks_by_topic,
    chunked_bags,
    messages_by_topic,
    sample_messages,
    write_mcap,
)

MESSAGES = sample_messages(120, 6)


@pytest.fixture(scope="module")
def bags() -> dict[str, bytes]:
    """Bytes of a small bag in 1 KiB chunks per chunk compression."""
    with tempfile.TemporaryDirectory() as tmp:
        return {name: data for name, (data, _) in chunked_bags(MESSAGES, Path(tmp)).items()}


def _blocks(path: Path, size: int = 7) -> tuple[dict[str, list[tuple[int, bytes]]], int]:
    """Messages per topic read in blocks (checked against ``raw_messages``), and how many
    blocks came as payload rows (read by the index)."""
    reader = open_bag(path)
    blocks = list(reader.raw_blocks(None, size))
    got = blocks_by_topic(blocks)
    assert got == messages_by_topic(reader.raw_messages())
    assert all(len(stamps) <= size for _, stamps, _ in blocks)
    return got, sum(isinstance(payloads, PayloadRows) for _, _, payloads in blocks)


@pytest.mark.parametrize("compression", ["zstd", "lz4", "none"])
def test_a_complete_file_is_read_by_its_message_indexes(
        bags: dict[str, bytes], tmp_path: Path, compression: str) -> None:
    path = tmp_path / "bag.mcap"
    path.write_bytes(bags[compression])
    got, rows = _blocks(path)
    assert [len(got[t]) for t in ("/tension", "/markers")] == [120, 20]
    assert rows > 0


def test_without_message_indexes_the_messages_are_walked(tmp_path: Path) -> None:
    path = write_mcap(tmp_path / "plain.mcap", MESSAGES, chunk_size=1024,
                      index_types=IndexType.CHUNK)
    got, rows = _blocks(path)
    assert len(got["/tension"]) == 120 and rows == 0


def _index_offsets(data: bytes, path: Path) -> list[int]:
    """File offsets of the message index records of every chunk."""
    path.write_bytes(data)
    with path.open("rb") as stream:
        summary = SeekingReader(stream).get_summary()
    assert summary is not None
    return [offset for chunk in summary.chunk_indexes
            for offset in chunk.message_index_offsets.values()]


@pytest.mark.parametrize("field, at", [("log time", 15), ("offset", 23)])
def test_an_index_entry_that_misses_its_record_has_its_chunk_walked(
        bags: dict[str, bytes], tmp_path: Path, field: str, at: int) -> None:
    """No CRC covers a message index: an entry whose log time or offset does not match a
    message record of its channel has its chunk walked, the other chunks still read by index."""
    data = bytearray(bags["zstd"])
    offsets = _index_offsets(bytes(data), tmp_path / "scratch.mcap")
    data[offsets[len(offsets) // 2] + at] ^= 0x04
    path = tmp_path / "damaged.mcap"
    path.write_bytes(bytes(data))
    whole, whole_rows = _blocks(tmp_path / "scratch.mcap")
    got, rows = _blocks(path)
    assert got == whole and 0 < rows < whole_rows


def test_an_index_that_lists_fewer_messages_than_counted_is_not_used(
        bags: dict[str, bytes], tmp_path: Path) -> None:
    """A message index record that claims fewer (time, offset) pairs than it holds: the
    statistics count more messages than the indexes list, so the file is walked."""
    data = bytearray(bags["zstd"])
    offsets = _index_offsets(bytes(data), tmp_path / "scratch.mcap")
    index = offsets[0]
    length = int.from_bytes(data[index + 1:index + 9], "little")
    pairs = int.from_bytes(data[index + 11:index + 15], "little")
    data[index + 1:index + 9] = (length - 16).to_bytes(8, "little")
    data[index + 11:index + 15] = (pairs - 16).to_bytes(4, "little")
    path = tmp_path / "short_index.mcap"
    path.write_bytes(bytes(data))
    got, rows = _blocks(path)
    assert len(got["/tension"]) == 120 and rows == 0


def test_payload_rows_are_a_sequence_of_bytes() -> None:
    rows = PayloadRows(np.arange(12, dtype=np.uint8).reshape(3, 4))
    assert len(rows) == 3 and rows[1] == bytes([4, 5, 6, 7])
    assert list(rows) == [bytes([0, 1, 2, 3]), bytes([4, 5, 6, 7]), bytes([8, 9, 10, 11])]
    assert isinstance(rows[1:], PayloadRows) and list(rows[1:]) == list(rows)[1:]
    with pytest.raises(ValueError, match="allowed: \\(n, length\\)"):
        PayloadRows(np.zeros(3, dtype=np.uint8))
