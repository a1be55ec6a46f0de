"""bench/results.py: the results document a bench writes with ``--results FILE`` (its fields,
byte-for-byte determinism, the round trip through a file), and the results files the docs
render (doc/results/*.json), each written by a bench that takes ``--results``."""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def _load() -> ModuleType:
    """bench/results.py as a module (bench/ is scripts, not a package)."""
    name = "tdcm_bench_results_writer"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, REPO / "bench" / "results.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while the class is made
    spec.loader.exec_module(module)
    return module


results = _load()

#: The benches whose figures the docs quote: each takes --results (bench/<name>.py).
CONVERTED = ("accuracy", "bench_bagio", "bench_band", "bench_batch", "bench_controller", "bench_design", "bench_effects",
             "bench_evaluate", "bench_evaluate_memory", "bench_grids", "bench_inverse",
             "bench_latency", "bench_loading", "bench_material", "bench_mesh", "bench_pose",
             "bench_progress", "bench_roll", "bench_shape_design", "bench_solve", "bench_start",
             "bench_tendon_states", "bench_tendons", "fault_campaign", "grid_accuracy")


def fixed_provenance() -> results.Provenance:
    return results.Provenance(
        argv=("bench/bench_demo.py", "--rounds", "3", "--label", "two words"),
        environment=(("TDCM_JIT", "0"),), sha="0123456789abcdef0123456789abcdef01234567",
        dirty=False, machine=results.Machine(platform="Linux-test", python="3.11.7 (CPython)",
                                             cpu_count=2, cpu_model="Test CPU @ 2.0GHz"),
        date="2026-01-02T03:04:05Z", load_average=(0.5, 0.25, 0.125))


def demo() -> results.BenchResults:
    bench = results.BenchResults("bench_demo", provenance=fixed_provenance())
    bench.table("Single solve", [results.Column("figure"),
                                 results.Column("median", "µs", ".1f"), "count"],
                [["paper-experiment", np.float64(13.25), np.int64(2000)],
                 ["no figure", math.nan, None]], note="20 N")
    bench.table("Flags", ["flag", "value"], [["met", True], ["lost", np.bool_(False)]])
    return bench


def test_the_document_holds_command_commit_machine_date_and_tables() -> None:
    document = demo().document()
    assert list(document) == list(results.KEYS)
    assert document["format"] == results.FORMAT == "tdcm-bench-results/1"
    assert document["bench"] == "bench_demo"
    assert document["command"] == ("TDCM_JIT=0 python3 bench/bench_demo.py --rounds 3 "
                                   "--label 'two words'")
    assert document["argv"] == ["bench/bench_demo.py", "--rounds", "3", "--label", "two words"]
    assert document["environment"] == {"TDCM_JIT": "0"}
    assert document["commit"] == {"sha": "0123456789abcdef0123456789abcdef01234567",
                                  "dirty": False}
    assert document["machine"] == {"platform": "Linux-test", "python": "3.11.7 (CPython)",
                                   "cpu_count": 2, "cpu_model": "Test CPU @ 2.0GHz"}
    assert document["date"] == "2026-01-02T03:04:05Z"
    assert document["load_average"] == [0.5, 0.25, 0.125]
    first, flags = document["tables"]
    assert first == {"title": "Single solve",
                     "columns": [{"name": "figure", "unit": "", "format": ""},
                                 {"name": "median", "unit": "µs", "format": ".1f"},
                                 {"name": "count", "unit": "", "format": ""}],
                     "rows": [["paper-experiment", 13.25, 2000], ["no figure", None, None]],
                     "note": "20 N"}
    # NumPy scalars became Python numbers, NaN no figure, booleans words
    assert type(first["rows"][0][1]) is float and type(first["rows"][0][2]) is int
    assert flags["rows"] == [["met", "yes"], ["lost", "no"]] and flags["note"] is None


def test_the_output_is_the_same_bytes_for_the_same_recording() -> None:
    text = demo().dumps()
    assert text == demo().dumps() == demo().dumps()
    assert text.endswith("}\n") and "µs" in text  # UTF-8 kept, not \u escapes
    assert json.loads(text) == demo().document()
    # keys in the documented order, not sorted; a row on one line
    assert [line.split('"')[1] for line in text.splitlines()
            if re.match(r'^  "', line)] == list(results.KEYS)
    assert '\n        ["paper-experiment", 13.25, 2000],\n' in text


