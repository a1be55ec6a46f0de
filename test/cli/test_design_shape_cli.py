"""``tdcm design --problem``: the answer printed and written (body file, plot, state, JSON),
the closest design written when none meets the targets, and the uniform search's options
refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tdcm_ros.model import named_design, read_body_file, solve
from test.support.cli import tdcm
from test.support.examples import REPO

WRIST = str(REPO / "config" / "design" / "tip_first_wrist.yaml")


def test_a_problem_writes_the_design_its_body_file_and_plot(tmp_path: Path) -> None:
    done = tdcm("design", "--problem", WRIST, "--workers", "1", "--out", str(tmp_path / "o"))
    assert done.returncode == 0, done.stderr
    assert "every target met" in done.stdout and "cut~linear[0]" in done.stdout
    out = tmp_path / "o"
    summary = json.loads((out / "design.json").read_text())
    assert summary["met"] and summary["targets"][1]["achieved"]["ratio"] >= 3.0
    body = read_body_file(out / "body.yaml").design()
    tip = solve(body, 2.0).tip_angle_rad
    assert tip == pytest.approx(summary["targets"][0]["achieved"]["angle"], rel=1e-12)
    assert (out / "shape.png").stat().st_size > 10_000
    assert json.loads((out / "state.json").read_text())["generations"] == summary["generations"]
    meshed = solve(named_design(str(out / "body_mesh.yaml")), 2.0)  # the STL, read back
    assert meshed.tip_angle_rad == pytest.approx(tip, rel=1e-4)


def test_json_and_an_unreachable_problem_exits_3_with_the_closest(tmp_path: Path) -> None:
    problem = tmp_path / "far.yaml"
    text = Path(WRIST).read_text().replace("body: ../bodies/", f"body: {REPO}/config/bodies/")
    problem.write_text(text.replace("{tension: 2.0}", "{tension: 0.2}")  # far too little
                       .replace("search: {seed: 0}", "search: {seed: 0, maxiter: 3}"))
    done = tdcm("design", "--problem", str(problem), "--workers", "1", "--json", "--out",
                str(tmp_path / "o"))
    assert done.returncode == 3, done.stderr
    assert "no candidate meets every target" in done.stderr and "cut~linear[0] = " in done.stderr
    summary = json.loads(done.stdout)
    assert summary["met"] is False and (tmp_path / "o" / "body.yaml").exists()


@pytest.mark.parametrize("option", [["--free", "w_n=1e-3:2e-3"], ["--samples", "10"],
                                    ["--design", "paper-experiment"], ["--tol", "1e-3"]])
def test_the_uniform_searchs_options_are_refused(option: list[str]) -> None:
    done = tdcm("design", "--problem", WRIST, *option)
    assert done.returncode == 2 and option[0] in done.stderr


def test_resume_needs_out_and_a_bad_file_is_named(tmp_path: Path) -> None:
    done = tdcm("design", "--problem", WRIST, "--resume")
    assert done.returncode == 2 and "--resume needs --out" in done.stderr
    done = tdcm("design", "--problem", str(tmp_path / "none.yaml"))
    assert done.returncode == 2 and "cannot read problem file" in done.stderr
    done = tdcm("design", "--problem", WRIST, "--workers", "two")
    assert done.returncode == 2 and "--workers" in done.stderr
