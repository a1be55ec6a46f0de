"""The ``tdcm inverse`` contract, run as a user runs it (a subprocess): JSON keys, the round trip
to ``tdcm solve``, the human summary and the exit statuses."""

import json

import pytest

from tdcm_ros.model import preset, solve
from test.support.cli import tdcm

KEYS = {"target", "tension_n", "tip_point_m", "tip_angle_rad", "tip_deflection_m", "residual",
        "residual_unit", "sensitivity", "forward_solves", "tension_bounds_n", "tendon_stroke_m"}


def test_json_tension_round_trips_through_tdcm_solve():
    proc = tdcm("inverse", "--design", "fig2-wn-1.9", "--tip-angle", "0.25", "--json")
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert KEYS <= set(data) and data["target"] == {"kind": "tip_angle", "value": 0.25}
    assert data["tip_angle_rad"] == pytest.approx(0.25, abs=1e-9)
    again = tdcm("solve", "--design", "fig2-wn-1.9", "--tension", repr(data["tension_n"]),
                 "--json")
    solved = json.loads(again.stdout)
    tip = solved["tip_position_m"]
    assert [tip[0], tip[2]] == pytest.approx(data["tip_point_m"], abs=1e-9)
    assert solved["tendon_strokes_m"] == pytest.approx([data["tendon_stroke_m"]], abs=1e-12)
    assert data["sensitivity"]["tip_angle_rad_per_n"] > 0.0


def test_tip_point_with_overrides_reports_the_least_squares_residual():
    expected = solve(preset("paper-experiment").with_overrides(E=1.2e9), 12.0).tip_position
    point = f"{float(expected[0]) + 1e-4!r},{float(expected[2])!r}"
    proc = tdcm("inverse", "--tip-point", point, "--set", "E=1.2e9", "--json")
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["residual_unit"] == "m" and 0.0 < data["residual"] < 1e-4
    assert data["tension_n"] == pytest.approx(12.0, abs=0.5)


def test_human_summary_names_tension_tip_and_sensitivity():
    proc = tdcm("inverse", "--tip-deflection", "0.005")
    assert proc.returncode == 0, proc.stderr
    assert "tension 15.24" in proc.stdout and "d(tip)/dT" in proc.stdout
    assert "forward solves" in proc.stdout


def test_human_summary_answers_in_the_units_of_the_target_as_the_json():
    """One unit convention: the target is given in m, and the summary answers in m (the JSON's
    ``tip_point_m``, ``tip_deflection_m``), not mm."""
    human = tdcm("inverse", "--tip-deflection", "0.005").stdout
    data = json.loads(tdcm("inverse", "--tip-deflection", "0.005", "--json").stdout)
    x, z = data["tip_point_m"]
    assert f"achieved tip (x, z) = ({x:.9f}, {z:.9f}) m" in human
    assert f"deflection {data['tip_deflection_m']:.9f} m" in human
    assert data["tip_deflection_m"] == pytest.approx(0.005, abs=1e-9)
    assert " mm" not in human


@pytest.mark.parametrize(("args", "status", "kind"), [
    (["--tip-deflection", "0.05"], 3, "unreachable_target"),
    (["--tip-angle", "-0.2"], 3, "unreachable_target"),
    (["--tip-angle", "4", "--tension-max", "400"], 3, "unreachable_target"),
    (["--tip-deflection", "-0.001"], 2, "invalid_target"),
    (["--tip-deflection", "abc"], 2, "invalid_target"),
    (["--tip-point", "0.01"], 2, "invalid_target"),
    (["--tip-angle", "0.1", "--tension-max", "-1"], 2, "invalid_target"),
    (["--tip-angle", "0.1", "--set", "w_n=-1"], 2, "invalid_design"),
])
def test_errors_exit_with_the_cli_convention(args, status, kind):
    proc = tdcm("inverse", *args, "--json")
    assert proc.returncode == status, proc.stderr
    assert json.loads(proc.stdout)["error"]["kind"] == kind
    assert proc.stderr.startswith("tdcm inverse: ")


def test_unreachable_names_the_range_and_the_limit():
    proc = tdcm("inverse", "--tip-angle", "4", "--tension-max", "400")
    assert proc.returncode == 3
    assert "spans 0 to 3.43" in proc.stderr and "tendon singularity" in proc.stderr


def test_exactly_one_target_is_usage():
    assert tdcm("inverse").returncode == 2
    assert tdcm("inverse", "--tip-angle", "0.1", "--tip-deflection", "0.001").returncode == 2


def test_a_target_that_needs_more_than_the_device_holds_is_said_to() -> None:
    """tip angle 0.3 rad on the paper design needs about 23.7 N: above the device's 22 N, said on
    stderr and in the JSON (it was answered without a word); with --device-max 30 nothing is."""
    proc = tdcm("inverse", "--tip-angle", "0.3", "--json")
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["tension_n"] > 22.0 and data["device_max_n"] == 22.0
    assert data["within_device"] is False
    assert "more than the device holds (22 N, --device-max)" in proc.stderr
    ok = tdcm("inverse", "--tip-angle", "0.3", "--device-max", "30")
    assert ok.returncode == 0 and "WARNING" not in ok.stderr


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf"])
def test_a_device_max_that_is_not_positive_is_refused(value: str) -> None:
    proc = tdcm("inverse", "--tip-angle", "0.1", "--device-max", value)
    assert proc.returncode == 2 and "--device-max" in proc.stderr