def test_a_written_file_reads_back_as_the_same_document(tmp_path: Path) -> None:
    path = demo().write(tmp_path / "bench_demo.json")
    assert not list(tmp_path.glob(".*partial"))
    again = results.read_results(path)
    assert again.document() == demo().document()
    assert again.dumps() == path.read_text(encoding="utf-8")


@pytest.mark.parametrize("rows, phrase", [([["a"]], "1 cells for 2 columns"),
                                          ([["a", object()]], "is not text, a number or None")])
def test_a_row_that_does_not_fit_is_refused(rows: list[list[object]], phrase: str) -> None:
    bench = results.BenchResults("bench_demo", provenance=fixed_provenance())
    with pytest.raises(results.ResultsError, match=phrase):
        bench.table("T", ["a", "b"], rows)


@pytest.mark.parametrize("change, phrase", [
    (lambda d: d.update(format="other/1"), "format"),
    (lambda d: d.pop("machine"), "missing keys: machine"),
    (lambda d: d["tables"][0]["rows"].append([1]), r"tables\[0\].rows"),
    (lambda d: d.update(commit={"sha": None}), "commit")])
def test_a_malformed_document_is_refused_naming_the_file(tmp_path: Path, change, phrase) -> None:
    document = demo().document()
    change(document)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(document))
    with pytest.raises(results.ResultsError, match=phrase) as error:
        results.read_results(path)
    assert str(path) in str(error.value)
    path.write_text("{not json")
    with pytest.raises(results.ResultsError, match=re.escape(str(path))):
        results.read_results(path)


def test_provenance_is_this_process_and_this_checkout(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in results.ENVIRONMENT:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("TDCM_JIT", "0")
    monkeypatch.setenv("TDCM_UNRELATED", "x")
    found = results.Provenance.capture(["bench/bench_demo.py", "--quick"])
    assert found.command == "TDCM_JIT=0 python3 bench/bench_demo.py --quick"
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", found.date)
    assert found.machine.cpu_count == os.cpu_count()
    assert found.machine.python.startswith(".".join(map(str, sys.version_info[:3])))
    if shutil.which("git") and (REPO / ".git").exists():
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True,
                              text=True, check=True).stdout.strip()
        assert found.sha == head and isinstance(found.dirty, bool)


def test_outside_a_checkout_the_commit_is_unknown(tmp_path: Path) -> None:
    assert results.git_commit(tmp_path) == (None, None)


@pytest.mark.parametrize("text, model", [
    ("processor\t: 0\nmodel name\t: AMD EPYC  7B13\nflags\t: fpu\n", "AMD EPYC 7B13"),
    ("processor\t: 0\nBogoMIPS\t: 50.00\nModel\t: Raspberry Pi 4 Model B Rev 1.4\n",
     "Raspberry Pi 4 Model B Rev 1.4"),
    ("processor\t: 0\n", None)])
def test_the_cpu_model_is_read_from_cpuinfo(tmp_path: Path, text: str, model: str | None) -> None:
    path = tmp_path / "cpuinfo"
    path.write_text(text)
    assert results.cpu_model(path) == model
    assert results.cpu_model(tmp_path / "missing") is None


def test_the_results_option_checks_its_folder_before_the_bench_runs(tmp_path: Path) -> None:
    parser = argparse.ArgumentParser()
    results.add_results_argument(parser, "bench_demo")
    assert parser.parse_args([]).results is None
    assert parser.parse_args(["--results", str(tmp_path / "a.json")]).results == \
        tmp_path / "a.json"
    assert "doc/results/bench_demo.json" in parser.format_help()
    for bad in (tmp_path / "missing" / "a.json", tmp_path):
        with pytest.raises(SystemExit):
            parser.parse_args(["--results", str(bad)])


@pytest.mark.parametrize("name", CONVERTED)
def test_every_bench_the_docs_quote_takes_results(name: str) -> None:
    source = (REPO / "bench" / f"{name}.py").read_text()
    assert re.search(rf'add_results_argument\(.*, "{name}"\)', source)
    assert f'BenchResults("{name}")' in source and ".write(args.results)" in source


def test_the_docs_results_files_are_results_of_those_benches() -> None:
    files = sorted((REPO / "doc" / "results").glob("*.json"))
    assert files, "doc/results holds the docs' results files"
    for path in files:
        found = results.read_results(path)
        assert found.bench == path.stem and path.stem in CONVERTED, path
        assert found.tables and found.provenance.sha, path
        assert found.dumps() == path.read_text(encoding="utf-8"), f"{path}: not as written"
