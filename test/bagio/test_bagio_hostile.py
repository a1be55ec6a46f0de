"""Hostile input for the bag reader: flipped bytes and cuts in a small valid MCAP file.

Whatever the damage, ``open_bag`` and reading give messages, with a warning whenever what they
give differs from the file as written, or raise ``BagError``: never another exception, never a
hang (each example must finish within the hypothesis deadline). Read in blocks (by the message
indexes, which no CRC covers), each topic's messages are those read one by one.
"""

from __future__ import annotations

import struct
import tempfile
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.reader import SeekingReader

from tdcm_ros.bagio import BagError, to_dict
from tdcm_ros.bagio.reader import open_bag
from test.bagio.bagio_samples import (
    blocks_by_topic,
    chunked_bags,
    messages_by_topic,
    sample_messages,
)


@pytest.fixture(scope="module")
def bags() -> dict[str, tuple[bytes, list[tuple[str, int, object]]]]:
    """Bytes of a small bag per chunk compression, with its messages (topic, log time, dict)."""
    with tempfile.TemporaryDirectory() as tmp:
        return chunked_bags(sample_messages(120, 6), Path(tmp))


def _read(path: Path) -> tuple[list[tuple[str, int, object]], list[str]] | None:
    """Messages and warnings, or None on a BagError; any other exception fails the test."""
    try:
        reader = open_bag(path)
        got = [(t, s, to_dict(m)) for t, s, m in reader.messages()]
        raw = list(reader.raw_messages())
        blocks = list(reader.raw_blocks(None, 7))
    except BagError:
        return None
    assert len(raw) == len(got) <= reader.message_count or reader.warnings
    assert blocks_by_topic(blocks) == messages_by_topic(raw)  # read by index or walked
    return got, reader.warnings


