"""Sphinx extension: the ``bench-results`` directive renders a benchmark's results file.

A bench under ``bench/`` run with ``--results FILE`` writes the figures it printed as a JSON
results document (``bench/results.py`` defines the format, ``tdcm-bench-results/1``); the
files the docs show live in ``doc/results/``. In a MyST page (a colon fence, so that the scripts
that collect the pages' code blocks do not take it for one; a backtick fence works as well)::

    :::{bench-results} /results/bench_solve.json
    :tables: 1 3
    :::

The path is taken as ``literalinclude`` takes it: relative to the page, or, starting with
``/``, to the docs' source folder (``doc/``); so it holds wherever the source folder is copied
to (rosdoc2 builds from its own folder). ``:tables:`` picks tables by their 1-based place in the
file (default: all of them, in order); ``:class:`` adds classes to the tables.

Output: a caption line, "Measured by ``<command>`` at commit <short sha> (<clean tree or
uncommitted changes>) on <machine>, <UTC date>, load average <1 min> at the start (results
file)", the last words a download link to the file; then each table with its title as the
caption, each column headed "name (unit)", numbers shown with the column's format spec (none:
integers with thousands separators; floats to 4 significant digits, with thousands separators
from 10,000 and in exponent notation below 0.001), an empty cell for a missing figure; and the
table's note under it. A missing, unreadable or malformed file, or a table number not in it, is
an error naming the file (a failed build under ``-W``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx import addnodes
from sphinx.util.docutils import SphinxDirective

if TYPE_CHECKING:
    from sphinx.application import Sphinx
    from sphinx.util.typing import ExtensionMetadata

FORMAT = "tdcm-bench-results/1"


class ResultsFileError(ValueError):
    """The file is not a results document of :data:`FORMAT` (the message says why)."""


def format_cell(value: object, spec: str = "") -> str:
    """One cell as the docs show it: ``spec`` (a Python format spec) for numbers when given,
    else the automatic form (see the module docstring); text as it is; ``None`` empty."""
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ResultsFileError(f"cell {value!r} is not text, a number or null")
    if spec:
        try:
            return format(value, spec)
        except ValueError as error:
            raise ResultsFileError(f"format {spec!r} of {value!r}: {error}") from error
    if isinstance(value, int):
        return f"{value:,}"
    if not math.isfinite(value):
        return ""
    magnitude = abs(value)
    if magnitude == 0.0:
        return "0"
    if magnitude >= 1e4:
        return f"{value:,.0f}"
    if magnitude < 1e-3:
        return f"{value:.2e}"
    return f"{value:.4g}"


def header(column: dict[str, str]) -> str:
    """A column's heading: ``name (unit)``, or the name alone."""
    return f"{column['name']} ({column['unit']})" if column["unit"] else column["name"]


def check(document: Any) -> dict[str, Any]:
    """``document`` when it is a results document the directive can render, else
    :class:`ResultsFileError` saying what is wrong."""
    if not isinstance(document, dict):
        raise ResultsFileError("not a JSON object")
    if document.get("format") != FORMAT:
        raise ResultsFileError(f"format {document.get('format')!r}, expected {FORMAT!r}")
    for key, kind in (("command", str), ("commit", dict), ("machine", dict), ("date", str),
                      ("tables", list)):
        if not isinstance(document.get(key), kind):
            raise ResultsFileError(f"{key!r}: missing or not a {kind.__name__}")
    for k, table in enumerate(document["tables"], 1):
        where = f"table {k}"
        if not isinstance(table, dict) or not isinstance(table.get("title"), str):
            raise ResultsFileError(f"{where}: no title")
        columns = table.get("columns")
        if not isinstance(columns, list) or not columns or not all(
                isinstance(c, dict) and all(isinstance(c.get(key), str)
                                            for key in ("name", "unit", "format"))
                for c in columns):
            raise ResultsFileError(f"{where}: columns need a name, a unit and a format")
        rows = table.get("rows")
        if not isinstance(rows, list) or not all(
                isinstance(r, list) and len(r) == len(columns) for r in rows):
            raise ResultsFileError(f"{where}: rows need one cell per column")
        if table.get("note") is not None and not isinstance(table["note"], str):
            raise ResultsFileError(f"{where}: a note is text or null")
        for row in rows:
            for cell, column in zip(row, columns, strict=True):
                format_cell(cell, column["format"])
    return document


