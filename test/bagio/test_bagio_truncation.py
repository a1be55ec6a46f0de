"""A cut MCAP file yields a prefix of its messages, each intact, or a BagError: nothing else."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.reader import SeekingReader

from tdcm_ros.bagio import BagError, to_dict
from tdcm_ros.bagio.reader import open_bag
from test.bagio.bagio_samples import chunked_bags, sample_messages, write_mcap

N = 300


@pytest.fixture(scope="module")
def bag_bytes() -> dict[str, tuple[bytes, list[tuple[str, int, object]]]]:
    """Bytes of one bag per compression (small chunks) and an unchunked one, with the messages."""
    expected = sample_messages(N, 7)
    with tempfile.TemporaryDirectory() as tmp:
        out = chunked_bags(expected, Path(tmp))
        out["unchunked"] = (_unchunked(Path(tmp) / "unchunked.mcap", expected),
                            out["none"][1])
    return out


def _unchunked(path: Path, expected: list[tuple[str, int, str, object]]) -> bytes:
    """An MCAP of loose message records (no chunks, no summary repeats of channels)."""
    return write_mcap(path, expected, use_chunking=False, repeat_channels=False,
                      repeat_schemas=False).read_bytes()


@settings(max_examples=120,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(compression=st.sampled_from(["zstd", "lz4", "none", "unchunked"]), fraction=st.floats(0.0, 1.0))
def test_cut_file_gives_an_intact_prefix_or_bag_error(
        bag_bytes: dict[str, tuple[bytes, list[tuple[str, int, object]]]], tmp_path: Path,
        compression: str, fraction: float) -> None:
    data, expected = bag_bytes[compression]
    cut = int(fraction * len(data))
    path = tmp_path / f"cut_{compression}_{cut}.mcap"
    path.write_bytes(data[:cut])
    try:
        reader = open_bag(path)
        got = [(t, s, to_dict(m)) for t, s, m in reader.messages()]
    except BagError:
        return
    assert got == expected[:len(got)]
    assert reader.message_count == len(got)
    if cut < len(data):
        assert len(got) < len(expected) or reader.warnings
        assert any("truncated" in w or "summary" in w for w in reader.warnings)


def test_every_complete_chunk_survives(
        bag_bytes: dict[str, tuple[bytes, list[tuple[str, int, object]]]], tmp_path: Path) -> None:
    """Cutting just before the summary loses nothing; cutting in the last chunk loses it only."""
    data, expected = bag_bytes["zstd"]
    path = tmp_path / "whole.mcap"
    path.write_bytes(data)
    with path.open("rb") as stream:
        summary = SeekingReader(stream).get_summary()
    assert summary is not None
    last = summary.chunk_indexes[-1]
    data_end = last.chunk_start_offset + last.chunk_length + last.message_index_length
    cases = {data_end: len(expected), last.chunk_start_offset + 20:
             len(expected) - sum(1 for _ in _in_chunk(expected, last))}
    for cut, count in cases.items():
        path.write_bytes(data[:cut])
        reader = open_bag(path)
        assert reader.message_count == count
        assert [(t, s, to_dict(m)) for t, s, m in reader.messages()] == expected[:count]


def _in_chunk(expected: list[tuple[str, int, object]], chunk: object) -> list[object]:
    return [e for e in expected
            if chunk.message_start_time <= e[1] <= chunk.message_end_time]  # type: ignore[attr-defined]
