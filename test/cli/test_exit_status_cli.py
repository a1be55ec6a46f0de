"""Exit statuses through the CLI in its own process: every ``--help`` lists them, with what the
command means by one; ``calibrate`` on a terminal shows why the fit is not usable before the
table, not after it."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tdcm_ros.cli.main import EXIT_STATUSES
from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset
from test.runtime.pty_helpers import run_on_terminal
from test.support.cli import tdcm as run_tdcm

REPO = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(
    p for p in (str(REPO), os.environ.get("PYTHONPATH")) if p)}


def tdcm(*args: str) -> subprocess.CompletedProcess[str]:
    return run_tdcm(*args, cwd=REPO)


def on_terminal(*args: str) -> tuple[int, str]:
    """Exit status and what a terminal shows (stdout and stderr on one pty, as a user sees)."""
    status, _, screen = run_on_terminal([sys.executable, "-m", "tdcm_ros", *args], env=ENV,
                                        cwd=REPO, stdout_on_terminal=True, timeout=120,
                                        columns=None)
    return status, screen.replace("\r\n", "\n")


def one_line(text: str) -> str:
    return " ".join(text.split())


@pytest.mark.parametrize(("argv", "meaning"), [
    ((), None),
    (("calibrate",), ("3 a physical limit of the model, or numerics that did not converge (the "
                      "fit did not converge or a parameter is not identifiable")),
    (("record",), "1 failure (no message was recorded; the empty bag is kept)"),
    (("topic", "echo"), None)], ids=["tdcm", "calibrate", "record", "topic_echo"])
def test_help_lists_the_exit_statuses(argv: tuple[str, ...], meaning: str | None) -> None:
    done = tdcm(*argv, "--help")
    assert done.returncode == 0, done.stderr
    epilog = one_line(done.stdout.partition("exit status: ")[2])
    for code, text in EXIT_STATUSES.items():
        assert f"{code} {text}" in epilog
    if meaning:
        assert meaning in epilog


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rec = simulate(preset("paper-experiment").with_overrides(E=0.8e9), levels=(0.0, 5.0, 10.0),
                   hold_s=2.0, trials=1, tension_hz=200.0, mocap_hz=40.0, seed=5)
    return write_recording(rec, tmp_path_factory.mktemp("cal") / "sim")


def test_calibrate_shows_why_the_fit_is_not_usable_before_the_table(bag: Path) -> None:
    status, screen = on_terminal("calibrate", str(bag), "--fit", "E,w_d")
    assert status == 3, screen
    lines = screen.splitlines()
    table = next(i for i, line in enumerate(lines) if line.startswith("Table I"))
    reasons = [i for i, line in enumerate(lines)
               if line.startswith(("warning:", "tdcm calibrate: the fit is not usable"))]
    assert reasons and max(reasons) < table, screen
    assert any(lines[i].startswith("tdcm calibrate: the fit is not usable: not identifiable")
               for i in reasons)
