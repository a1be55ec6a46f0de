"""The body's URDF: a chain whose forward kinematics, computed here from the URDF's own text
with 4x4 matrices, puts its tip link on the model's tip for the joint values of a solve."""

from __future__ import annotations

import io
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from tdcm_ros.model import InvalidDesignError, named_design, preset, solve
from tdcm_ros.model.urdf import body_urdf, body_xacro, joint_names, joint_positions
from test.support.examples import REPO

WRIST = str(REPO / "config" / "bodies" / "tip_first_wrist.yaml")


def axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation about the unit ``axis`` by ``angle`` (rad)."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def forward(urdf: str, positions: dict[str, float], tip: str) -> np.ndarray:
    """The pose (4x4) of link ``tip`` in the root link, walking the URDF's joints."""
    joints = {j.find("child").get("link"): j for j in ET.fromstring(urdf).iter("joint")}
    chain = []
    link = tip
    while link in joints:
        chain.append(joints[link])
        link = joints[link].find("parent").get("link")
    pose = np.eye(4)
    for joint in reversed(chain):
        origin = joint.find("origin")
        assert origin.get("rpy") == "0 0 0"
        step = np.eye(4)
        step[:3, 3] = [float(v) for v in origin.get("xyz").split()]
        axis = np.array([float(v) for v in joint.find("axis").get("xyz").split()])
        value = positions[joint.get("name")]
        move = np.eye(4)
        if joint.get("type") == "prismatic":
            move[:3, 3] = axis * value
        else:
            move[:3, :3] = axis_rotation(axis, value)
        pose = pose @ step @ move
    return pose


@pytest.mark.parametrize(("design", "tension"), [(preset("paper-experiment"), 20.0),
                                                 (named_design(WRIST), 2.0)])
@pytest.mark.parametrize("roll", [0.0, 0.7])
def test_the_chain_reaches_the_models_tip(design: object, tension: float, roll: float) -> None:
    result = solve(design, tension)
    urdf = body_urdf(design)
    names = joint_names(design)
    positions = dict(zip(names, joint_positions(result, roll), strict=True))
    pose = forward(urdf, positions, "tdcm_body_tip")
    turn = axis_rotation(np.array([0.0, 0.0, 1.0]), roll)
    assert pose[:3, 3] == pytest.approx(turn @ result.tip_position, abs=1e-9)  # far under 10 um
    tangent = turn @ np.array([math.sin(result.tip_angle_rad), 0.0, math.cos(result.tip_angle_rad)])
    assert pose[:3, 2] == pytest.approx(tangent, abs=1e-12)


def test_every_joint_and_link_is_named_once_and_notches_are_waists() -> None:
    design = named_design(WRIST)
    root = ET.fromstring(body_urdf(design, prefix="robot1/"))
    links = [link.get("name") for link in root.iter("link")]
    joints = [joint.get("name") for joint in root.iter("joint")]
    assert len(set(links)) == len(links) and len(set(joints)) == len(joints)
    assert joints == joint_names(design, prefix="robot1/")
    assert links[0] == "robot1/tdcm_base" and all(n.startswith("robot1/") for n in links)
    boxes = [box.get("size") for box in root.iter("box")]
    assert len(boxes) == design.N  # one backbone box per notch
    assert float(boxes[-1].split()[0]) == pytest.approx(design.per_notch("w_d")[-1])
    assert len(list(root.iter("cylinder"))) == len(design.segment_ends()) - design.N


def test_a_bad_name_is_refused() -> None:
    with pytest.raises(InvalidDesignError, match="name"):
        body_urdf(preset("paper-experiment"), name="my body")


# -- a larger robot includes the body: real xacro expands it, yourdfpy walks it ----------------

ARM = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{body}"/>
  <link name="world"/><link name="upper"/><link name="fore"/><link name="tool0"/>
  <joint name="shoulder" type="revolute">
    <parent link="world"/><child link="upper"/><origin xyz="0 0 0.1" rpy="0 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/><origin xyz="0 0 0.3" rpy="0 0.2 0"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="flange" type="fixed">
    <parent link="fore"/><child link="tool0"/><origin xyz="0.05 0 0.25" rpy="0.1 -0.3 0.5"/>
  </joint>
  <xacro:tdcm_body parent="tool0" xyz="0 0 0.01" rpy="0 0 {quarter}"/>
  <xacro:tdcm_body parent="upper" prefix="left_"/>
</robot>
"""


def rpy_pose(xyz: list[float], rpy: list[float]) -> np.ndarray:
    """URDF's origin: rotations about the fixed x, y, z axes (roll, pitch, yaw), then ``xyz``."""
    pose = np.eye(4)
    pose[:3, :3] = (axis_rotation(np.array([0.0, 0.0, 1.0]), rpy[2])
                    @ axis_rotation(np.array([0.0, 1.0, 0.0]), rpy[1])
                    @ axis_rotation(np.array([1.0, 0.0, 0.0]), rpy[0]))
    pose[:3, 3] = xyz
    return pose


@pytest.mark.parametrize(("design", "tension"), [(preset("paper-experiment"), 20.0),
                                                 (named_design(WRIST), 2.0)])
def test_a_larger_robot_includes_the_body_under_its_tool_link(
        tmp_path: Path, design: object, tension: float) -> None:
    import xacro  # the test extra's: the real xacro, and a URDF library of its own
    import yourdfpy
    (tmp_path / "body.urdf.xacro").write_text(body_xacro(design))
    (tmp_path / "arm.urdf.xacro").write_text(ARM.format(body=tmp_path / "body.urdf.xacro",
                                                        quarter=math.pi / 2))
    expanded = xacro.process_file(str(tmp_path / "arm.urdf.xacro")).toxml()
    robot = yourdfpy.URDF.load(io.StringIO(expanded), load_meshes=False,
                               build_collision_scene_graph=False)
    assert robot.validate()
    result = solve(design, tension)
    shoulder, elbow, roll = 0.4, -0.6, 0.3
    body = dict(zip(joint_names(design), joint_positions(result, roll), strict=True))
    left = dict(zip(joint_names(design, prefix="left_"), joint_positions(result), strict=True))
    robot.update_cfg({"shoulder": shoulder, "elbow": elbow, **body, **left})

    tool = (rpy_pose([0, 0, 0.1], [0, 0, shoulder]) @ rpy_pose([0, 0, 0.3], [0, 0.2 + elbow, 0])
            @ rpy_pose([0.05, 0, 0.25], [0.1, -0.3, 0.5]))
    tip = np.eye(4)
    tip[:3, :3] = axis_rotation(np.array([0.0, 1.0, 0.0]), result.tip_angle_rad)
    tip[:3, 3] = result.tip_position
    expected = (tool @ rpy_pose([0, 0, 0.01], [0, 0, math.pi / 2])
                @ rpy_pose([0, 0, 0], [0, 0, roll]) @ tip)
    found = robot.get_transform("tdcm_body_tip", "world")
    assert found[:3, 3] == pytest.approx(expected[:3, 3], abs=1e-8)  # 10 nm: far under 10 um
    assert found[:3, :3] == pytest.approx(expected[:3, :3], abs=1e-9)
    upper = rpy_pose([0, 0, 0.1], [0, 0, shoulder])
    assert robot.get_transform("left_tdcm_body_tip", "world")[:3, 3] == pytest.approx(
        (upper @ tip)[:3, 3], abs=1e-8)
