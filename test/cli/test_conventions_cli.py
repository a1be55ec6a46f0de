"""One spelling per concept on the command line, checked through ``python -m tdcm_ros``:

- preset and scene names take ``-`` and ``_`` alike (``paper-experiment`` = ``paper_experiment``);
- a design is named the same way in solve, evaluate and calibrate (``--design NAME`` or
  ``--set design.preset=NAME``);
- a command writing several files takes ``--out DIR`` (``evaluate --plots`` still works, warns);
- every command's help has a description and examples.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import tdcm_ros
from tdcm_ros.cli.main import COMMANDS
from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.metrics.synthetic_bag import write_recording
from tdcm_ros.model import preset
from test.support.cli import tdcm

ROOT = Path(tdcm_ros.__file__).resolve().parents[1]


def solve_json(*args: str) -> dict[str, object]:
    done = tdcm("solve", "--tension", "12", "--json", *args)
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    data.pop("solve_time_s")
    return data


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    rec = simulate(preset("paper-experiment"), levels=(0.0, 8.0), hold_s=2.0, trials=1,
                   tension_hz=200.0, mocap_hz=40.0)
    return write_recording(rec, tmp_path_factory.mktemp("conventions") / "bag")


def test_preset_names_take_hyphen_or_underscore() -> None:
    assert solve_json("--design", "paper_experiment") == solve_json("--design",
                                                                    "paper-experiment")
    assert solve_json("--design", "fig2_wn_1.9") == solve_json("--design", "fig2-wn-1.9")


def test_scene_names_take_hyphen_or_underscore() -> None:
    done = tdcm("scene", "validate", "paper-experiment", "friction-hysteresis")
    assert done.returncode == 0, done.stderr
    assert "paper-experiment: ok" in done.stdout and "friction-hysteresis: ok" in done.stdout


def test_solve_takes_the_design_as_evaluate_does() -> None:
    named = solve_json("--design", "fig3-wd-2", "--set", "E=1.2e9")
    assert solve_json("--set", "design.preset=fig3-wd-2", "--set", "design.E=1.2e9") == named
    assert named != solve_json("--set", "E=1.2e9")


def test_evaluate_takes_the_design_as_solve_does(bag: Path) -> None:
    def table(*args: str) -> dict[str, object]:
        done = tdcm("evaluate", str(bag), "--json", *args)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)

    named = table("--design", "fig3-wd-2", "--set", "E=1.2e9")
    assert table("--set", "design.preset=fig3-wd-2", "--set", "E=1.2e9") == named
    assert named["details"]["design"]["w_d"] == pytest.approx(0.002)


@pytest.mark.parametrize("command", ["solve", "evaluate"])
def test_naming_the_design_twice_is_one_line_error(command: str, bag: Path) -> None:
    args = ["--tension", "5"] if command == "solve" else [str(bag)]
    done = tdcm(command, *args, "--design", "fig3-wd-2", "--set", "design.preset=fig2-wn-1")
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1
    assert "--design 'fig3-wd-2'" in done.stderr and "both name the design" in done.stderr


def test_evaluate_out_writes_the_plots_and_plots_is_a_deprecated_alias(bag: Path,
                                                                        tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    done = tdcm("evaluate", str(bag), "--out", str(tmp_path / "new"))
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in (tmp_path / "new").iterdir()) == ["error_vs_tension.png",
                                                                    "shapes.png"]
    assert "deprecated" not in done.stderr
    old = tdcm("evaluate", str(bag), "--plots", str(tmp_path / "old"))
    assert old.returncode == 0, old.stderr
    assert (tmp_path / "old" / "shapes.png").is_file()
    assert old.stderr.strip() == "tdcm: warning: --plots is deprecated; use --out (same meaning)"


def test_figures_writes_into_a_default_out_folder(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    done = tdcm("figures", "--points", "3", "--dpi", "30", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in (tmp_path / "tdcm_figures").iterdir()) == [
        "feasibility.png", "fig2.png", "fig3.png"]


def test_top_level_help_has_a_quick_start_and_the_conventions() -> None:
    done = tdcm("-h")
    assert done.returncode == 0
    assert "quick start:\n  tdcm demo" in done.stdout
    assert "--out DIR" in done.stdout and "-q/--quiet" in done.stdout


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_has_a_description_and_examples(command: str) -> None:
    done = tdcm(command, "-h")
    assert done.returncode == 0, done.stderr
    usage, _, rest = done.stdout.partition("\n\n")
    description = rest.split("\n\n")[0]
    assert usage.startswith(f"usage: tdcm {command}")
    assert not description.startswith(("positional arguments:", "options:")), done.stdout
    examples = done.stdout.split("examples:\n", 1)
    assert len(examples) == 2, f"tdcm {command} -h has no examples"
    assert examples[1].lstrip().startswith(f"tdcm {command}")
