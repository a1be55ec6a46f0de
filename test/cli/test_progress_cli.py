"""Progress bars of the long commands (``figures``, ``calibrate``, ``evaluate``): drawn on stderr
when it is a terminal, never with ``-q/--quiet`` (global or after the command) or when stderr is
a pipe; stdout (``--json``) stays clean either way. Run as child processes with stderr on a pty."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import tdcm_ros
from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset
from test.runtime.pty_helpers import run_on_terminal

ROOT = Path(tdcm_ros.__file__).resolve().parents[1]
BAR = "%|"
"""What every tqdm bar line holds (percentage, then the bar's left edge)."""


def run_tdcm(*args: str, cwd: Path, tty: bool = True) -> tuple[int, str, str]:
    """``python -m tdcm_ros ARGS`` with stderr on a pseudo-terminal (``tty``) or a pipe; the
    exit status, stdout and stderr."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)}
    command = [sys.executable, "-m", "tdcm_ros", *args]
    if not tty:
        done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=cwd,
                              timeout=300, check=False)
        return done.returncode, done.stdout, done.stderr
    return run_on_terminal(command, env=env, cwd=cwd)


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rec = simulate(preset("paper-experiment").with_overrides(E=0.8e9), levels=(0.0, 5.0, 10.0),
                   hold_s=2.0, trials=1, tension_hz=200.0, mocap_hz=40.0, seed=5)
    return write_recording(rec, tmp_path_factory.mktemp("progress") / "sim")


def test_figures_draws_a_bar_per_file_on_a_terminal(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    status, out, err = run_tdcm("figures", "--points", "5", "--dpi", "40", "--out", "figs",
                                cwd=tmp_path)
    assert status == 0, err
    for name in ("fig2.png", "fig3.png", "feasibility.png"):
        assert f"{name}:   0%|" in err, err  # tqdm draws each bar at its start
    assert BAR not in out and "3 figures in" in out


@pytest.mark.parametrize("quiet", [["-q", "figures"], ["figures", "--quiet"]])
def test_quiet_global_or_after_the_command_draws_nothing(quiet: list[str],
                                                         tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    status, out, err = run_tdcm(*quiet, "--points", "5", "--dpi", "40", "--out", "figs",
                                cwd=tmp_path)
    assert status == 0, err
    assert BAR not in err and err.strip() == ""
    assert "3 figures in" in out


def test_no_bar_when_stderr_is_not_a_terminal(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    status, out, err = run_tdcm("figures", "--points", "5", "--dpi", "40", "--out", "figs",
                                cwd=tmp_path, tty=False)
    assert status == 0, err
    assert err == "" and "3 figures in" in out


def test_calibrate_bar_counts_the_fit_and_json_stays_clean(bag: Path, tmp_path: Path) -> None:
    status, out, err = run_tdcm("calibrate", str(bag), "--json", cwd=tmp_path)
    assert status == 0, err
    assert "reading bags:   0%|" in err and "fitting E: 0it" in err, err
    assert "Table I before and after:   0%|" in err
    assert json.loads(out)["parameters"]["E"]["unit"] == "Pa"


def test_evaluate_bar_and_quiet(bag: Path, tmp_path: Path) -> None:
    status, out, err = run_tdcm("evaluate", str(bag), "--json", cwd=tmp_path)
    assert status == 0 and "reading bags:   0%|" in err
    assert json.loads(out)["steps"]
    status, out, err = run_tdcm("evaluate", str(bag), "--json", "-q", cwd=tmp_path)
    assert status == 0 and BAR not in err
