"""Rows kept on disk by a file's content (:mod:`tdcm_ros.model.file_cache`), and the mesh body
read through them: a hit is bit-identical and skips the mesh library; a changed file, another
unit, a damaged entry or an unwritable folder recompute; the cache never fails a read."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tdcm_ros.model import mesh_body
from tdcm_ros.model.body_file import read_body_file
from tdcm_ros.model.file_cache import CACHE_ENV, cache_folder, cached_rows
from tdcm_ros.model.mesh_body import read_mesh_body

BODIES = Path(__file__).resolve().parents[2] / "config" / "bodies"
FIELDS = ("a", "b")


class Counting:
    """A computation that counts its calls."""

    def __init__(self, rows: list[tuple[float, ...]]) -> None:
        self.rows, self.calls = rows, 0

    def __call__(self) -> list[tuple[float, ...]]:
        self.calls += 1
        return self.rows


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache" / "rows"


def test_a_second_read_of_the_same_bytes_is_a_hit_and_exact(tmp_path: Path, folder: Path
                                                             ) -> None:
    source = tmp_path / "data.bin"
    source.write_bytes(b"one")
    rows = [(0.1, 1.0 / 3.0), (2.5e-300, -7.0)]
    compute = Counting(rows)
    assert cached_rows(source, "mm", FIELDS, compute) == rows and compute.calls == 1
    assert cached_rows(source, "mm", FIELDS, compute) == rows and compute.calls == 1
    assert len(list(folder.glob("*.json"))) == 1 and not list(folder.glob("*.tmp"))
    # another salt, other fields or other bytes: another entry, computed
    cached_rows(source, "m", FIELDS, compute)
    cached_rows(source, "m", ("a", "c"), compute)
    source.write_bytes(b"two")
    cached_rows(source, "m", FIELDS, compute)
    assert compute.calls == 4


@pytest.mark.parametrize("damage", ['{"rows": [[1.0]]}', '{"rows": [[1.0, NaN]]}', "{",
                                    '{"rows": "x"}', '{"rows": []}'])
def test_a_damaged_entry_is_computed_again_and_replaced(tmp_path: Path, folder: Path,
                                                        damage: str) -> None:
    source = tmp_path / "data.bin"
    source.write_bytes(b"one")
    compute = Counting([(1.0, 2.0)])
    cached_rows(source, "mm", FIELDS, compute)
    (entry,) = folder.glob("*.json")
    entry.write_text(damage, encoding="utf-8")
    assert cached_rows(source, "mm", FIELDS, compute) == [(1.0, 2.0)] and compute.calls == 2
    assert json.loads(entry.read_text(encoding="utf-8"))["rows"] == [[1.0, 2.0]]


def test_no_folder_or_an_unwritable_one_computes_every_time(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch
                                                            ) -> None:
    source = tmp_path / "data.bin"
    source.write_bytes(b"one")
    compute = Counting([(1.0, 2.0)])
    monkeypatch.setenv(CACHE_ENV, "")  # off
    assert cache_folder() is None
    cached_rows(source, "mm", FIELDS, compute)
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder", encoding="utf-8")
    monkeypatch.setenv(CACHE_ENV, str(blocker))  # its rows folder cannot be made
    assert cached_rows(source, "mm", FIELDS, compute) == [(1.0, 2.0)]
    assert cached_rows(source, "mm", FIELDS, compute) == [(1.0, 2.0)]
    assert compute.calls == 3


def test_the_default_folder_is_the_users_cache(monkeypatch: pytest.MonkeyPatch,
                                               tmp_path: Path) -> None:
    monkeypatch.delenv(CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache_folder() == tmp_path / "tdcm_ros" / "rows"


def test_a_mesh_read_again_skips_reading_it_and_gives_the_same_body(
        folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    stl = BODIES / "tee_notches.stl"
    first = read_mesh_body(stl, "mm")
    design = read_body_file(BODIES / "tee_mesh.yaml").design()

    def no_mesh_library(*_args: object) -> None:
        raise AssertionError("the mesh was loaded again")

    monkeypatch.setattr(mesh_body, "read_mesh", no_mesh_library)
    assert read_mesh_body(stl, "mm") == first  # bit for bit (frozen dataclasses compare ==)
    assert read_body_file(BODIES / "tee_mesh.yaml").design() == design
    with pytest.raises(AssertionError, match="loaded again"):
        read_mesh_body(stl, "m")  # another unit is another entry