def load(path: Path) -> dict[str, Any]:
    """The checked results document in the file ``path``."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ResultsFileError(error.strerror or str(error)) from error
    try:
        document = json.loads(text)
    except ValueError as error:
        raise ResultsFileError(f"not JSON: {error}") from error
    return check(document)


def machine_text(document: dict[str, Any]) -> str:
    """The machine as the caption names it: CPUs, CPU model, platform, Python."""
    machine = document["machine"]
    count = machine.get("cpu_count")
    parts = [f"{count} CPUs" if count else "an unknown number of CPUs"]
    if machine.get("cpu_model"):
        parts[0] += f" ({machine['cpu_model']})"
    parts += [str(machine.get("platform", "unknown platform")),
              f"Python {machine.get('python', 'unknown')}"]
    return ", ".join(parts)


def caption_text(document: dict[str, Any]) -> tuple[str, str]:
    """The caption line around the command: (after the command, before the link)."""
    commit = document["commit"]
    sha = commit.get("sha")
    if sha:
        tree = {True: "uncommitted changes", False: "clean tree"}.get(commit.get("dirty"),
                                                                      "tree state unknown")
        at = f" at commit {str(sha)[:7]} ({tree})"
    else:
        at = " at an unknown commit"
    date = document["date"].replace("T", " ").replace("Z", " UTC")
    load = document.get("load_average")
    busy = (f", load average {load[0]:g} at the start"
            if isinstance(load, list) and load and isinstance(load[0], int | float) else "")
    return f"{at} on {machine_text(document)}, {date}{busy} (", ")."


def table_node(table: dict[str, Any], classes: list[str]) -> nodes.table:
    """One results table as a docutils table, its title the caption."""
    columns = table["columns"]
    node = nodes.table(classes=classes)
    node += nodes.title(text=table["title"])
    group = nodes.tgroup(cols=len(columns))
    node += group
    for _ in columns:
        group += nodes.colspec(colwidth=1)
    head = nodes.thead()
    group += head
    head += _row([header(c) for c in columns])
    body = nodes.tbody()
    group += body
    for row in table["rows"]:
        body += _row([format_cell(cell, column["format"])
                      for cell, column in zip(row, columns, strict=True)])
    return node


def _row(texts: list[str]) -> nodes.row:
    row = nodes.row()
    for text in texts:
        entry = nodes.entry()
        if text:
            entry += nodes.paragraph(text=text)
        row += entry
    return row


def parse_tables(text: str | None) -> list[int] | None:
    """``:tables:``'s value: 1-based table numbers, spaces or commas between them."""
    if text is None:
        return None
    try:
        picked = [int(word) for word in text.replace(",", " ").split()]
    except ValueError as error:
        raise ValueError(f"table numbers, e.g. '1 3': {text!r}") from error
    if not picked or min(picked) < 1:
        raise ValueError(f"table numbers from 1: {text!r}")
    return picked


class BenchResults(SphinxDirective):
    """``bench-results PATH``: the tables of a results file, under a caption saying what
    measured them (see the module docstring)."""

    required_arguments = 1
    optional_arguments = 0
    has_content = False
    option_spec: ClassVar[dict[str, Any]] = {"tables": directives.unchanged,
                                             "class": directives.class_option}

    def run(self) -> list[nodes.Node]:
        argument = self.arguments[0]
        relative, absolute = self.env.relfn2path(argument, self.env.docname)
        self.env.note_dependency(relative)
        try:
            picked = parse_tables(self.options.get("tables"))
        except ValueError as error:
            raise self.error(f"bench-results {argument}: :tables: takes {error}") from error
        try:
            document = load(Path(absolute))
        except ResultsFileError as error:
            raise self.error(f"bench-results: results file {relative} ({argument}): "
                             f"{error}") from error
        tables = document["tables"]
        if picked is not None and max(picked) > len(tables):
            raise self.error(f"bench-results: results file {relative} has {len(tables)} "
                             f"tables, no table {max(picked)}")
        after, close = caption_text(document)
        caption = nodes.paragraph(classes=["bench-results-caption"])
        caption += nodes.Text("Measured by ")
        caption += nodes.literal(text=document["command"])
        caption += nodes.Text(after)
        link = addnodes.download_reference("", "", reftarget=argument, refdoc=self.env.docname,
                                           refdomain="", reftype="download", refexplicit=True)
        link += nodes.literal(text="results file", classes=["download"])
        caption += link
        caption += nodes.Text(close)
        out: list[nodes.Node] = [caption]
        classes = ["bench-results", *self.options.get("class", [])]
        for number in picked or range(1, len(tables) + 1):
            table = tables[number - 1]
            out.append(table_node(table, classes))
            if table.get("note"):
                out.append(nodes.paragraph(text=table["note"], classes=["bench-results-note"]))
        for node in out:
            self.set_source_info(node)
        return out


def setup(app: Sphinx) -> ExtensionMetadata:
    """Register the ``bench-results`` directive."""
    app.add_directive("bench-results", BenchResults)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
