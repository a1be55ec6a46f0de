"""model_node and metrics_node start from a body file named by ``design.file`` (in-process,
MemoryPort): the preset's file gives the preset's midline bit for bit, a ``design.*`` override
still applies, and a bad file stops the start with the key's path."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.model import InvalidDesignError, body_file_text, preset, solve
from tdcm_ros.nodes.metrics_node import declare_design_and_layout
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort


def midline_at(overrides: dict[str, Any], newtons: float) -> np.ndarray:
    """The x, z of the midline model_node publishes for one tension."""
    port = MemoryPort(overrides, name="model_node")
    ModelNode(port)
    port.deliver("tension", from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": port.clock_ns // 10**9, "nanosec": port.clock_ns % 10**9}},
        "wrench": {"force": {"z": newtons}}}))
    port.advance(0.01)
    path = port.messages("midline")[-1]
    return np.array([[p.pose.position.x, p.pose.position.z] for p in path.poses])


def test_model_node_from_the_presets_body_file_is_the_preset(tmp_path: Path) -> None:
    body = tmp_path / "fig3.yaml"
    body.write_text(body_file_text(preset("fig3-wd-1.2")), encoding="utf-8")
    from_file = midline_at({"design.file": str(body)}, 12.0)
    assert np.array_equal(from_file, midline_at({"design.preset": "fig3-wd-1.2"}, 12.0))
    assert not np.array_equal(from_file, midline_at({}, 12.0))  # not the default preset
    stiffer = midline_at({"design.file": str(body), "design.E": 4e9}, 12.0)
    assert abs(stiffer[-1, 0]) < abs(from_file[-1, 0])


def test_a_bad_body_file_stops_the_start_naming_the_key(tmp_path: Path) -> None:
    body = tmp_path / "bad.yaml"
    body.write_text(body_file_text(preset("paper-experiment")).replace("E: 1850000000.0",
                                                                        "E: -1"), "utf-8")
    with pytest.raises(InvalidDesignError, match=r"bad\.yaml: material\.E = -1 is out of range"):
        ModelNode(MemoryPort({"design.file": str(body)}, name="model_node"))
    with pytest.raises(InvalidDesignError, match="cannot read body file"):
        declare_design_and_layout(MemoryPort({"design.file": str(tmp_path / "none.yaml")},
                                             name="metrics_node"))


def test_shape_controller_refuses_a_body_with_a_tendon_list_naming_it() -> None:
    """shape_controller takes one tension: a body with several tendons stops its start;
    metrics_node takes it (a tension per tendon: test_metrics_node_tendons.py)."""
    body = str(Path(__file__).resolve().parents[2] / "config" / "bodies" / "antagonistic_pair.yaml")
    name = "shape_controller"
    with pytest.raises(InvalidDesignError, match=rf"design\.file: {name} \(one tension"):
        declare_design_and_layout(MemoryPort({"design.file": body}, name=name), name)
    design, _, _ = declare_design_and_layout(MemoryPort({"design.file": body}, name="metrics_node"),
                                          tendon_list=True)
    assert [t.name for t in design.tendon_list()] == ["flexor", "extensor"]


def test_metrics_node_takes_the_same_file(tmp_path: Path) -> None:
    body = tmp_path / "fig2.yaml"
    body.write_text(body_file_text(preset("fig2-wn-2.5")), encoding="utf-8")
    design, _, _ = declare_design_and_layout(MemoryPort({"design.file": str(body)},
                                                     name="metrics_node"))
    assert design == preset("fig2-wn-2.5")



def test_the_profile_is_a_parameter_as_the_body_file_gives_it(tmp_path: Path) -> None:
    """``design.profile``: from the start point (a body file's, or circular), and set at start or
    at run time; a scene's rectangular notches reach the nodes (the demo passes it)."""
    design = preset("fig3-wd-1.52").with_overrides(profile="rectangular")
    body = tmp_path / "rect.yaml"
    body.write_text(body_file_text(design), encoding="utf-8")
    from_file = midline_at({"design.file": str(body)}, 12.0)
    by_parameter = midline_at({"design.preset": "fig3-wd-1.52", "design.profile": "rectangular"},
                              12.0)
    assert np.array_equal(from_file, by_parameter)
    assert not np.array_equal(from_file, midline_at({"design.preset": "fig3-wd-1.52"}, 12.0))
    port = MemoryPort({"design.preset": "fig3-wd-1.52"}, name="model_node")
    node = ModelNode(port)
    assert node.config.design.profile.name == "circular"
    assert port.store.set({"design.profile": "rectangular"}).successful
    assert node.config.design.profile.name == "rectangular"
    assert not port.store.set({"design.profile": "oval"}).successful


def test_a_per_notch_body_file_reaches_both_nodes_and_its_lists_are_not_parameters(
        tmp_path: Path) -> None:
    design = preset("paper-experiment").with_overrides(
        w_d=[1.6e-3, 1.5e-3, 1.4e-3, 1.3e-3, 1.2e-3, 1.1e-3, 1.0e-3, 0.9e-3])
    body = tmp_path / "graded.yaml"
    body.write_text(body_file_text(design), encoding="utf-8")
    midline = midline_at({"design.file": str(body)}, 12.0)
    expected = solve(design, 12.0).pose_at(np.linspace(0.0, design.length, midline.shape[0]))[0]
    assert midline[-1] == pytest.approx(expected[-1, [0, 2]], abs=1e-12)   # the tip
    port = MemoryPort({"design.file": str(body)}, name="model_node")
    node = ModelNode(port)
    assert node.config.design == design
    names = set(port.store.specs)
    assert {"design.E", "design.w_n", "design.w_t"} <= names and "design.w_d" not in names
    assert port.store.set({"design.E": 2.0e9}).successful   # a uniform field is still a parameter
    assert node.config.design.w_d == design.w_d and node.config.design.E == 2.0e9
    metrics_design, _, _ = declare_design_and_layout(MemoryPort({"design.file": str(body)},
                                                             name="metrics_node"))
    assert metrics_design == design


@pytest.mark.parametrize("name", ["tee_notches.yaml", "tee_mesh.yaml"])
def test_a_polygon_or_mesh_body_file_reaches_both_nodes_its_sections_not_parameters(
        name: str) -> None:
    """A prismatic notch's section is the file's: its profile, w_d and w_o (derived from the
    section) are not parameters; the others still are."""
    body = Path(__file__).resolve().parents[2] / "config" / "bodies" / name
    port = MemoryPort({"design.file": str(body)}, name="model_node")
    node = ModelNode(port)
    names = set(port.store.specs)
    assert "design.E" in names  # (a mesh's widths differ in their last bits: per notch)
    assert not names & {"design.profile", "design.w_d", "design.w_o"}
    midline = midline_at({"design.file": str(body)}, 5.0)
    expected = solve(node.config.design, 5.0).pose_at(np.linspace(0.0, node.config.design.length,
                                                            midline.shape[0]))[0]
    assert midline[-1] == pytest.approx(expected[-1, [0, 2]], abs=1e-12)
    assert port.store.set({"design.E": 2.0e9}).successful and node.config.design.E == 2.0e9
    metrics_design, _, _ = declare_design_and_layout(MemoryPort({"design.file": str(body)},
                                                             name="metrics_node"))
    assert metrics_design == node.config.design.with_overrides(E=1.85e9)


def test_a_body_with_several_tendons_takes_a_joint_state_of_tensions_by_name() -> None:
    """``input.tension_type: sensor_msgs/msg/JointState``: one effort per tendon by the body
    file's names, in any order; the shape is the library's for those tensions, and
    tendon_states names each tendon. A message without every tendon is dropped and counted."""
    from tdcm_ros.model import read_body_file

    body = Path(__file__).resolve().parents[2] / "config" / "bodies" / "antagonistic_pair.yaml"
    port = MemoryPort({"design.file": str(body),
                       "input.tension_type": "sensor_msgs/msg/JointState"}, name="model_node")
    node = ModelNode(port)

    def send(names: list[str], efforts: list[float]) -> None:
        port.deliver("tension", from_dict("sensor_msgs/msg/JointState", {
            "header": {"stamp": {"sec": port.clock_ns // 10**9,
                                 "nanosec": port.clock_ns % 10**9}},
            "name": names, "effort": efforts}))
        port.advance(0.01)

    send(["extensor", "flexor"], [5.0, 25.0])
    expected = solve(read_body_file(body).design(), [25.0, 5.0])
    tip = port.messages("tip_pose")[-1].pose.position
    assert [tip.x, tip.z] == pytest.approx([expected.tip_position[0], expected.tip_position[2]],
                                           abs=1e-12)
    states = port.messages("tendon_states")[-1]
    assert list(states.name) == ["flexor", "extensor"]
    assert list(states.effort) == [25.0, 5.0]
    assert list(states.position) == pytest.approx(expected.actuator_strokes_m.tolist(), abs=1e-12)
    solved = len(port.messages("tip_pose"))
    send(["flexor"], [25.0])
    assert len(port.messages("tip_pose")) == solved
    assert node.counts["dropped_missing_tendon"] == 1


def test_a_body_with_several_tendons_needs_the_joint_state_input() -> None:
    body = str(Path(__file__).resolve().parents[2] / "config" / "bodies" / "antagonistic_pair.yaml")
    with pytest.raises(InputError, match=r"input\.tension_type = .*JointState") as info:
        ModelNode(MemoryPort({"design.file": body}, name="model_node"))
    assert info.value.parameter == "input.tension_type"
