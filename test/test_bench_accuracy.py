"""``tdcm bench accuracy --quick``: a table with every method, JSON and a Pareto PNG."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.model import accuracy
from tdcm_ros.model.baselines import METHODS

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def report() -> accuracy.Report:
    return accuracy.run_bench(quick=True)


def test_quick_run_covers_every_method(report: accuracy.Report) -> None:
    assert {row.method for row in report.rows} == set(METHODS)
    table = accuracy.format_table(report)
    for name in METHODS:
        assert name in table
    assert all(row.solves > 0 for row in report.rows)


def test_default_row_and_reference(report: accuracy.Report) -> None:
    default = [row for row in report.rows if row.default]
    assert len(default) == 1
    assert default[0].failed == 0 and default[0].not_converged == 0
    spread = report.reference["max_tip_change_to_coarser_m"]["paper/closed"]
    assert spread < 1e-8
    # The refined setting beats the default, which beats one cell per notch.
    by_label = {row.label: row for row in report.rows}
    assert by_label["algorithm1 cpn=8"].max_error_m < default[0].max_error_m \
        < by_label["algorithm1 cpn=1"].max_error_m


def test_model_differences_are_separate(report: accuracy.Report) -> None:
    assert set(report.model_differences) == {"constrained vs paper/closed",
                                             "free/closed vs paper/closed",
                                             "paper/literal vs paper/closed"}
    free = next(r for r in report.rows if r.model == "free/closed")
    # Its error is against the free routing's own reference, not the routing difference.
    assert free.max_error_m < report.model_differences["free/closed vs paper/closed"]


def test_shooting_findings_have_numbers(report: accuracy.Report) -> None:
    text = " ".join(report.shooting_findings)
    assert "shooting-whole" in text and "shooting-segmented" in text
    assert any(ch.isdigit() for ch in text)


def test_pareto_png(report: accuracy.Report, tmp_path: Path) -> None:
    path = tmp_path / "pareto.png"
    accuracy.plot_pareto(report, str(path))
    data = path.read_bytes()
    assert data.startswith(b"\x89PNG") and len(data) > 10_000


def test_cli_json_and_plot(report: accuracy.Report, tmp_path: Path,
                           monkeypatch: pytest.MonkeyPatch,
                           capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(accuracy, "run_bench", lambda **_: report)
    path = tmp_path / "p.png"
    assert main(["bench", "accuracy", "--quick", "--json", "--plot", str(path)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {row["method"] for row in data["rows"]} == set(METHODS)
    assert path.stat().st_size > 0
    assert main(["bench", "accuracy", "--quick"]) == 0
    assert "where shooting fails" in capsys.readouterr().out
