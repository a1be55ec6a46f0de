"""Every script under bench/ takes ``--results FILE`` (bench/results.py): its ``--help`` lists the
option with the default name the docs read, ``doc/results/<script name>.json``, and it records its
tables under that name. A script is a ``bench/*.py`` with ``if __name__ == "__main__"``; the
others are helper modules the scripts import (:data:`HELPERS`)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BENCH = REPO / "bench"

#: bench/*.py that are no scripts: imported by the scripts, nothing to run.
HELPERS = frozenset({"results"})


def _is_script(path: Path) -> bool:
    return re.search(r'^if __name__ == "__main__":', path.read_text(), re.MULTILINE) is not None


SCRIPTS = tuple(sorted(p.stem for p in BENCH.glob("*.py")
                       if p.stem not in HELPERS and _is_script(p)))

# The --help runs are made once, side by side, so every test of this module stays on one worker.
pytestmark = pytest.mark.xdist_group("bench_help")


def _help(name: str) -> subprocess.CompletedProcess[str]:
    """``python3 bench/<name>.py --help`` from the checkout, the checkout on ``PYTHONPATH``."""
    env = {**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "100"}
    return subprocess.run([sys.executable, f"bench/{name}.py", "--help"], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=120, check=False)


@pytest.fixture(scope="module")
def helps() -> dict[str, subprocess.CompletedProcess[str]]:
    """Every script's ``--help``, run in parallel (one process per CPU at a time)."""
    with ThreadPoolExecutor(max_workers=max(2, os.cpu_count() or 1)) as pool:
        return dict(zip(SCRIPTS, pool.map(_help, SCRIPTS), strict=True))


def test_the_scripts_are_found() -> None:
    assert {"bench_solve", "bench_latency", "fault_campaign", "accuracy"} <= set(SCRIPTS)
    others = {p.stem for p in BENCH.glob("*.py")} - set(SCRIPTS)
    assert others == HELPERS, f"bench/*.py neither a script nor a known helper: {others - HELPERS}"


@pytest.mark.parametrize("name", SCRIPTS)
def test_help_lists_results(name: str, helps: dict[str, subprocess.CompletedProcess[str]]
                            ) -> None:
    done = helps[name]
    assert done.returncode == 0, done.stderr
    assert re.search(r"^\s+--results FILE\b", done.stdout, re.MULTILINE), done.stdout
    assert f"doc/results/{name}.json" in done.stdout, done.stdout


@pytest.mark.parametrize("name", SCRIPTS)
def test_it_records_its_tables_under_its_name(name: str) -> None:
    source = (BENCH / f"{name}.py").read_text()
    assert re.search(rf'add_results_argument\(.*, "{name}"\)', source)
    assert f'BenchResults("{name}")' in source and ".write(args.results)" in source
