"""model_node's TF: the static tendon frame on /tf_static (transient local) and the tip (and
stations) on /tf, received by a peer on both runtimes; and every frame a node stamps is in one
TF tree (RViz shows everything with no "no transform" warning)."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.metrics.bagdata import BASE_FRAME
from tdcm_ros.model import preset, solve
from tdcm_ros.nodes import device_twin, mocap_node, tension_driver
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.nodes.tf_messages import station_lengths
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.port import QoS
from test.support.waiting import eventually

MODEL = "tdcm_ros.nodes.model_node:ModelNode"
Spawn = Callable[..., subprocess.Popen[bytes]]
TF = "tf2_msgs/msg/TFMessage"


def wrench(tension: float, stamp_ns: int, frame_id: str = "tdcm_tendon") -> Any:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9},
                   "frame_id": frame_id},
        "wrench": {"force": {"z": tension}}})


def stamp_of(transform: Any) -> int:
    return transform.header.stamp.sec * 10**9 + transform.header.stamp.nanosec


def xyz(transform: Any) -> np.ndarray:
    t = transform.transform.translation
    return np.array([t.x, t.y, t.z])


def xyzw(transform: Any) -> np.ndarray:
    q = transform.transform.rotation
    return np.array([q.x, q.y, q.z, q.w])



def test_a_peer_receives_the_tendon_frame_and_the_models_tip(runtime, context, spawn,
                                                             tmp_path: Path) -> None:
    params = tmp_path / "model.yaml"
    params.write_text(yaml.safe_dump({"model_node": {"ros__parameters": {"tf": {"stations": 3}}}}))
    spawn("tdcm_ros.runtime.run_node", MODEL, "--params", str(params))
    port = context.create_port("tf_probe")
    dynamic: list[Any] = []
    port.create_subscription("/tf", TF, dynamic.append, QoS(depth=100))
    tension = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped")

    def tip_for(stamp: int) -> list[Any]:
        return [m for m in dynamic if stamp_of(m.transforms[0]) == stamp]

    sent: list[int] = []

    def send() -> None:
        sent.append(time.time_ns())
        tension.publish(wrench(20.0, sent[-1]))

    stamp = eventually(lambda: next((t for t in sent if tip_for(t)), None), 30.0,
                       "/tf for a tension sent", spin=context, action=send, every=0.2)
    (message,) = tip_for(stamp)
    expected = solve(preset("paper-experiment"), 20.0)
    tip, *stations = message.transforms
    assert (tip.header.frame_id, tip.child_frame_id) == ("tdcm_base", "tdcm_tip")
    assert np.allclose(xyz(tip), expected.tip_position, rtol=0, atol=1e-12)
    assert np.allclose(xyzw(tip), expected.tip_quaternion, rtol=0, atol=1e-12)
    assert [s.child_frame_id for s in stations] == [f"tdcm_station_{k}" for k in (1, 2, 3)]
    positions, quaternions = expected.pose_at(station_lengths(expected.design.length, 3))
    assert np.allclose([xyz(s) for s in stations], positions, rtol=0, atol=1e-12)
    assert np.allclose([xyzw(s) for s in stations], quaternions, rtol=0, atol=1e-12)

    # /tf_static went out when the node started: a node joining now still gets it.
    static: list[Any] = []
    context.create_port("late_joiner").create_subscription(
        "/tf_static", TF, static.append, QoS(depth=1, durability="transient_local"))
    eventually(lambda: static, 15.0, "/tf_static from the model node", spin=context)
    (tendon,) = static[-1].transforms
    assert (tendon.header.frame_id, tendon.child_frame_id) == ("tdcm_base", "tdcm_tendon")
    assert np.allclose(xyz(tendon), [preset("paper-experiment").R_c, 0.0, 0.0], atol=1e-15)
    assert np.allclose(xyzw(tendon), [1.0, 0.0, 0.0, 0.0])


def _model_port(**overrides: Any) -> MemoryPort:
    port = MemoryPort(overrides, name="model_node")
    node = ModelNode(port)
    port.deliver("tension", wrench(15.0, port.now_ns()))
    node.process()
    return port


def test_the_tendon_transform_follows_the_frame_and_the_design_at_runtime() -> None:
    port = _model_port()
    port.store.set({"frame_id": "robot_base", "design.R_c": 0.002})
    (tendon,) = port.messages("/tf_static")[-1].transforms
    assert (tendon.header.frame_id, tendon.child_frame_id) == ("robot_base", "tdcm_tendon")
    assert np.allclose(xyz(tendon), [0.002, 0.0, 0.0])
    assert port.publishers["/tf_static"].qos == QoS(depth=1, durability="transient_local")


def _edges(*messages: Any) -> dict[str, str]:
    """child -> parent of every transform in ``messages``."""
    return {t.child_frame_id: t.header.frame_id for m in messages for t in m.transforms}


def _root(frame: str, parents: dict[str, str]) -> str:
    seen = {frame}
    while frame in parents:
        frame = parents[frame]
        assert frame not in seen, f"TF cycle through {frame}"
        seen.add(frame)
    return frame


def test_every_frame_a_node_stamps_is_in_one_tf_tree() -> None:
    model = _model_port()
    mocap = MemoryPort({"source": "sim"}, name="mocap_node")
    mocap_node.MocapNode(mocap)
    mocap.advance(0.05)
    parents = _edges(*model.messages("/tf_static"), *model.messages("/tf"),
                     *mocap.messages("/tf_static"))
    stamped = {BASE_FRAME, str(tension_driver.PARAMETERS["frame_id"].default),
               str(device_twin.PARAMETERS["frame_id"].default)}
    for port in (model, mocap):
        for topic, messages in port.published.items():
            for message in messages:
                header = getattr(message, "header", None)
                # diagnostics and joint states (tendon_states, joint_states) name no frame
                if header is not None and topic not in ("tendon_states", "joint_states") \
                        and not topic.endswith("diagnostics"):
                    stamped.add(header.frame_id)
    assert {"tdcm_base", "tdcm_tendon", "tdcm_tip", "mocap"} <= stamped | set(parents)
    roots = {frame: _root(frame, parents) for frame in stamped | set(parents)}
    assert set(roots.values()) == {"mocap"}, roots


@pytest.mark.parametrize(("overrides", "name"), [
    ({"tf.tip_frame_id": ""}, "tf.tip_frame_id"),
    ({"tf.tendon_frame_id": "/tdcm_tendon"}, "tf.tendon_frame_id"),
    ({"tf.tip_frame_id": "tdcm_tendon"}, "tf.tip_frame_id"),
    ({"tf.stations": -1}, "tf.stations"),
])
def test_bad_frame_parameters_are_typed_errors_naming_the_parameter(overrides, name) -> None:
    with pytest.raises(InputError) as caught:
        ModelNode(MemoryPort(overrides, name="model_node"))
    assert caught.value.parameter == name and name in str(caught.value)


def test_the_tendon_broadcast_can_be_left_to_another_node() -> None:
    port = _model_port(**{"tf.tendon": False})
    assert not port.messages("/tf_static") and port.messages("/tf")
