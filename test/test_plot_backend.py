"""The one pyplot loader: Agg when matplotlib is there; without it, a typed error naming the
``plot`` extra, the option and its value, from every function that writes a plot (they all load
pyplot before reading their inputs, so the inputs here are placeholders)."""

from __future__ import annotations

import ast
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import tdcm_ros
from tdcm_ros.cli.main import main
from tdcm_ros.demo.tracking_plots import write_tracking_plots
from tdcm_ros.errors import InputError
from tdcm_ros.figures import write_figures
from tdcm_ros.metrics import write_plots
from tdcm_ros.model.accuracy import plot_pareto
from tdcm_ros.plot_backend import load_pyplot
from tdcm_ros.plotting import plot_search, plot_solution

HINT = "pip install 'tdcm_ros[plot]'"


@pytest.fixture
def no_matplotlib(monkeypatch: pytest.MonkeyPatch) -> None:
    """``import matplotlib`` fails as it does where the ``plot`` extra is not installed."""
    monkeypatch.setitem(sys.modules, "matplotlib", None)


def test_pyplot_comes_on_the_agg_backend() -> None:
    matplotlib = pytest.importorskip("matplotlib")
    plt = load_pyplot("--out", "plots")
    assert plt is sys.modules["matplotlib.pyplot"]
    assert matplotlib.get_backend().lower() == "agg"


def test_without_matplotlib_the_error_names_option_value_and_extra(no_matplotlib: None) -> None:
    with pytest.raises(InputError) as caught:
        load_pyplot("--plot", Path("out/shape.png"))
    assert str(caught.value) == f"--plot needs matplotlib: {HINT}"
    assert (caught.value.parameter, caught.value.value, caught.value.allowed) == (
        "plot", "out/shape.png", "matplotlib installed")
    assert isinstance(caught.value.__cause__, ImportError)


def test_the_subject_of_the_message_can_be_named(no_matplotlib: None) -> None:
    with pytest.raises(InputError, match=r"^figures need matplotlib: pip install") as caught:
        load_pyplot("matplotlib", None, subject="figures need")
    assert (caught.value.parameter, caught.value.value) == ("matplotlib", None)


WRITERS: dict[str, tuple[Callable[[Path], Any], str, str]] = {
    # name: (call with the output path, message, parameter)
    "plot_solution": (lambda p: plot_solution(None, p), "--plot needs", "plot"),  # type: ignore[arg-type]
    "plot_search": (lambda p: plot_search(None, p), "--out needs", "out"),  # type: ignore[arg-type]
    "write_plots": (lambda p: write_plots(None, p), "--out needs", "out"),  # type: ignore[arg-type]
    "plot_pareto": (lambda p: plot_pareto(None, str(p)), "--plot needs", "plot"),  # type: ignore[arg-type]
    "write_tracking_plots": (lambda p: write_tracking_plots(None, [], None, p),  # type: ignore[arg-type]
                             "--out needs", "out"),
    "write_figures": (write_figures, "figures need", "matplotlib"),
}


@pytest.mark.parametrize("name", sorted(WRITERS))
def test_every_plot_writer_gives_the_typed_error(name: str, tmp_path: Path,
                                                 no_matplotlib: None) -> None:
    call, subject, parameter = WRITERS[name]
    with pytest.raises(InputError) as caught:
        call(tmp_path / "plot.png")
    assert str(caught.value) == f"{subject} matplotlib: {HINT}"
    assert caught.value.parameter == parameter
    assert list(tmp_path.iterdir()) == []


def test_the_cli_exits_2_with_one_line_naming_the_extra(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], no_matplotlib: None) -> None:
    assert main(["solve", "--tension", "5", "--plot", str(tmp_path / "shape.png")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert f"--plot needs matplotlib: {HINT}" in err
    assert not (tmp_path / "shape.png").exists()


def test_only_the_loader_imports_pyplot_or_picks_a_backend() -> None:
    source = Path(tdcm_ros.__file__).parent
    found = []
    for path in sorted(source.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [f"{node.module}.{a.name}" for a in node.names]
                     if isinstance(node, ast.ImportFrom) else [])
            picks_backend = (isinstance(node, ast.Attribute) and node.attr == "use"
                             and isinstance(node.value, ast.Name) and node.value.id == "matplotlib")
            if picks_backend or any(n in ("matplotlib", "matplotlib.pyplot") for n in names):
                found.append(path.relative_to(source).as_posix())
    assert sorted(set(found)) == ["plot_backend.py"]
