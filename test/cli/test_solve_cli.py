"""The ``tdcm solve`` contract: exit codes, JSON keys, overrides and the plot."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tdcm_ros.cli.main import main
from tdcm_ros.model import SolverSettings, preset, solve

KEYS = {"converged", "iterations", "tension_n", "tip_position_m", "tip_angle_rad",
        "tip_deflection_m", "tip_displacement_m", "solve_time_s", "design", "tendon_lengths_m",
        "tendon_strokes_m"}


def run_json(capsys, *args):
    status = main(["solve", *args, "--json"])
    out = capsys.readouterr()
    return status, json.loads(out.out), out.err


def test_json_contract_matches_library(capsys):
    status, data, _ = run_json(capsys, "--design", "paper-experiment", "--tension", "20")
    assert status == 0 and KEYS <= set(data)
    expected = solve(preset("paper-experiment"), 20.0)
    assert data["tip_position_m"] == pytest.approx(expected.tip_position.tolist(), abs=1e-15)
    assert data["tip_deflection_m"] == pytest.approx(expected.tip_deflection_m)
    assert data["design"]["E"] == 1.85e9 and data["design"]["L"] == pytest.approx(0.053)
    assert data["tendon_strokes_m"] == expected.tendon_strokes_m.tolist()


def test_a_stroke_solves_for_the_tension_that_pulls_the_tendon_in_that_far(capsys):
    status, data, _ = run_json(capsys, "--stroke", "0.0005", "--routing", "free")
    assert status == 0 and data["settings"]["routing"] == "free"
    assert data["tendon_strokes_m"] == pytest.approx([0.0005], abs=1e-9)
    again = solve(preset("paper-experiment"), data["tension_n"],
                  settings=SolverSettings(routing="free"))
    assert again.tendon_strokes_m == pytest.approx([0.0005], abs=1e-9)
    with pytest.raises(SystemExit) as exited:                              # one or the other
        main(["solve", "--stroke", "0.0005", "--tension", "3"])
    assert exited.value.code == 2 and "not allowed with" in capsys.readouterr().err


def test_overrides_profile_and_routing(capsys):
    _, base, _ = run_json(capsys, "--tension", "10")
    _, soft, _ = run_json(capsys, "--tension", "10", "--set", "E=1.2e9", "--set", "w_d=0.0014")
    _, rect, _ = run_json(capsys, "--tension", "10", "--profile", "rectangular")
    _, free, _ = run_json(capsys, "--tension", "10", "--routing", "free")
    assert soft["design"]["E"] == 1.2e9 and soft["tip_deflection_m"] > base["tip_deflection_m"]
    assert rect["design"]["profile"] == "rectangular"
    assert rect["tip_deflection_m"] > base["tip_deflection_m"]
    assert free["tip_deflection_m"] != base["tip_deflection_m"]


PAIR = str(Path(__file__).resolve().parents[2] / "config" / "bodies" / "antagonistic_pair.yaml")


def test_a_body_with_several_tendons_takes_one_tension_each(capsys):
    """``--tension 25,5``: one per tendon, in the body file's order; each tendon's tension,
    length and stroke by its name."""
    status, data, _ = run_json(capsys, "--design", PAIR, "--tension", "25,5")
    assert status == 0
    assert data["tendon_names"] == ["flexor", "extensor"]
    assert data["tendon_tensions_n"] == [25.0, 5.0] and data["tension_n"] == 25.0
    one = solve(preset("paper-experiment"), 20.0)
    assert data["tip_position_m"] == pytest.approx(one.tip_position.tolist(), abs=2e-8)
    assert data["tendon_strokes_m"][0] == pytest.approx(-data["tendon_strokes_m"][1], rel=1e-5)
    assert main(["solve", "--design", PAIR, "--tension", "25,5"]) == 0
    text = capsys.readouterr().out
    assert "tension 25, 5 N" in text and "flexor: 25 N, length" in text
    assert "extensor: 5 N, length" in text


def test_tdcm_inverse_seeks_the_named_tendon_with_the_others_held(capsys):
    status = main(["inverse", "--design", PAIR, "--tip-angle", "0.2", "--tendon", "flexor",
                   "--tensions", "0,5", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert status == 0 and data["tendon"] == "flexor" and data["tensions_n"][1] == 5.0
    assert data["tip_angle_rad"] == pytest.approx(0.2, abs=1e-9)
    assert main(["inverse", "--design", PAIR, "--tip-angle", "0.2", "--tendon", "biceps"]) == 2
    assert "tendon = 'biceps' is not one of this design's tendons" in capsys.readouterr().err


def test_a_stroke_seeks_the_named_tendon_with_the_others_held(capsys):
    status, data, _ = run_json(capsys, "--design", PAIR, "--stroke", "0.0004", "--tendon",
                               "extensor", "--tensions", "12,0")
    assert status == 0 and data["tendon_tensions_n"][0] == 12.0
    assert data["actuator_strokes_m"][1] == pytest.approx(4e-4, abs=1e-9)
    assert data["tip_angle_rad"] < 0.0  # the extensor wins
    code = main(["solve", "--design", PAIR, "--tension", "20,5", "--tendon", "flexor"])
    assert code == 2 and "--tendon and --tensions go with --stroke" in capsys.readouterr().err


def test_axial_compression_is_a_switch_that_shortens_the_body(capsys):
    _, rigid, _ = run_json(capsys, "--tension", "20")
    _, soft, _ = run_json(capsys, "--tension", "20", "--axial", "compressible")
    assert rigid["settings"]["axial"] == "rigid" and soft["settings"]["axial"] == "compressible"
    expected = solve(preset("paper-experiment"), 20.0,
                     settings=SolverSettings(axial="compressible"))
    assert soft["tip_position_m"] == pytest.approx(expected.tip_position.tolist(), abs=1e-15)
    assert rigid["tip_position_m"][2] - soft["tip_position_m"][2] > 2e-5
    assert main(["solve", "--tension", "20", "--axial", "compressible"]) == 0
    assert "axial compressible" in capsys.readouterr().out


@pytest.mark.parametrize(("args", "status", "kind"), [
    (["--design", PAIR, "--tension", "20"], 2, "tension_out_of_range"),
    (["--design", PAIR, "--tension", "20,x"], 2, "tension_out_of_range"),
    (["--design", PAIR, "--tension", "20,-1"], 2, "tension_out_of_range"),
    (["--design", PAIR, "--stroke", "0.0005"], 2, "invalid_target"),
    (["--tension", "20,5"], 2, "tension_out_of_range"),
    (["--tension", "-1"], 2, "tension_out_of_range"),
    (["--tension", "nan"], 2, "tension_out_of_range"),
    (["--tension", "inf"], 2, "tension_out_of_range"),
    (["--tension", "20", "--set", "w_n=-1"], 2, "invalid_design"),
    (["--tension", "20", "--set", "bogus=1"], 2, "invalid_design"),
    (["--tension", "20", "--set", "novalue"], 2, "input"),
    (["--tension", "5000"], 3, "tendon_singularity"),
    (["--tension", "200", "--profile", "rectangular"], 3, "notch_closure"),
    (["--stroke", "-0.001"], 2, "invalid_target"),
    (["--stroke", "abc"], 2, "invalid_target"),
    (["--stroke", "0.01"], 3, "unreachable_target"),
])
def test_errors_exit_codes_and_json(capsys, args, status, kind):
    code = main(["solve", *args, "--json"])
    out = capsys.readouterr()
    assert code == status
    assert json.loads(out.out)["error"]["kind"] == kind
    assert len(out.err.strip().splitlines()) == 1 and out.err.startswith("tdcm solve:")


def test_console_script_and_plot(tmp_path):
    png = tmp_path / "shape.png"
    proc = subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "solve", "--tension", "20",
                           "--plot", str(png)], capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    assert "tip" in proc.stdout and png.stat().st_size > 10_000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


ISSUE_13 = ["--tension", "20", "--loads", "literal", "--profile", "rectangular",
            *[arg for pair in ("w_base=0", "w_tip=0.00554", "w_n=0.0088", "w_t=0", "w_d=1e-9",
                               "N=33", "R_outer=0.5", "r_inner=0.0005", "R_c=0.0005", "E=1000")
              for arg in ("--set", pair)]]


def test_issue_13_fuzz_case_exits_with_one_line_and_no_lapack_noise():
    """It ended in a LinAlgError traceback, exit 1, with LAPACK's DLASCL complaint and NumPy
    overflow warnings on stderr."""
    proc = subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "solve", *ISSUE_13],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode in (2, 3), proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tdcm solve:"), proc.stderr
    assert "DLASCL" not in proc.stderr and "Warning" not in proc.stderr


@pytest.mark.parametrize(("args", "kind"), [
    (["--tension", "20", "--set", "R_c=0.004"], "invalid_design"),
    (["--tension", "20", "--set", "w_d=0.008"], "invalid_design"),
    (["--tension", "20", "--set", "w_t=1e-30"], "invalid_design"),
])
def test_cross_field_limits_exit_2(capsys, args, kind):
    code = main(["solve", *args, "--json"])
    out = capsys.readouterr()
    assert code == 2 and json.loads(out.out)["error"]["kind"] == kind
    assert len(out.err.strip().splitlines()) == 1


def test_set_l_derives_w_t_as_design_does_and_the_design_is_named_modified(capsys):
    """``--set L=0.06`` (refused before as an unknown field) gives the preset with w_t from the
    length, the same design ``tdcm design --free L`` builds; the console names it modified."""
    from tdcm_ros.model import candidate

    _, data, _ = run_json(capsys, "--tension", "10", "--set", "L=0.06")
    expected = candidate(preset("paper-experiment"), {"L": 0.06})
    assert data["design"]["w_t"] == expected.w_t and data["design"]["L"] == pytest.approx(0.06)
    assert main(["solve", "--tension", "10", "--set", "L=0.06", "--set", "E=1.2e9"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("design paper-experiment modified (E, L): L = 60.000 mm, E = 1.2e+09")
    assert main(["solve", "--tension", "10"]) == 0
    assert capsys.readouterr().out.startswith("design paper-experiment: L = 53.000 mm")


@pytest.mark.parametrize("value", ["-0.01", "0", "nan", "inf", "short"])
def test_a_length_that_is_not_positive_is_refused(capsys, value):
    assert main(["solve", "--tension", "10", "--set", f"L={value}"]) == 2
    assert "--set L = " in capsys.readouterr().err
