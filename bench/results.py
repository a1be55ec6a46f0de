"""Results files of the benchmarks: the figures a bench printed, with what ran them and where.

Every bench under ``bench/`` that the docs quote takes ``--results FILE`` (see
:func:`add_results_argument`) and then writes, besides printing as before, one JSON document
holding the tables it printed. The docs render those files (``doc/_ext/bench_results.py``, the
``bench-results`` directive; the files live in ``doc/results/``)::

    results = BenchResults("bench_solve")          # captures command, commit, machine, date
    results.table("Single solve", [Column("figure"), Column("median", "us", ".1f")],
                  [["paper-experiment", 13.2]], note="20 N, default settings")
    results.write(args.results)

The document, keys in this order (the output depends only on what was recorded: same
recording, same bytes)::

    {"format": "tdcm-bench-results/1",
     "bench": "bench_solve",
     "command": "python3 bench/bench_solve.py --results doc/results/bench_solve.json",
     "argv": ["bench/bench_solve.py", "--results", "doc/results/bench_solve.json"],
     "environment": {"TDCM_JIT": "0"},             # the ENVIRONMENT variables that were set
     "commit": {"sha": "2e82316...", "dirty": true},  # null, null outside a git checkout
     "machine": {"platform": "Linux-...", "python": "3.11.7 (CPython)", "cpu_count": 2,
                 "cpu_model": "AMD EPYC ..."},     # cpu_model null without /proc/cpuinfo
     "date": "2026-05-10T16:55:33Z",               # UTC, when the bench started
     "load_average": [2.02, 1.34, 1.12],           # 1, 5 and 15 min, when the bench started
     "tables": [{"title": "...",
                 "columns": [{"name": "median", "unit": "us", "format": ".1f"}, ...],
                 "rows": [["paper-experiment", 13.2], ...],
                 "note": "..."}]}                  # note null when none

Cells are text, integers, floats or null (no figure: a NaN or infinity is stored as null). A
number is stored in its column's unit (``unit``; ``""`` for text and pure numbers), at full
precision; ``format`` is the Python format spec the docs show it with (``""``: automatic, see
the directive). ``dirty`` is whether tracked files differed from the commit when the bench
started (``git status --untracked-files=no``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import shlex
import subprocess
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, TypeAlias

FORMAT = "tdcm-bench-results/1"
"""The ``format`` key of every results document this module writes and reads."""

ROOT = Path(__file__).resolve().parents[1]
"""The checkout the benches run from (its commit is recorded)."""

ENVIRONMENT = ("TDCM_JIT", "ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "RMW_IMPLEMENTATION")
"""Environment variables recorded (when set) because they change what a bench measures: the
compiled kernel, the ROS graph (the benches pin their thread pools themselves; how Python finds
its packages, e.g. a sourced ROS workspace, is not recorded)."""

DEFAULT_FOLDER = "doc/results"
"""Where the docs read results files from (relative to the checkout)."""

Cell: TypeAlias = str | int | float | None
"""One table cell: text, a number in its column's unit, or ``None`` for no figure."""


class ResultsError(ValueError):
    """A results document or a table that does not follow the format (the message says where)."""


@dataclass(frozen=True)
class Column:
    """A table column: its ``name``, the ``unit`` its numbers are in (``""`` for text and pure
    numbers such as counts and ratios) and the Python ``format`` spec the docs show its numbers
    with (``""``: automatic)."""

    name: str
    unit: str = ""
    format: str = ""

    def to_json(self) -> dict[str, str]:
        return {"name": self.name, "unit": self.unit, "format": self.format}


@dataclass(frozen=True)
class Table:
    """One table of figures: a ``title``, its columns, its rows (one cell per column) and an
    optional ``note`` (how it was measured, what a figure means)."""

    title: str
    columns: tuple[Column, ...]
    rows: tuple[tuple[Cell, ...], ...]
    note: str | None = None

    def to_json(self) -> dict[str, Any]:
        return {"title": self.title, "columns": [c.to_json() for c in self.columns],
                "rows": [list(row) for row in self.rows], "note": self.note}


