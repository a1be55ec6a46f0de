"""``tdcm``'s start: each command imports only what it runs (behaviour, not timing).

``tdcm solve`` must reach its JSON without the evaluation, plotting, transport or compiler
stacks; the import lists come from a child run with ``-X importtime``.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import tdcm_ros
from tdcm_ros.cli.main import COMMANDS, build_parser
from tdcm_ros.model import preset, solve

HEAVY = {"scipy", "matplotlib", "zenoh", "mcap", "rosbags", "numba", "rclpy"}
"""Top-level packages ``tdcm solve`` and ``tdcm COMMAND -h`` must not import."""


def run_child(*args: str) -> tuple[subprocess.CompletedProcess[str], set[str]]:
    """``python -X importtime -m tdcm_ros ARGS`` on this checkout; the result and the
    top-level packages it imported."""
    root = str(Path(tdcm_ros.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (root, os.environ.get("PYTHONPATH")) if p)}
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "tdcm_ros", *args],
                          capture_output=True, text=True, env=env, timeout=120, check=False)
    imported = {line.split("|")[-1].strip().split(".")[0] for line in done.stderr.splitlines()
                if line.startswith("import time:") and "|" in line}
    return done, imported


def test_solve_child_gives_the_library_json_without_heavy_imports() -> None:
    done, imported = run_child("solve", "--tension", "20", "--json")
    assert done.returncode == 0
    assert "tdcm_ros" in imported and "numpy" in imported  # the import list was read
    assert not imported & HEAVY, sorted(imported & HEAVY)
    data = json.loads(done.stdout)
    expected = solve(preset("paper-experiment"), 20.0).summary()
    data.pop("solve_time_s"), expected.pop("solve_time_s")
    assert data == json.loads(json.dumps(expected))


def test_solve_child_errors_keep_their_exit_status_and_json() -> None:
    done, imported = run_child("solve", "--tension", "-1", "--json")
    assert done.returncode == 2
    assert json.loads(done.stdout)["error"]["kind"] == "tension_out_of_range"
    assert not imported & HEAVY


@pytest.mark.parametrize("args", [["-h"], ["evaluate", "-h"], ["calibrate", "-h"],
                                  ["demo", "-h"], ["scene", "-h"], ["bench", "-h"]])
def test_help_builds_parsers_without_heavy_imports(args: list[str]) -> None:
    done, imported = run_child(*args)
    assert done.returncode == 0 and "usage: tdcm" in done.stdout
    assert not imported & HEAVY, sorted(imported & HEAVY)


def _registered(module_names: list[str]) -> set[str]:
    parser = argparse.ArgumentParser()
    subparsers = parser.add_subparsers()
    for name in module_names:
        importlib.import_module(name).register(subparsers)
    return set(subparsers.choices)


def test_the_command_table_names_what_each_module_registers() -> None:
    for module in set(COMMANDS.values()):
        assert _registered([module]) == {c for c, m in COMMANDS.items() if m == module}


def test_a_named_command_builds_only_its_parser_and_help_builds_all() -> None:
    subparsers = next(a for a in build_parser(["solve", "--tension", "1"])._actions
                      if isinstance(a, argparse._SubParsersAction))
    assert set(subparsers.choices) == {"solve"}
    for argv in (["-h"], ["nosuch"], [], None):
        everything = next(a for a in build_parser(argv)._actions
                          if isinstance(a, argparse._SubParsersAction))
        assert set(everything.choices) == set(COMMANDS)


def test_record_module_serves_both_of_its_commands(capsys: pytest.CaptureFixture[str]) -> None:
    from tdcm_ros.cli.main import main

    with pytest.raises(SystemExit) as exited:
        main(["bag", "info", "-h"])
    assert exited.value.code == 0 and "usage: tdcm bag info" in capsys.readouterr().out


def test_evaluate_child_runs_the_plain_kernel_without_numba() -> None:
    """An evaluation solves once per step: it keeps numba (and its memory) out."""
    bag = Path(tdcm_ros.__file__).resolve().parents[1] / "bags" / "paper_experiment"
    done, imported = run_child("evaluate", str(bag), "--json")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "scipy" in imported  # the import list was read (evaluation needs scipy)
    assert "numba" not in imported
    assert json.loads(done.stdout)["steps"]


def test_a_reader_that_closes_stdout_ends_the_command_quietly_with_141(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """``tdcm solve ... | head -1``: once ``head`` exits, writing raises BrokenPipeError; the
    command ends with 141 (128 + SIGPIPE) and no traceback."""
    import io

    from tdcm_ros.cli.main import CLOSED_PIPE_EXIT, EXIT_STATUSES, main

    class ClosedPipe(io.StringIO):
        def write(self, text: str) -> int:
            raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(sys, "stdout", ClosedPipe())
    assert main(["solve", "--tension", "20"]) == CLOSED_PIPE_EXIT == 141
    assert capsys.readouterr().err == ""
    assert "stdout closed" in EXIT_STATUSES[141]
