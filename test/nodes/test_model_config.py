"""The model node's configuration snapshot: built once per parameter change, swapped whole,
and the only thing the per-input path reads (in-process, MemoryPort)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.model import ModelSpec, ParameterCovariance, SolverSettings, preset
from tdcm_ros.nodes.model_config import ModelConfig
from tdcm_ros.nodes.model_node import TUNABLE_SPECS, ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort

DESIGN = preset("paper-experiment")
UNCERTAINTY = ParameterCovariance(("E",), np.array([DESIGN.E]), np.array([[1.0e14]]), 1.0e-4)


def wrench(newtons: float, stamp_ns: int) -> Any:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9}},
        "wrench": {"force": {"z": newtons}}})


def tunable(**changes: Any) -> dict[str, Any]:
    values = {name: spec.check(spec.default) for name, spec in TUNABLE_SPECS.items()}
    return values | {name.replace("__", "."): value for name, value in changes.items()}


def count_parameter_reads(port: MemoryPort) -> list[str]:
    """Names read through ``port.get_parameter`` from now on."""
    reads: list[str] = []
    read = port.get_parameter

    def counted(name: str) -> Any:
        reads.append(name)
        return read(name)

    port.get_parameter = counted  # type: ignore[method-assign]
    return reads


def test_inputs_read_no_parameter_by_name(tmp_path: Path) -> None:
    """Drawn and undrawn solves, the band, dropped inputs: none reads a parameter."""
    model = tmp_path / "model.yaml"
    model.write_text(ModelSpec(DESIGN, 0.0, UNCERTAINTY).text(), encoding="utf-8")
    port = MemoryPort({"design.file": str(model)}, name="model_node")
    ModelNode(port)
    reads = count_parameter_reads(port)
    for k, newtons in enumerate((5.0, 6.0, -1.0, 1e9, 7.0)):
        port.deliver("tension", wrench(newtons, port.clock_ns))
        port.advance(0.001 if k < 2 else 0.05)
    assert reads == []
    assert len(port.messages("tip_pose")) == 3 and port.messages("shape_band")
    assert len(port.messages("midline")) == 2  # the second is within 1 / 30 s of the first


def test_a_change_swaps_the_whole_configuration_and_the_next_input_uses_it() -> None:
    port = MemoryPort(name="model_node")
    node = ModelNode(port)
    before = node.config
    assert port.store.set({"output.samples": 7, "frame_id": "base_2",
                           "output.visual_rate_hz": 0.0}).successful
    assert node.config is not before and node.config.samples == 7
    port.deliver("tension", wrench(5.0, port.clock_ns))
    (midline,) = port.messages("midline")
    assert len(midline.poses) == 7 and midline.header.frame_id == "base_2"


def test_a_rejected_change_keeps_the_configuration_object() -> None:
    port = MemoryPort(name="model_node")
    node = ModelNode(port)
    before = node.config
    result = port.store.set({"output.samples": 9, "markers.arc_lengths": [0.0, 1.0]})
    assert not result.successful and "markers.arc_lengths" in result.reason
    assert node.config is before and port.get_parameter("output.samples") == 54


def test_the_snapshot_derives_each_field_from_its_parameter() -> None:
    design = DESIGN
    config = ModelConfig.of(design, SolverSettings(), tunable(
        output__visual_rate_hz=30.0, markers__ball_radius=0.004, markers__side_deg=90.0,
        markers__arc_lengths=[0.0, design.length + 5e-10], frame_id="base"), "r1/")
    assert config.frame_id == "r1/base"
    assert config.visual_period_ns == round(1e9 / 30.0)
    assert config.marker_radius_m == design.R_outer + 0.004
    assert config.marker_side_rad == math.pi / 2.0
    assert config.marker_s.tolist() == [0.0, design.length]  # within the tolerance: the tip
    with pytest.raises(ValueError):
        config.marker_s[0] = 1.0  # read-only: the snapshot cannot change under a solve
    assert config.tendon_names == tuple(t.name for t in design.tendon_list())
    every_solve = ModelConfig.of(design, SolverSettings(), tunable(
        output__visual_rate_hz=0.0, markers__placement="midline"), "")
    assert (every_solve.visual_period_ns, every_solve.marker_radius_m) == (0, 0.0)


def test_a_marker_past_the_tip_is_refused_naming_the_parameter() -> None:
    design = DESIGN
    with pytest.raises(InputError) as error:
        ModelConfig.of(design, SolverSettings(), tunable(
            markers__arc_lengths=[design.length + 1e-6]), "")
    assert error.value.parameter == "markers.arc_lengths"
    assert np.isclose(error.value.value[0], design.length + 1e-6)
