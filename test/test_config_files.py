"""Every shipped parameter and scene file is valid against the specs: no unknown names, no value
outside its range (a renamed or re-ranged parameter fails here, not on a robot)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.nodes import (
    device_twin,
    metrics_node,
    mocap_node,
    model_node,
    shape_controller,
    tension_driver,
)
from tdcm_ros.runtime.params import read_param_file
from tdcm_ros.scenes.load import load_scene
from tdcm_ros.scenes.paths import shipped_scenes
from tdcm_ros.spec import Spec

CONFIG = Path(__file__).resolve().parents[1] / "config"
NODES: dict[str, dict[str, Spec]] = {
    "model_node": model_node.PARAMETERS, "metrics_node": metrics_node.PARAMETERS,
    "mocap_node": mocap_node.PARAMETERS, "tension_driver": tension_driver.PARAMETERS,
    "device_twin": device_twin.PARAMETERS, "shape_controller": shape_controller.PARAMETERS}


def check_parameter_file(path: Path) -> int:
    """Check every entry of a ROS parameter file against its node's specs; the number of
    values checked. Raises ``InputError`` naming the first unknown or invalid parameter."""
    checked = 0
    for key, values in read_param_file(path):
        node = key.strip("/").split("/")[-1]
        specs = NODES.get(node)
        if specs is None:
            raise InputError(f"{path.name}: unknown node {node!r}", parameter="node", value=node,
                             allowed=", ".join(NODES))
        for name, value in values.items():
            if name not in specs:
                raise InputError(f"{path.name}: unknown parameter {name!r} of {node}",
                                 parameter=name, value=value, allowed=", ".join(sorted(specs)))
            specs[name].check(value, name)
            checked += 1
    return checked


def node_files() -> list[Path]:
    return sorted(CONFIG.glob("*.yaml"))


def test_config_holds_parameter_files_and_scenes() -> None:
    assert len(node_files()) >= 4 and len(shipped_scenes()) >= 7


@pytest.mark.parametrize("path", node_files(), ids=lambda p: p.name)
def test_shipped_parameter_file_matches_the_specs(path: Path) -> None:
    assert check_parameter_file(path) >= 5


@pytest.mark.parametrize("name", sorted(shipped_scenes()))
def test_shipped_scene_loads_against_the_specs(name: str) -> None:
    assert load_scene(shipped_scenes()[name]).name


def _model_node_file(tmp_path: Path, line: str) -> Path:
    path = tmp_path / "model_node.yaml"
    path.write_text(f"model_node:\n  ros__parameters:\n    {line}\n", encoding="utf-8")
    return path


@pytest.mark.parametrize(("line", "parameter"), [
    ("solver: {tol: 0.5}", "solver.tol"),            # above 0.01 m
    ("solver: {routing: tight}", "solver.routing"),  # not a choice
    ("design: {N: 2.5}", "design.N"),                # not an integer
    ("output: {samples: 1}", "output.samples"),      # below 2
    ("solver: {tolerance: 1.0e-6}", "solver.tolerance"),  # unknown (renamed) parameter
])
def test_a_bad_or_unknown_parameter_fails_the_check(tmp_path: Path, line: str,
                                                    parameter: str) -> None:
    with pytest.raises(InputError) as caught:
        check_parameter_file(_model_node_file(tmp_path, line))
    assert caught.value.parameter == parameter