@dataclass(frozen=True)
class Machine:
    """What ran the bench: ``platform.platform()``, the Python version and implementation (and
    whether it ran in a virtual environment), the number of CPUs (``os.cpu_count()``) and the CPU model (``/proc/cpuinfo``; ``None`` without
    it)."""

    platform: str
    python: str
    cpu_count: int | None
    cpu_model: str | None

    @classmethod
    def here(cls) -> Machine:
        venv = ", virtual environment" if sys.prefix != sys.base_prefix else ""
        return cls(platform=platform.platform(),
                   python=f"{platform.python_version()} ({platform.python_implementation()}{venv})",
                   cpu_count=os.cpu_count(), cpu_model=cpu_model())

    def to_json(self) -> dict[str, Any]:
        return {"platform": self.platform, "python": self.python, "cpu_count": self.cpu_count,
                "cpu_model": self.cpu_model}


@dataclass(frozen=True)
class Provenance:
    """Where and when a bench ran: its command line (``argv`` as Python got it, ``sys.argv``),
    the recorded environment variables, the commit (``None`` outside a git checkout) and whether
    tracked files differed from it, the machine, the UTC start date (ISO 8601, seconds, ``Z``)
    and the 1, 5 and 15 minute load averages at the start."""

    argv: tuple[str, ...]
    environment: tuple[tuple[str, str], ...]
    sha: str | None
    dirty: bool | None
    machine: Machine
    date: str
    load_average: tuple[float, float, float] | None

    @classmethod
    def capture(cls, argv: Sequence[str] | None = None, root: Path = ROOT) -> Provenance:
        """This process's: ``argv`` defaults to ``sys.argv``, the commit is ``root``'s."""
        sha, dirty = git_commit(root)
        try:
            one, five, fifteen = os.getloadavg()
            load: tuple[float, float, float] | None = (round(one, 2), round(five, 2),
                                                       round(fifteen, 2))
        except OSError:
            load = None
        return cls(argv=tuple(sys.argv if argv is None else argv),
                   environment=tuple((name, os.environ[name]) for name in ENVIRONMENT
                                     if name in os.environ),
                   sha=sha, dirty=dirty, machine=Machine.here(),
                   date=datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
                   load_average=load)

    @property
    def command(self) -> str:
        """The command line as a shell would take it: the recorded environment variables, then
        ``python3`` and ``argv``."""
        words = [f"{name}={shlex.quote(value)}" for name, value in self.environment]
        return " ".join([*words, shlex.join(["python3", *self.argv])])


def cpu_model(cpuinfo: Path = Path("/proc/cpuinfo")) -> str | None:
    """The first ``model name`` (x86) or ``Model``/``Hardware`` (ARM) of ``cpuinfo``, else
    ``None``."""
    try:
        text = cpuinfo.read_text(errors="replace")
    except OSError:
        return None
    found: dict[str, str] = {}
    for line in text.splitlines():
        key, sep, value = line.partition(":")
        if sep and key.strip() in ("model name", "Model", "Hardware") and value.strip():
            found.setdefault(key.strip(), " ".join(value.split()))
    return found.get("model name") or found.get("Model") or found.get("Hardware")


def git_commit(root: Path = ROOT) -> tuple[str | None, bool | None]:
    """``(sha, dirty)`` of the checkout at ``root``: ``git rev-parse HEAD`` and whether
    ``git status`` lists a changed tracked file (read only: no index refresh is written);
    ``(None, None)`` without git or outside a checkout."""
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                             text=True, check=True, timeout=30).stdout.strip()
        status = subprocess.run(["git", "--no-optional-locks", "status", "--porcelain",
                                 "--untracked-files=no"], cwd=root, capture_output=True,
                                text=True, check=True, timeout=60).stdout
    except (OSError, subprocess.SubprocessError):
        return None, None
    return sha or None, bool(status.strip())


