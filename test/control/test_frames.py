"""The TF buffer: chains of transforms resolved between any two connected frames."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tdcm_ros.bagio import from_dict
from tdcm_ros.control import TargetRefusedError, TransformBuffer


def _tf(parent: str, child: str, xyz: tuple[float, ...], quat: tuple[float, ...]) -> dict:
    return {"header": {"frame_id": parent}, "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", xyz, strict=True)),
                          "rotation": dict(zip("xyzw", quat, strict=True))}}


def test_a_point_goes_through_a_chain_up_and_down_the_tree() -> None:
    turn = Rotation.from_euler("z", 90, degrees=True)
    buffer = TransformBuffer()
    problems = buffer.add_message(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [
        _tf("/world", "mocap", (1.0, 0.0, 0.0), tuple(turn.as_quat())),
        _tf("mocap", "tdcm_base", (0.0, 2.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
        _tf("world", "camera", (0.0, 0.0, 3.0), (0.0, 0.0, 0.0, 1.0))]}))
    assert problems == []
    # camera origin in world (0, 0, 3); in mocap: R^T (p - t) = (0, 1, 3); in base: (0, -1, 3)
    to_base = buffer.lookup("tdcm_base", "camera")
    assert to_base.to_base(np.zeros(3)) == pytest.approx((0.0, -1.0, 3.0))
    assert buffer.lookup("camera", "camera").to_base([1.0, 2.0, 3.0]) == pytest.approx(
        (1.0, 2.0, 3.0))


def test_an_unknown_frame_is_refused_naming_the_known_ones() -> None:
    buffer = TransformBuffer()
    buffer.add("mocap", "tdcm_base", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    with pytest.raises(TargetRefusedError, match=r"'nowhere' has no transform to 'tdcm_base'; "
                       r"known frames: mocap, tdcm_base"):
        buffer.lookup("tdcm_base", "nowhere")


def test_a_bad_transform_is_skipped_with_a_reason() -> None:
    buffer = TransformBuffer()
    problems = buffer.add_message(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [
        _tf("mocap", "tdcm_base", (math.nan, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))]}))
    assert len(problems) == 1 and "translation" in problems[0]
    assert buffer.frames() == set()
