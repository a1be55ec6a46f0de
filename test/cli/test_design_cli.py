"""The ``tdcm design`` contract, run as a user runs it (a subprocess): JSON fields, every Pareto
design re-solved at its tension, --out files, the table, and the exit statuses."""

import csv
import json
import sys

import pytest

from tdcm_ros.model import Design, solve
from test.support.cli import tdcm

KEYS = {"design", "target", "tension_budget_n", "allowable_strain", "tol", "ladder",
        "base_design", "free", "sampling", "seed", "samples", "counts", "solves", "rounds",
        "pareto", "time_s"}
ROW_KEYS = {"index", "free", "design", "tension_n", "tip_angle", "peak_strain", "reach",
            "reach_tension_n"}
SEARCH = ("--tip-angle", "0.45", "--free", "w_n=0.5e-3:3e-3", "--free", "N=3:12",
          "--free", "w_d=0.6e-3:2.2e-3", "--samples", "300", "--allowable-strain", "0.03")


@pytest.fixture(scope="module")
def found():
    proc = tdcm("design", *SEARCH, "--json")
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_json_has_the_search_counts_and_pareto_rows(found):
    assert KEYS <= set(found)
    assert found["target"] == {"kind": "tip_angle", "value": 0.45, "unit": "rad"}
    assert found["free"] == {"w_n": [0.5e-3, 3e-3], "N": [3, 12], "w_d": [0.6e-3, 2.2e-3]}
    assert found["tension_budget_n"] == [0.0, 20.0] and found["samples"] == 300
    assert sum(found["counts"].values()) == 300 and found["counts"]["meets"] > 0
    assert found["pareto"] and all(set(row) == ROW_KEYS for row in found["pareto"])
    tensions = [row["tension_n"] for row in found["pareto"]]
    assert tensions == sorted(tensions)


def test_every_pareto_design_reaches_the_target_at_its_tension(found):
    for row in found["pareto"]:
        fields = {k: v for k, v in row["design"].items() if k not in ("L", "profile")}
        design = Design(**fields)
        assert {k: row["design"][k] for k in row["free"]} == row["free"]
        result = solve(design, row["tension_n"])
        assert result.tip_angle_rad == pytest.approx(0.45, abs=1e-9)
        assert result.tip_angle_rad == row["tip_angle"]
        assert 0.0 < row["peak_strain"] <= 0.03 and row["reach"] >= 0.45


def test_table_lists_the_pareto_set_by_tension(found):
    proc = tdcm("design", *SEARCH, "--top", "1")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("design paper-experiment: tip angle 0.45 rad within 0-20 N")
    assert f"{found['counts']['meets']} meets" in lines[0]
    assert lines[1].startswith(f"Pareto set: {len(found['pareto'])} designs")
    assert "tension (N)" in lines[2] and "peak strain (%)" in lines[2]
    assert f"{found['pareto'][0]['tension_n']:.6f}" in lines[3]
    assert len(found["pareto"]) == 1 or lines[4].startswith(f"... {len(found['pareto']) - 1} more")


def test_out_writes_the_summary_the_pareto_table_and_the_plot(found, tmp_path):
    pytest.importorskip("matplotlib")
    proc = tdcm("design", *SEARCH, "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["design.json", "pareto.csv", "pareto.png"]
    assert json.loads((out / "design.json").read_text())["pareto"] == found["pareto"]
    with (out / "pareto.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [float(r["tension_n"]) for r in rows] == [r["tension_n"] for r in found["pareto"]]
    assert (out / "pareto.png").stat().st_size > 10_000


def test_no_design_meeting_the_target_exits_3_naming_the_closest():
    proc = tdcm("design", "--tip-angle", "2", "--free", "w_n=1e-3:2e-3", "--samples", "16",
                "--json")
    assert proc.returncode == 3
    error = json.loads(proc.stdout)["error"]
    assert error["kind"] == "no_design_meets_target"
    assert "the closest reaches" in error["message"] and "w_n = " in error["message"]
    assert len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(("args", "names"), [
    (["--free", "w_n=1e-3"], "--free 'w_n=1e-3' is not NAME=MIN:MAX"),
    (["--free", "w_x=1:2"], "free field = 'w_x'"),
    (["--free", "w_n=2e-3:1e-3"], "w_n range 0.002:0.001 is empty"),
    (["--free", "w_d=1e-3:9e-3"], "w_d max = 0.009 is out of range; allowed: (0, 2 R_outer"),
    (["--free", "N=3:x"], "--free N max = 'x' is not an integer"),
    (["--free", "w_n=1e-3:2e-3", "--samples", "0"], "samples = 0"),
    (["--free", "w_n=1e-3:2e-3", "--tension-max", "0"], "tension_max = 0.0"),
])
def test_bad_input_exits_2_naming_the_parameter(args, names):
    proc = tdcm("design", "--tip-angle", "0.3", *args)
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert names in proc.stderr


@pytest.mark.parametrize("quiet", [False, True])
def test_progress_bar_on_a_terminal_and_stdout_stays_json(quiet, tmp_path):
    import os
    from pathlib import Path

    import tdcm_ros
    from test.runtime.pty_helpers import run_on_terminal

    root = Path(tdcm_ros.__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (str(root), os.environ.get("PYTHONPATH")) if p)}
    status, out, err = run_on_terminal(
        [sys.executable, "-m", "tdcm_ros", "design", *SEARCH, "--json",
         *(["-q"] if quiet else [])], env=env, cwd=tmp_path)
    assert status == 0, err
    assert json.loads(out)["samples"] == 300
    assert ("design search:" in err) is not quiet, err