def _cell(value: object, where: str) -> Cell:
    """``value`` as a JSON cell: NumPy scalars become Python numbers, booleans ``yes``/``no``,
    NaN and infinities ``None``."""
    if value is None or isinstance(value, str):
        return value
    if not isinstance(value, int | float) and hasattr(value, "item"):
        value = value.item()  # a NumPy scalar
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value) if math.isfinite(value) else None
    raise ResultsError(f"{where}: {value!r} is not text, a number or None")


def _column(column: Column | str) -> Column:
    return column if isinstance(column, Column) else Column(column)


class BenchResults:
    """The tables one bench run prints, with its :class:`Provenance` (captured when this object
    is made, i.e. when the bench starts)."""

    def __init__(self, bench: str, *, provenance: Provenance | None = None) -> None:
        if not bench:
            raise ResultsError("a bench needs a name")
        self.bench = bench
        self.provenance = provenance or Provenance.capture()
        self.tables: list[Table] = []

    def table(self, title: str, columns: Sequence[Column | str],
              rows: Iterable[Sequence[object]], note: str | None = None) -> Table:
        """Record a table: ``columns`` (a plain string is a column without unit or format),
        ``rows`` of one cell per column (see :data:`Cell`; numbers in the column's unit).
        Returns it."""
        cols = tuple(_column(c) for c in columns)
        if not title or not cols:
            raise ResultsError("a table needs a title and at least one column")
        cells = []
        for k, row in enumerate(rows):
            if len(row) != len(cols):
                raise ResultsError(f"table {title!r}, row {k + 1}: {len(row)} cells for "
                                   f"{len(cols)} columns")
            cells.append(tuple(_cell(v, f"table {title!r}, row {k + 1}") for v in row))
        table = Table(title, cols, tuple(cells), note)
        self.tables.append(table)
        return table

    def document(self) -> dict[str, Any]:
        """The results document (a JSON-ready dict, keys in the documented order)."""
        p = self.provenance
        return {
            "format": FORMAT,
            "bench": self.bench,
            "command": p.command,
            "argv": list(p.argv),
            "environment": dict(p.environment),
            "commit": {"sha": p.sha, "dirty": p.dirty},
            "machine": p.machine.to_json(),
            "date": p.date,
            "load_average": None if p.load_average is None else list(p.load_average),
            "tables": [t.to_json() for t in self.tables],
        }

    def dumps(self) -> str:
        """The document as JSON text: 2-space indent, but an object or list holding no object
        or list (a row, a column, the machine) on one line; UTF-8 characters kept; a newline at
        the end."""
        return _dumps(self.document(), "") + "\n"

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the document to ``path`` (replaced whole: written next to it, then renamed);
        say so on stderr. Returns the path."""
        target = Path(path)
        partial = target.with_name(f".{target.name}.partial")
        partial.write_text(self.dumps(), encoding="utf-8")
        partial.replace(target)
        print(f"{self.bench}: results written to {target}", file=sys.stderr)
        return target

    @classmethod
    def from_document(cls, document: Mapping[str, Any]) -> BenchResults:
        """The results of a document (as :meth:`document` gives and :func:`read_results` reads);
        :class:`ResultsError` naming the first key that does not follow the format."""
        check_document(document)
        machine = document["machine"]
        load = document["load_average"]
        provenance = Provenance(
            argv=tuple(document["argv"]), environment=tuple(document["environment"].items()),
            sha=document["commit"]["sha"], dirty=document["commit"]["dirty"],
            machine=Machine(platform=machine["platform"], python=machine["python"],
                            cpu_count=machine["cpu_count"], cpu_model=machine["cpu_model"]),
            date=document["date"],
            load_average=None if load is None else (load[0], load[1], load[2]))
        results = cls(document["bench"], provenance=provenance)
        for table in document["tables"]:
            results.table(table["title"], [Column(**c) for c in table["columns"]],
                          table["rows"], note=table["note"])
        return results


def _dumps(value: Any, indent: str) -> str:
    """``value`` as JSON, each container that holds another container spread over lines."""
    if isinstance(value, dict):
        items = list(value.items())
        flat = not any(isinstance(v, dict | list) for _, v in items)
        if flat or not items:
            return json.dumps(value, ensure_ascii=False, allow_nan=False)
        inner = indent + "  "
        body = ",\n".join(f"{inner}{json.dumps(k, ensure_ascii=False)}: {_dumps(v, inner)}"
                           for k, v in items)
        return f"{{\n{body}\n{indent}}}"
    if isinstance(value, list):
        if not any(isinstance(v, dict | list) for v in value):
            return json.dumps(value, ensure_ascii=False, allow_nan=False)
        inner = indent + "  "
        body = ",\n".join(f"{inner}{_dumps(v, inner)}" for v in value)
        return f"[\n{body}\n{indent}]"
    return json.dumps(value, ensure_ascii=False, allow_nan=False)


KEYS = ("format", "bench", "command", "argv", "environment", "commit", "machine", "date",
        "load_average", "tables")


def check_document(document: Mapping[str, Any]) -> None:
    """Raise :class:`ResultsError` unless ``document`` is a results document of this format."""
    if not isinstance(document, Mapping):
        raise ResultsError("a results document is a JSON object")
    if document.get("format") != FORMAT:
        raise ResultsError(f"format: {document.get('format')!r}, expected {FORMAT!r}")
    missing = [key for key in KEYS if key not in document]
    if missing:
        raise ResultsError(f"missing keys: {', '.join(missing)}")
    if not isinstance(document["argv"], list) or not all(
            isinstance(a, str) for a in document["argv"]):
        raise ResultsError("argv: a list of strings")
    if not isinstance(document["environment"], dict):
        raise ResultsError("environment: an object")
    if not isinstance(document["commit"], dict) or set(document["commit"]) != {"sha", "dirty"}:
        raise ResultsError("commit: an object with sha and dirty")
    machine = document["machine"]
    if not isinstance(machine, dict) or set(machine) != {"platform", "python", "cpu_count",
                                                         "cpu_model"}:
        raise ResultsError("machine: an object with platform, python, cpu_count and cpu_model")
    load = document["load_average"]
    if load is not None and (not isinstance(load, list) or len(load) != 3):
        raise ResultsError("load_average: three numbers or null")
    if not isinstance(document["tables"], list):
        raise ResultsError("tables: a list")
    for k, table in enumerate(document["tables"]):
        if not isinstance(table, dict) or set(table) != {"title", "columns", "rows", "note"}:
            raise ResultsError(f"tables[{k}]: an object with title, columns, rows and note")
        if not isinstance(table["columns"], list) or not all(
                isinstance(c, dict) and set(c) == {"name", "unit", "format"}
                for c in table["columns"]):
            raise ResultsError(f"tables[{k}].columns: objects with name, unit and format")
        if not isinstance(table["rows"], list) or not all(
                isinstance(r, list) and len(r) == len(table["columns"]) for r in table["rows"]):
            raise ResultsError(f"tables[{k}].rows: lists of one cell per column")


def read_results(path: str | os.PathLike[str]) -> BenchResults:
    """The results file at ``path``; :class:`ResultsError` naming it when it is not one."""
    try:
        document = json.loads(Path(path).read_text(encoding="utf-8"))
        return BenchResults.from_document(document)
    except (OSError, ValueError, TypeError, KeyError) as error:
        raise ResultsError(f"{path}: {error}") from error


def _results_path(text: str) -> Path:
    """``--results``'s type: a file in an existing folder (checked before the bench runs, not
    after its minutes of measuring)."""
    path = Path(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a folder, not a file")
    if not path.parent.resolve().is_dir():
        raise argparse.ArgumentTypeError(f"no folder {path.parent} for {text}")
    return path


def add_results_argument(parser: argparse.ArgumentParser, bench: str) -> None:
    """Add ``--results FILE`` to a bench's ``parser`` (``None`` when not given): where to write
    the results document of the run."""
    parser.add_argument("--results", type=_results_path, metavar="FILE",
                        help="also write the printed figures, with the command, commit, machine "
                             "and date, as a JSON results file (the docs' tables: "
                             f"{DEFAULT_FOLDER}/{bench}.json)")
