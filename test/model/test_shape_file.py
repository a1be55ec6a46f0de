"""Shape-design problem files: the shipped examples read, defaults, and every bad key named by
its path in the file."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.model.design_space import DEFAULT_ALLOWABLE_STRAIN
from tdcm_ros.model.shape_file import problem_from_mapping, read_problem_file
from tdcm_ros.model.shape_targets import (
    CurveTarget,
    NotchAngleTarget,
    StopAngleTarget,
    TipTarget,
)
from test.support.examples import REPO

MINIMAL: dict[str, Any] = {
    "body": "paper-experiment", "load": {"tension": 10.0},
    "vary": [{"field": "w_d", "law": "linear", "low": 0.5e-3, "high": 2e-3}],
    "targets": [{"tip": {"angle": 0.5}}]}


def test_the_shipped_problems_read() -> None:
    for path in sorted((REPO / "config" / "design").glob("*.yaml")):
        problem = read_problem_file(path).problem
        assert problem.goals and problem.variables.size >= 1


def test_a_body_file_is_read_relative_to_the_problem_and_sets_the_strain_default() -> None:
    read = read_problem_file(REPO / "config" / "design" / "tip_first_wrist.yaml")
    assert read.problem.variables.base.R_outer == 0.81e-3
    nitinol = problem_from_mapping({**MINIMAL, "body": "nitinol_wrist.yaml", "vary": [
        {"field": "cut", "law": "uniform", "low": 1.0e-3, "high": 1.4e-3}]},
        folder=REPO / "config" / "bodies")
    assert nitinol.problem.limits.max_strain == 0.08  # the material's recoverable strain
    assert problem_from_mapping(MINIMAL).problem.limits.max_strain == DEFAULT_ALLOWABLE_STRAIN


def test_every_target_kind_and_its_own_load() -> None:
    data = {**MINIMAL, "targets": [
        {"tip": {"x": 0.01, "z": 0.05, "position_tol": 1e-3}},
        {"curve": {"arc": {"angle": 0.8}, "tol": 2e-4}, "load": {"tension": 5.0, "mu": 0.1}},
        {"curve": {"points": [[0.001, 0.02], [0.004, 0.04]]}},
        {"notch_angles": {"kind": "angles", "angles": [0.1] * 8, "tol": 0.01}},
        {"stop_angle": {"angle": 1.2}}], "search": {"seed": 3, "maxiter": 10}}
    read = problem_from_mapping(data)
    kinds = [type(goal.target) for goal in read.problem.goals]
    assert kinds == [TipTarget, CurveTarget, CurveTarget, NotchAngleTarget, StopAngleTarget]
    arc = read.problem.goals[1].target
    assert isinstance(arc, CurveTarget)
    assert math.hypot(*arc.points[-1]) < read.problem.variables.base.length  # a chord
    assert read.problem.goals[1].load.mu == 0.1 and len(read.problem.loads) == 2
    assert (read.search.seed, read.search.maxiter) == (3, 10)


@pytest.mark.parametrize(("change", "parameter"), [
    ({"colour": 1}, "colour"),
    ({"body": 3}, "body"),
    ({"vary": {"field": "w_d"}}, "vary"),
    ({"vary": [{"field": "w_d", "low": 2e-3, "high": 1e-3}]}, "vary[0]: vary[w_d].high"),
    ({"targets": [{"tip": {"angle": "steep"}}]}, "targets[0].tip: targets.tip.angle"),
    ({"targets": [{"tip": {"angle": 1.0}, "curve": {}}]}, "targets[0]"),
    ({"targets": [{"notch_angles": {"kind": "angles", "angles": [0.1]}}]},
     "targets.notch_angles.angles"),
    ({"load": {"tension": 1.0, "stroke": 1e-3}}, "load: load"),
    ({"limits": {"max_strain": -1}}, "limits: limits.max_strain"),
    ({"fabrication": {"min_gap": 1e-3}}, "min_gap"),
    ({"search": {"speed": 2}}, "speed"),
])
def test_a_bad_key_is_named_by_its_path(change: dict[str, Any], parameter: str) -> None:
    with pytest.raises(InputError) as caught:
        problem_from_mapping({**MINIMAL, **change})
    assert caught.value.parameter == parameter


def test_a_target_without_a_load_and_an_unreadable_file(tmp_path: Path) -> None:
    data = {k: v for k, v in MINIMAL.items() if k != "load"}
    with pytest.raises(InputError, match="targets\\[0\\] has no load"):
        problem_from_mapping(data)
    with pytest.raises(InputError, match="cannot read problem file"):
        read_problem_file(tmp_path / "missing.yaml")
    (tmp_path / "bad.yaml").write_text("body: [unclosed\n")
    with pytest.raises(InputError):
        read_problem_file(tmp_path / "bad.yaml")
