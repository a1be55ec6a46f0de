"""``tdcm urdf``: the body's URDF on stdout or in a file, names checked."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from test.model.test_urdf import WRIST
from test.support.cli import tdcm


def test_the_urdf_goes_to_stdout_or_a_file(tmp_path: Path) -> None:
    shown = tdcm("urdf")
    assert shown.returncode == 0 and ET.fromstring(shown.stdout.split("\n", 1)[1]).tag == "robot"
    written = tdcm("urdf", "--design", WRIST, "--prefix", "left_", "-o", str(tmp_path / "w.urdf"))
    assert written.returncode == 0, written.stderr
    root = ET.parse(tmp_path / "w.urdf").getroot()
    assert root.get("name") == "left_tdcm_body"
    assert len(list(root.iter("box"))) == 4  # the wrist's four notches


def test_bad_names_exit_2() -> None:
    for argv in (["--prefix", "/x"], ["--name", "two words"]):
        done = tdcm("urdf", *argv)
        assert done.returncode == 2 and argv[0].lstrip("-") in done.stderr


def test_params_gives_the_body_model_node_starts_with(tmp_path: Path) -> None:
    params = tmp_path / "model_node.yaml"
    params.write_text(f"/**/model_node:\n  ros__parameters:\n    design:\n      file: {WRIST}\n"
                      "/robot1/model_node:\n  ros__parameters:\n    design:\n"
                      "      preset: paper-experiment\n      R_outer: 0.004\n")
    wrist = ET.fromstring(tdcm("urdf", "--params", str(params)).stdout.split("\n", 1)[1])
    assert len(list(wrist.iter("box"))) == 4
    robot1 = tdcm("urdf", "--params", str(params), "--node", "/robot1/model_node")
    cylinders = ET.fromstring(robot1.stdout.split("\n", 1)[1]).iter("cylinder")
    assert {c.get("radius") for c in cylinders} == {"0.004"}
    missing = tdcm("urdf", "--params", str(tmp_path / "none.yaml"))
    assert missing.returncode == 2 and "--params" in missing.stderr


def test_xacro_writes_a_macro_that_takes_the_prefix() -> None:
    done = tdcm("urdf", "--xacro", "--name", "wrist")
    root = ET.fromstring(done.stdout.split("\n", 1)[1])
    (macro,) = root
    assert macro.tag.endswith("macro") and macro.get("name") == "wrist"
    assert "parent" in macro.get("params").split()
    refused = tdcm("urdf", "--xacro", "--prefix", "left_")
    assert refused.returncode == 2 and "--prefix" in refused.stderr
