"""The body's URDF: a chain whose forward kinematics, computed here from the URDF's own text
with 4x4 matrices, puts its tip link on the model's tip for the joint values of a solve."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from tdcm_ros.model import InvalidDesignError, named_design, preset, solve
from tdcm_ros.model.urdf import body_urdf, joint_names, joint_positions
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