@settings(max_examples=150, deadline=5000,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(compression=st.sampled_from(["zstd", "lz4", "none"]), data=st.data())
def test_flipped_bytes_give_messages_with_a_warning_or_a_bag_error(
        bags: dict[str, tuple[bytes, list[tuple[str, int, object]]]], tmp_path: Path,
        compression: str, data: st.DataObject) -> None:
    original, expected = bags[compression]
    damaged = bytearray(original)
    flips = data.draw(st.lists(st.tuples(st.integers(0, len(original) - 1),
                                         st.integers(1, 255)), min_size=1, max_size=4))
    for position, mask in flips:
        damaged[position] ^= mask
    cut = data.draw(st.one_of(st.just(len(damaged)), st.integers(0, len(damaged))))
    path = tmp_path / f"hostile_{compression}.mcap"
    path.write_bytes(bytes(damaged[:cut]))
    result = _read(path)
    if result is None:
        return
    got, warnings = result
    for topic, stamp, _ in got:
        assert isinstance(topic, str) and isinstance(stamp, int)
    if got != expected:  # chunks are CRC-checked: a difference is always said
        assert warnings, f"silent difference after flips {flips}, cut at {cut}"


@settings(max_examples=100, deadline=5000,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(compression=st.sampled_from(["zstd", "lz4", "none"]), data=st.data())
def test_a_flip_in_one_chunk_loses_that_chunk_only(
        bags: dict[str, tuple[bytes, list[tuple[str, int, object]]]], tmp_path: Path,
        compression: str, data: st.DataObject) -> None:
    original, expected = bags[compression]
    path = tmp_path / f"one_chunk_{compression}.mcap"
    path.write_bytes(original)
    with path.open("rb") as stream:
        chunks = SeekingReader(stream).get_summary().chunk_indexes  # type: ignore[union-attr]
    chunk = data.draw(st.sampled_from(chunks))
    position = data.draw(st.integers(chunk.chunk_start_offset,
                                     chunk.chunk_start_offset + chunk.chunk_length - 1))
    damaged = bytearray(original)
    damaged[position] ^= data.draw(st.integers(1, 255))
    path.write_bytes(bytes(damaged))
    reader = open_bag(path)
    got = [(t, s, to_dict(m)) for t, s, m in reader.messages()]
    if got != expected:
        assert any(f"corrupt chunk at byte {chunk.chunk_start_offset}" in w
                   for w in reader.warnings)
        assert got == [e for e in expected
                       if not chunk.message_start_time <= e[1] <= chunk.message_end_time]
        assert reader.message_count == len(got)


@pytest.mark.parametrize("claimed", [2**63 + 1000, 2**62, 1 << 31])
def test_a_chunk_claiming_an_absurd_uncompressed_size_is_skipped_with_a_warning(
        bags: dict[str, tuple[bytes, list[tuple[str, int, object]]]], tmp_path: Path,
        claimed: int) -> None:
    """Found by the flip test in CI: a flipped bit in a zstd chunk's uncompressed-size field
    made the decompressor raise ``OverflowError``."""
    original, expected = bags["zstd"]
    path = tmp_path / "absurd_size.mcap"
    path.write_bytes(original)
    with path.open("rb") as stream:
        chunk = SeekingReader(stream).get_summary().chunk_indexes[1]  # type: ignore[union-attr]
    damaged = bytearray(original)
    # Chunk record: opcode (1), length (8), start and end time (8 + 8), uncompressed size (8).
    struct.pack_into("<Q", damaged, chunk.chunk_start_offset + 25, claimed)
    path.write_bytes(bytes(damaged))
    reader = open_bag(path)
    got = [(t, s, to_dict(m)) for t, s, m in reader.messages()]
    assert any(f"corrupt chunk at byte {chunk.chunk_start_offset}" in w for w in reader.warnings)
    assert got == [e for e in expected
                   if not chunk.message_start_time <= e[1] <= chunk.message_end_time]


CONTENT = bytes(range(256)) * 4096  #: 1 MiB of chunk content


def _frames(compression: str) -> tuple[bytes, bytes, Any]:
    """:data:`CONTENT` compressed into a frame that declares its size and one that does not, and the
    reader's decompressor of that kind."""
    import lz4.frame
    import zstandard

    from tdcm_ros.bagio.reader import _lz4, _zstd

    if compression == "zstd":
        return (zstandard.ZstdCompressor().compress(CONTENT),
                zstandard.ZstdCompressor(write_content_size=False).compress(CONTENT), _zstd)
    return (lz4.frame.compress(CONTENT, store_size=True),
            lz4.frame.compress(CONTENT, store_size=False), _lz4)


@pytest.mark.parametrize("compression", ["zstd", "lz4"])
def test_a_chunk_allocates_what_its_data_holds_not_what_a_field_claims(compression: str) -> None:
    """A damaged size field used to be trusted as the output buffer (zstd: up to 1 GiB, a
    MemoryError on a busy machine, found by the flip test above; lz4: its frame header's size,
    guarded by a one-byte checksum). A declared size must be the chunk's; an undeclared one is
    read in pieces, never past the chunk's claim."""
    import tracemalloc

    from tdcm_ros.bagio.reader import MAX_CHUNK_BYTES, _Damaged

    sized, unsized, decompress = _frames(compression)
    content = CONTENT
    assert decompress(sized, len(content)) == content == decompress(unsized, len(content))
    tracemalloc.start()
    try:
        with pytest.raises(_Damaged, match=f"its {compression} frame holds 1048576"):
            decompress(sized, MAX_CHUNK_BYTES)
        assert decompress(unsized, MAX_CHUNK_BYTES) == content  # the caller sees the size differ
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 8 * len(content)
    with pytest.raises(_Damaged, match="holds more"):
        decompress(unsized, len(content) - 1)


def test_a_cut_or_empty_lz4_frame() -> None:
    import lz4.frame

    from tdcm_ros.bagio.reader import _Damaged, _lz4

    _, unsized, _ = _frames("lz4")
    with pytest.raises(_Damaged, match="cut short"):
        _lz4(unsized[:len(unsized) // 2], 1 << 20)
    assert _lz4(lz4.frame.compress(b""), 0) == b""
