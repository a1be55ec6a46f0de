"""``tdcm param specs NODE``: every parameter of a node, from the specs it declares them with."""

from __future__ import annotations

import importlib

import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.runtime.registry import NODES
from test.support.cli import tdcm


@pytest.mark.parametrize("node", sorted(NODES))
def test_every_parameter_of_the_node_is_one_row(node: str, capsys: pytest.CaptureFixture[str]
                                                ) -> None:
    assert main(["param", "specs", node]) == 0
    rows = capsys.readouterr().out.splitlines()[2:]
    module = importlib.import_module(NODES[node].partition(":")[0])
    assert [row.split(" | ")[0].strip("| `") for row in rows] == [*module.PARAMETERS,
                                                                   "use_sim_time"]
    assert all(row.count(" | ") == 4 for row in rows)  # choices' bars are escaped


def test_a_row_shows_unit_default_and_range(capsys: pytest.CaptureFixture[str]) -> None:
    main(["param", "specs", "model_node"])
    rows = {row.split(" | ")[0].strip("| `"): row for row in capsys.readouterr().out.splitlines()}
    assert rows["solver.tol"] == ("| `solver.tol` | m | 1e-10 | (0, 0.01] m | convergence "
                                  "tolerance on the midline nodes |")
    assert "| 1850000000.0 |" in rows["design.E"]  # Design's default E
    assert "| (derived) |" in rows["design.w_n"]   # no default: the preset gives it
    assert "paper \\| free" in rows["solver.routing"]
    assert rows["use_sim_time"].startswith("| `use_sim_time` |  | False | true \\| false | take ")


def test_an_unknown_node_is_an_input_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["param", "specs", "nope"]) == 2
    assert "unknown node 'nope'" in capsys.readouterr().err


@pytest.mark.parametrize("timeout", ["0", "-1", "nan"])
def test_a_timeout_that_is_not_positive_is_refused_before_any_connection(timeout: str) -> None:
    done = tdcm("param", "get", "/model_node", "design.E", "--timeout", timeout)
    assert done.returncode == 2
    assert f"--timeout = {float(timeout)} s is out of range; allowed: > 0 s" in done.stderr
