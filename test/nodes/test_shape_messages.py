"""shape_messages: the model node's outputs built from a SolveResult (no transport)."""

from __future__ import annotations

import math

import numpy as np

from tdcm_ros.bagio import deserialize
from tdcm_ros.model import preset, solve, surface_points
from tdcm_ros.nodes.shape_messages import midline_messages

TYPES = {"midline": "nav_msgs/msg/Path", "midline_poses": "geometry_msgs/msg/PoseArray",
         "tip_pose": "geometry_msgs/msg/PoseStamped",
         "predicted_markers": "geometry_msgs/msg/PoseArray",
         "body_markers": "visualization_msgs/msg/MarkerArray"}
ARCS = np.array([0.015, 0.033, 0.053])


def build(tension: float, stamp_ns: int, samples: int = 54) -> dict:
    result = solve(preset("paper-experiment"), tension)
    messages = midline_messages(result, stamp_ns=stamp_ns, frame_id="tdcm_base", samples=samples,
                                marker_s=ARCS, marker_radius=result.design.R_outer + 0.001,
                                marker_side_rad=math.pi)
    # CDR bytes, as a subscriber gets them.
    return {"result": result, **{topic: deserialize(data, TYPES[topic])
                                 for topic, data in messages}}


def xyz(poses) -> np.ndarray:
    return np.array([[p.position.x, p.position.y, p.position.z] for p in poses])


def test_midline_first_stamped_and_equal_to_the_solution():
    stamp = 1_700_000_000_123_456_789
    result = solve(preset("paper-experiment"), 12.0)
    topics = [topic for topic, _ in midline_messages(
        result, stamp_ns=stamp, frame_id="f", samples=5, marker_s=ARCS, marker_radius=0.0,
        marker_side_rad=0.0)]
    assert topics == list(TYPES)
    out = build(12.0, stamp, samples=54)
    s = np.linspace(0.0, result.design.length, 54)
    positions, quats = result.pose_at(s)
    path = out["midline"]
    assert (path.header.stamp.sec, path.header.stamp.nanosec) == (1_700_000_000, 123_456_789)
    assert all(p.header.stamp.nanosec == 123_456_789 for p in path.poses)
    assert np.array_equal(xyz([p.pose for p in path.poses]), positions)
    assert np.array_equal(xyz(out["midline_poses"].poses), positions)
    q = out["midline_poses"].poses[-1].orientation
    assert np.array_equal([q.x, q.y, q.z, q.w], quats[-1])
    assert np.array_equal(xyz([out["tip_pose"].pose]), result.tip_position[None, :])
    expected, _ = surface_points(result, ARCS, result.design.R_outer + 0.001, math.pi)
    assert np.array_equal(xyz(out["predicted_markers"].poses), expected)
    body, spheres = out["body_markers"].markers
    assert len(body.points) == 54 and len(spheres.points) == 3
    assert body.scale.x == 2.0 * result.design.R_outer


def test_successive_builds_do_not_share_headers_or_points():
    """A later build must not change an earlier one (no header or points shared)."""
    def raw(tension: float, stamp_ns: int, samples: int) -> dict:
        result = solve(preset("paper-experiment"), tension)
        return {topic: deserialize(data, TYPES[topic]) for topic, data in midline_messages(
            result, stamp_ns=stamp_ns, frame_id=f"f{samples}", samples=samples, marker_s=ARCS,
            marker_radius=0.0, marker_side_rad=0.0)}

    first = raw(4.0, 1_000_000_000, 54)
    tip_x = first["body_markers"].markers[0].points[-1].x
    second = raw(20.0, 2_000_000_000, 10)
    for out, sec, count in ((first, 1, 54), (second, 2, 10)):
        body, spheres = out["body_markers"].markers
        for marker in (body, spheres):
            assert marker.header.stamp.sec == sec and marker.header.frame_id == f"f{count}"
        assert len(body.points) == count
    assert first["body_markers"].markers[0].points[-1].x == tip_x
    assert second["body_markers"].markers[0].points[-1].x > tip_x
