"""doc/_ext/bench_results.py: the ``bench-results`` directive renders a results file that
bench/results.py wrote (caption, tables, notes); a missing or malformed file is an error naming
it; and doc/conf.py loads the extension when rosdoc2 runs it from another folder. Small Sphinx
projects built in-process."""

from __future__ import annotations

import json
import re
import shutil
import sys
from collections.abc import Iterator
from io import StringIO
from pathlib import Path

import pytest

from test.bench.test_results import REPO, demo

EXT = REPO / "doc" / "_ext"


@pytest.fixture(autouse=True)
def _own_sys_path(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The projects put an _ext folder on sys.path and import bench_results from it: both
    undone after each test."""
    monkeypatch.setattr(sys, "path", list(sys.path))
    before = sys.modules.pop("bench_results", None)
    yield
    sys.modules.pop("bench_results", None)
    if before is not None:
        sys.modules["bench_results"] = before


def ext():
    sys.path.insert(0, str(EXT))
    import bench_results

    return bench_results


def build(srcdir: Path, confdir: Path | None = None, warningiserror: bool = False
          ) -> tuple[str, Path, int]:
    """Build ``srcdir`` as HTML in-process (``warningiserror``: as ``-W``); (warnings, output
    folder, exit status)."""
    # Sphinx comes with the test extra; the ROS venv's run of the rclpy tier collects this module
    from sphinx.application import Sphinx
    from sphinx.util.docutils import docutils_namespace, patch_docutils

    out = srcdir.parent / "out"
    warnings = StringIO()
    confdir = confdir or srcdir
    with patch_docutils(confdir), docutils_namespace():
        app = Sphinx(srcdir, confdir, out, srcdir.parent / "doctrees", "html", status=StringIO(),
                     warning=warnings, freshenv=True, warningiserror=warningiserror)
        app.build(force_all=True)
    return warnings.getvalue(), out, app.statuscode


def project(tmp_path: Path, page: str) -> Path:
    """A reST project: conf.py loading the extension from doc/_ext, index.rst holding ``page``,
    results/demo.json written by bench/results.py."""
    src = tmp_path / "src"
    (src / "results").mkdir(parents=True)
    (src / "conf.py").write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(EXT)!r})\n"
        "extensions = ['bench_results']\n")
    (src / "index.rst").write_text(f"Index\n=====\n\n{page}\n")
    demo().write(src / "results" / "demo.json")
    return src


def test_a_results_file_renders_as_captioned_tables(tmp_path: Path) -> None:
    src = project(tmp_path, ".. bench-results:: results/demo.json\n")
    warnings, out, status = build(src)
    assert warnings == "" and status == 0
    html = (out / "index.html").read_text().replace("&#64;", "@")
    assert "Measured by <code" in html and "bench/bench_demo.py" in html
    assert "TDCM_JIT=0" in html
    assert ("at commit 0123456 (clean tree) on 2 CPUs (Test CPU @ 2.0GHz), Linux-test, Python "
            "3.11.7 (CPython), 2026-01-02 03:04:05 UTC, load average 0.5 at the start") in html
    assert "_downloads/" in html and "demo.json" in html  # the file itself is linked
    assert list((out / "_downloads").rglob("demo.json"))
    assert '<span class="caption-text">Single solve</span>' in html
    assert "<p>median (µs)</p>" in html and "<p>13.2</p>" in html and "<p>2,000</p>" in html
    assert '<p class="bench-results-note">20 N</p>' in html
    assert '<span class="caption-text">Flags</span>' in html and "<p>yes</p>" in html


def test_tables_are_picked_by_number(tmp_path: Path) -> None:
    src = project(tmp_path, ".. bench-results:: /results/demo.json\n   :tables: 2\n")
    warnings, out, _ = build(src)
    assert warnings == ""
    html = (out / "index.html").read_text()
    assert "Flags" in html and "Single solve" not in html


@pytest.mark.parametrize("page, text, phrase", [
    (".. bench-results:: results/missing.json", None, "results file results/missing.json"),
    (".. bench-results:: results/bad.json", "{not json", "results file results/bad.json"),
    (".. bench-results:: results/bad.json", json.dumps({"format": "other"}),
     "results file results/bad.json"),
    (".. bench-results:: results/demo.json\n   :tables: 3", None,
     "results file results/demo.json has 2 tables, no table 3")])
def test_a_missing_or_malformed_file_is_an_error_naming_it(tmp_path: Path, page: str,
                                                          text: str | None, phrase: str) -> None:
    src = project(tmp_path, page + "\n")
    if text is not None:
        (src / "results" / "bad.json").write_text(text)
    warnings, _, status = build(src)
    assert "ERROR" in warnings and phrase in warnings and status == 0, warnings
    warnings, _, status = build(src, warningiserror=True)  # -W: the build fails
    assert phrase in warnings and status == 1


def test_a_malformed_table_names_what_is_wrong(tmp_path: Path) -> None:
    src = project(tmp_path, ".. bench-results:: results/bad.json\n")
    document = demo().document()
    document["tables"][1]["rows"].append(["one cell"])
    (src / "results" / "bad.json").write_text(json.dumps(document))
    warnings, _, _ = build(src)
    assert "results/bad.json" in warnings and "table 2: rows need one cell per column" in warnings


@pytest.mark.parametrize("value, spec, text", [
    (None, "", ""), ("text", ".2f", "text"), (2000, "", "2,000"), (13.249, ".1f", "13.2"),
    (13.2456, "", "13.25"), (1634.24, "", "1634"), (247294.4, "", "247,294"),
    (2.4e-10, "", "2.40e-10"), (0.0, "", "0"), (0.25, "", "0.25")])
def test_cells_are_shown_with_their_column_format(value: object, spec: str, text: str) -> None:
    assert ext().format_cell(value, spec) == text


def test_conf_py_loads_the_extension_when_run_from_another_folder(tmp_path: Path) -> None:
    """As rosdoc2 does: a wrapping conf.py elsewhere exec()s doc/conf.py (so its ``__file__``
    is the wrapper's), and the source folder may be a copy of doc/."""
    pytest.importorskip("myst_parser")
    src = tmp_path / "copy_of_doc"
    shutil.copytree(EXT, src / "_ext", ignore=shutil.ignore_patterns("__pycache__"))
    (src / "results").mkdir()
    demo().write(src / "results" / "demo.json")
    (src / "index.md").write_text("# Index\n\n:::{bench-results} /results/demo.json\n:::\n")
    wrapper = tmp_path / "wrapper"
    wrapper.mkdir()
    (wrapper / "conf.py").write_text(
        f"exec(open({str(REPO / 'doc' / 'conf.py')!r}).read())\n"
        "extensions = [e for e in extensions if e == 'myst_parser']\n"
        "html_theme = 'basic'\n")
    warnings, out, _ = build(src, confdir=wrapper)
    assert "bench" not in warnings, warnings
    assert Path(sys.modules["bench_results"].__file__).parent == src / "_ext"
    html = (out / "index.html").read_text()
    assert "Measured by" in html and "Single solve" in html


def test_the_docs_pages_show_every_results_file_from_colon_fences() -> None:
    """Each ``bench-results`` of doc/ names a results file that exists, from a ``:::`` fence
    (test/test_doc_snippets.py and the examples' collector read backtick fences as code blocks);
    each file of doc/results is shown somewhere."""
    doc = REPO / "doc"
    shown = set()
    for page in doc.rglob("*.md"):
        for match in re.finditer(r"^(\S*)\{bench-results\} (\S+)", page.read_text(),
                                 re.MULTILINE):
            fence, target = match.groups()
            assert fence == ":::", f"{page}: {match.group(0)}"
            path = (doc / target[1:]) if target.startswith("/") else page.parent / target
            assert path.is_file(), f"{page}: {target}"
            shown.add(path.resolve())
    assert shown == {path.resolve() for path in (doc / "results").glob("*.json")}
