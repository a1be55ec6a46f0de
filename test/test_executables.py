"""Executable names: a pip install puts only ``tdcm``-prefixed names on PATH; a colcon install
(``setup.py install`` with setup.cfg's script dir, as colcon's ament_python build runs it) also
puts the nodes' ROS names into ``lib/tdcm_ros``, where ``ros2 run tdcm_ros <name>`` looks."""

from __future__ import annotations

import configparser
import subprocess
import sys
from pathlib import Path

from test.setup_info import REPO, console_scripts

NODES = ("model_node", "metrics_node", "mocap_node", "tension_driver", "device_twin",
         "shape_controller")


def _entry_points(egg_info: Path) -> dict[str, str]:
    parser = configparser.ConfigParser()
    parser.read(next(egg_info.glob("*.egg-info")) / "entry_points.txt")
    return dict(parser["console_scripts"])


def test_pip_metadata_has_only_prefixed_executables(tmp_path: Path) -> None:
    # pip's setuptools backend runs egg_info (then bdist_wheel) and turns the entry points it
    # writes into scripts on PATH; this is that step.
    subprocess.run([sys.executable, "setup.py", "-q", "egg_info", "--egg-base", str(tmp_path)],
                   cwd=REPO, check=True, capture_output=True)
    scripts = _entry_points(tmp_path)
    assert all(name.startswith("tdcm") for name in scripts), sorted(scripts)
    assert not set(NODES) & set(scripts)
    for node in NODES:
        assert scripts[f"tdcm_{node}"] == f"tdcm_ros.nodes.{node}:main"


def test_colcon_install_has_ros_names_in_lib_tdcm_ros(tmp_path: Path) -> None:
    config = configparser.ConfigParser()
    config.read(REPO / "setup.cfg")
    script_dir = config["install"]["install_scripts"]
    assert script_dir == "$base/lib/tdcm_ros" == config["develop"]["script_dir"]
    prefix = tmp_path / "prefix"
    # The command colcon-core's python build task runs for an ament_python package.
    subprocess.run([sys.executable, "setup.py", "-q", "egg_info", "--egg-base", str(tmp_path),
                    "build", "--build-base", str(tmp_path / "build"), "install",
                    "--record", str(tmp_path / "install.log"), "--prefix", str(prefix),
                    "--install-scripts", script_dir, "--single-version-externally-managed",
                    "install_data"], cwd=REPO, check=True, capture_output=True)
    lib = prefix / "lib" / "tdcm_ros"
    installed = {path.name for path in lib.iterdir()}
    assert set(NODES) | {f"tdcm_{node}" for node in NODES} | {"tdcm"} <= installed
    assert not (prefix / "bin").exists()
    site = next(prefix.glob("lib/python3*/site-packages"))
    done = subprocess.run([str(lib / "model_node"), "--help"], check=False, capture_output=True,
                          text=True,
                          env={"PYTHONPATH": str(site), "PATH": "/usr/bin:/bin"}, timeout=60)
    assert done.returncode == 0 and "--runtime" in done.stdout, done.stderr
    assert done.stdout.startswith("usage: model_node "), done.stdout  # its own name, not tdcm_node
    assert "Run the model_node node." in done.stdout


def test_every_console_script_target_exists() -> None:
    import importlib

    for name, target in console_scripts("install").items():
        module, function = target.split(":")
        assert callable(getattr(importlib.import_module(module), function)), name
