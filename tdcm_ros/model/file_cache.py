"""Rows of numbers computed from a file, kept on disk by the file's content.

A mesh body's slices (:mod:`tdcm_ros.model.mesh_body`) cost a process reading the mesh (for a
format other than STL, trimesh's import: ~1.5 s on the shared 2-core test machine) and
slicing it; every node of a graph reads the body again. So the slices are kept here, keyed by
the file's bytes and a ``salt`` naming everything else they depend on (the unit), and a
process reading the same file again skips both.

Folder: ``TDCM_CACHE_DIR`` if set (set and empty: no cache), else ``$XDG_CACHE_HOME/tdcm_ros``
(``~/.cache/tdcm_ros``), in its ``rows`` folder. An entry is JSON (floats round-trip exactly,
so a hit is bit-identical to the computation), written to a temporary file then renamed (a
reader never sees half an entry). An entry that does not read back as finite rows of the
expected fields is computed again and replaced; a folder that cannot be made or written is
skipped (logged at debug level): the cache never fails a read. :data:`FORMAT` is bumped when
what a computation stores changes, which retires every older entry.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

LOG = logging.getLogger(__name__)

#: The version of the stored rows' meaning; part of every key.
FORMAT = 2
#: Environment variable naming the cache folder ("" turns the cache off).
CACHE_ENV = "TDCM_CACHE_DIR"

Row = tuple[float, ...]


def cache_folder() -> Path | None:
    """The folder entries go in, ``None`` when the cache is off (module docstring)."""
    configured = os.environ.get(CACHE_ENV)
    if configured is not None:
        return Path(configured) / "rows" if configured else None
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "tdcm_ros" / "rows"


def cached_rows(path: Path, salt: str, fields: Sequence[str],
                compute: Callable[[], list[Row]]) -> list[Row]:
    """The rows ``compute()`` gives for the file at ``path``: from the cache when an entry for
    its bytes, ``salt`` and ``fields`` is there, else computed and stored. Errors of ``compute``
    propagate (nothing is stored); an unreadable file is left to ``compute`` to report."""
    folder = cache_folder()
    try:
        data = path.read_bytes() if folder is not None else None
    except OSError:
        data = None
    if folder is None or data is None:
        return compute()
    digest = hashlib.sha256(data)
    digest.update(json.dumps([FORMAT, salt, list(fields)]).encode())
    entry = folder / f"{digest.hexdigest()}.json"
    found = _read(entry, len(fields))
    if found is not None:
        return found
    rows = compute()
    _write(entry, list(fields), rows)
    return rows


def _read(entry: Path, width: int) -> list[Row] | None:
    """The entry's rows if it exists and holds finite rows of ``width`` numbers."""
    try:
        stored = json.loads(entry.read_text(encoding="utf-8"))["rows"]
        rows = [tuple(float(v) for v in row) for row in stored]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not rows or any(len(row) != width or not all(map(math.isfinite, row)) for row in rows):
        LOG.debug("cache entry %s is not %d finite numbers per row: computed again", entry,
                  width)
        return None
    return rows


def _write(entry: Path, fields: list[str], rows: list[Row]) -> None:
    """Store ``rows`` at ``entry`` atomically; skipped (logged) where it cannot be written."""
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=entry.parent, suffix=".tmp")
        with os.fdopen(handle, "w", encoding="utf-8") as out:
            json.dump({"format": FORMAT, "fields": fields, "rows": rows}, out)
        os.replace(temporary, entry)
    except OSError as error:
        LOG.debug("cache entry %s not written: %s", entry, error)
