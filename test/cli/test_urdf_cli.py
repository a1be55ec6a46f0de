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
