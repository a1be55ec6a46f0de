"""model_node with a model file: stick-slip friction (the shape follows the direction of the
tension's change), and the calibration's covariance carried to the tip
(PoseWithCovarianceStamped) and to a band, checked against central differences through the
stateless capstan law; in-process on a MemoryPort (messages round-trip CDR)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import (
    Capstan,
    FrictionTrack,
    Loading,
    ModelSpec,
    ParameterCovariance,
    body_file_text,
    preset,
    solve,
)
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort

DESIGN = preset("paper-experiment").with_overrides(E=7.0e8)
MU = 0.3
UNCERTAINTY = ParameterCovariance(("E", "mu"), np.array([7.0e8, MU]),
                                  np.array([[(7e6) ** 2, -2.0e4], [-2.0e4, 0.03**2]]), 1.2e-4)


@pytest.fixture
def model_file(tmp_path: Path) -> str:
    path = tmp_path / "model.yaml"
    path.write_text(ModelSpec(DESIGN, MU, UNCERTAINTY).text(), encoding="utf-8")
    return str(path)


def node_on(parameters: dict[str, Any]) -> tuple[MemoryPort, ModelNode]:
    port = MemoryPort({"output.visual_rate_hz": 0.0, **parameters}, name="model_node")
    return port, ModelNode(port)


def send(port: MemoryPort, node: ModelNode, tension: float, roll: float | None = None) -> None:
    port.advance(0.01)
    stamp = {"sec": port.clock_ns // 10**9, "nanosec": port.clock_ns % 10**9}
    if roll is not None:
        port.deliver("joint_states", from_dict("sensor_msgs/msg/JointState", {
            "header": {"stamp": stamp}, "name": ["roll"], "position": [roll]}))
    port.deliver("tension", from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": stamp}, "wrench": {"force": {"z": tension}}}))
    node.process()


def tip_of(port: MemoryPort) -> np.ndarray:
    p = port.messages("tip_pose")[-1].pose.position
    return np.array([p.x, p.y, p.z])


def test_friction_from_the_file_makes_the_shape_follow_the_direction(model_file: str) -> None:
    port, node = node_on({"design.file": model_file})
    assert port.get_parameter("friction.mu") == MU
    track = FrictionTrack(MU)
    for tension in (0.0, 20.0, 10.0):
        send(port, node, tension)
        assert np.allclose(tip_of(port), track.solve(DESIGN, tension).tip_position,
                           rtol=0.0, atol=1e-9)
    unloading_10 = tip_of(port)
    send(port, node, 0.0)
    send(port, node, 10.0)  # loading to 10 N: the tendon loses tension toward the tip
    assert tip_of(port)[0] < unloading_10[0] - 3e-4
    # friction off at run time: the paper's solve, history gone
    assert port.store.set({"friction.mu": 0.0}).successful
    send(port, node, 10.0)
    assert np.allclose(tip_of(port), solve(DESIGN, 10.0).tip_position, rtol=0.0, atol=1e-12)


def capstan_tip(e: float, mu: float, tension: float) -> tuple[np.ndarray, float]:
    """The tip (m) and tip angle (rad) loaded from slack: the stateless capstan law."""
    result = solve(DESIGN.with_overrides(E=e), tension,
                   loading=Loading(tension_profile=Capstan(mu)))
    return np.asarray(result.tip_position), result.tip_angle_rad


def expected_tip_covariance(tension: float) -> tuple[np.ndarray, float]:
    """Tip position covariance (prediction: with the residual) and tip angle variance, by
    central differences (steps 1e-4 of E and mu) of the capstan law."""
    columns, angles = [], []
    for index, step in ((0, 7e4), (1, 3e-5)):
        plus, minus = np.array([7.0e8, MU]), np.array([7.0e8, MU])
        plus[index] += step
        minus[index] -= step
        (p, a), (m, b) = capstan_tip(*plus, tension), capstan_tip(*minus, tension)
        columns.append((p - m) / (2 * step))
        angles.append((a - b) / (2 * step))
    jac, jac_angle = np.array(columns).T, np.array(angles)
    cov = jac @ UNCERTAINTY.covariance @ jac.T + UNCERTAINTY.residual_m**2 * np.eye(3)
    return cov, float(jac_angle @ UNCERTAINTY.covariance @ jac_angle)


@pytest.mark.parametrize("roll", [0.0, 0.7])
def test_the_tip_covariance_is_the_fits_carried_through_the_solver(model_file: str,
                                                                    roll: float) -> None:
    port, node = node_on({"design.file": model_file})
    send(port, node, 15.0, roll)  # the first tension: loaded from slack
    message = port.messages("tip_pose_with_covariance")[-1]
    got = np.reshape(message.pose.covariance, (6, 6))
    cov, angle_var = expected_tip_covariance(15.0)
    c, s = math.cos(roll), math.sin(roll)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    assert np.allclose(got[:3, :3], turn @ cov @ turn.T, rtol=2e-3, atol=1e-14)
    axis = turn @ np.array([0.0, 1.0, 0.0])
    assert np.allclose(got[3:, 3:], angle_var * np.outer(axis, axis), rtol=2e-3, atol=1e-14)
    assert np.all(got[:3, 3:] == 0.0)
    pose = message.pose.pose.position
    assert np.allclose([pose.x, pose.y, pose.z], turn @ capstan_tip(7.0e8, MU, 15.0)[0],
                       atol=1e-9)
    assert message.header.frame_id == "tdcm_base"


def test_the_band_is_as_wide_as_the_tips_interval_across_the_plane(model_file: str) -> None:
    port, node = node_on({"design.file": model_file, "output.samples": 20})
    send(port, node, 15.0)
    band = port.messages("shape_band")[-1]
    assert band.type == 11 and band.ns == "tdcm_band" and len(band.points) == 6 * 19
    corners = np.array([[p.x, p.y, p.z] for p in band.points])
    outer_tip, inner_tip = corners[-1], corners[-2]  # the last triangle ends inner, outer
    cov, _ = expected_tip_covariance(15.0)
    angle = solve(DESIGN, 15.0, loading=Loading(tension_profile=Capstan(MU))).tip_angle_rad
    normal = np.array([math.cos(angle), 0.0, -math.sin(angle)])
    half = 1.959963984540054 * math.sqrt(normal @ cov @ normal)
    assert np.linalg.norm(outer_tip - inner_tip) == pytest.approx(2 * half, rel=2e-2)
    assert port.store.set({"band.confidence": 0.5}).successful
    send(port, node, 15.0)
    narrower = np.array([[p.x, p.y, p.z] for p in port.messages("shape_band")[-1].points])
    assert np.linalg.norm(narrower[-1] - narrower[-2]) < 0.4 * np.linalg.norm(
        outer_tip - inner_tip)


def test_the_band_follows_the_visual_rate(model_file: str) -> None:
    port, node = node_on({"design.file": model_file, "output.visual_rate_hz": 30.0})
    for k in range(100):  # 1 s of inputs at 100 Hz
        send(port, node, 5.0 + 0.1 * k)
    assert len(port.messages("tip_pose")) == 100
    assert 25 <= len(port.messages("tip_pose_with_covariance")) <= 35
    assert len(port.messages("shape_band")) == len(port.messages("tip_pose_with_covariance"))


def test_a_body_file_has_no_band_and_no_friction(tmp_path: Path) -> None:
    path = tmp_path / "body.yaml"
    path.write_text(body_file_text(DESIGN), encoding="utf-8")
    port, node = node_on({"design.file": str(path)})
    send(port, node, 15.0)
    assert port.get_parameter("friction.mu") == 0.0
    assert "tip_pose_with_covariance" not in node.publishers
    assert not port.messages("tip_pose_with_covariance") and not port.messages("shape_band")
    assert np.allclose(tip_of(port), solve(DESIGN, 15.0).tip_position, rtol=0.0, atol=1e-12)


def test_metrics_node_takes_the_model_files_friction_and_band(model_file: str) -> None:
    from tdcm_ros.nodes.metrics_node import MetricsNode

    port = MemoryPort({"design.file": model_file}, name="metrics_node")
    node = MetricsNode(port)
    assert port.get_parameter("friction.mu") == MU
    assert node.options.friction_mu == MU
    assert node.options.uncertainty is not None
    assert node.options.uncertainty.names == ("E", "mu")
