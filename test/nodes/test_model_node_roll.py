"""model_node with roll (issue 18): every output is ``solve()``'s planar shape turned about the
base +z axis by the joint ``roll`` of ``joint_states`` at the tension's time; in-process on a
MemoryPort, and in its own process on both runtimes."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import offset_points, preset, solve
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.nodes.tf_messages import station_lengths
from tdcm_ros.runtime.memory_port import MemoryPort
from tdcm_ros.runtime.port import QoS
from test.support.waiting import eventually

MODEL = "tdcm_ros.nodes.model_node:ModelNode"
PAPER = preset("paper-experiment")


def stamped(stamp_ns: int) -> dict[str, Any]:
    return {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9}}


def wrench(tension: float, stamp_ns: int) -> Any:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {**stamped(stamp_ns), "frame_id": "tdcm_tendon"},
        "wrench": {"force": {"z": tension}}})


def joint_states(names: list[str], positions: list[float], stamp_ns: int) -> Any:
    return from_dict("sensor_msgs/msg/JointState", {
        "header": stamped(stamp_ns), "name": names, "position": positions})


def rolled(points: np.ndarray, roll: float) -> np.ndarray:
    """Points (k, 3) turned by ``roll`` about +z, written out: (x c - y s, x s + y c, z)."""
    c, s = math.cos(roll), math.sin(roll)
    return np.stack([points[:, 0] * c - points[:, 1] * s, points[:, 0] * s + points[:, 1] * c,
                     points[:, 2]], axis=1)


def turned(quaternions: np.ndarray, roll: float) -> np.ndarray:
    return (Rotation.from_rotvec([0.0, 0.0, roll]) * Rotation.from_quat(quaternions)).as_quat()


def same_rotation(got: np.ndarray, expected: np.ndarray) -> bool:
    """Equal as rotations to 1e-12 (q and -q are one rotation)."""
    return bool(np.all(np.minimum(np.abs(got - expected).max(axis=-1),
                                  np.abs(got + expected).max(axis=-1)) <= 1e-12))


def xyz(points: list[Any]) -> np.ndarray:
    return np.array([[p.x, p.y, p.z] for p in points]).reshape(-1, 3)


def xyzw(quaternions: list[Any]) -> np.ndarray:
    return np.array([[q.x, q.y, q.z, q.w] for q in quaternions]).reshape(-1, 4)


def tip_of(tf_message: Any) -> tuple[np.ndarray, np.ndarray]:
    transform = tf_message.transforms[0].transform
    return xyz([transform.translation])[0], xyzw([transform.rotation])[0]


def test_every_output_is_the_planar_shape_rolled_by_the_joint() -> None:
    port = MemoryPort({"tf.stations": 2}, name="model_node")
    node = ModelNode(port)
    roll = 0.9
    port.deliver("joint_states", joint_states(["other", "roll"], [5.0, roll], port.clock_ns))
    port.deliver("tension", wrench(15.0, port.clock_ns))
    node.process()
    expected = solve(PAPER, 15.0)
    s = np.linspace(0.0, PAPER.length, 54)
    positions, quaternions = expected.pose_at(s)
    (path,) = port.messages("midline")
    assert np.max(np.abs(xyz([p.pose.position for p in path.poses]) - rolled(positions, roll))
                  ) <= 1e-12
    (poses,) = port.messages("midline_poses")
    assert same_rotation(xyzw([p.orientation for p in poses.poses]), turned(quaternions, roll))
    (tip_pose,) = port.messages("tip_pose")
    tip = expected.tip_position[None, :]
    assert np.max(np.abs(xyz([tip_pose.pose.position]) - rolled(tip, roll))) <= 1e-12
    (markers,) = port.messages("predicted_markers")
    arcs = np.array([0.015, 0.033, 0.053])
    at, frames = expected.pose_at(arcs)
    surface = offset_points(at, frames, PAPER.R_outer + 0.001, math.pi)
    assert np.max(np.abs(xyz([p.position for p in markers.poses]) - rolled(surface, roll))
                  ) <= 1e-12
    (body,) = port.messages("body_markers")
    assert np.max(np.abs(xyz(body.markers[0].points) - rolled(positions, roll))) <= 1e-12
    (tf,) = port.messages("/tf")
    tip_xyz, tip_xyzw = tip_of(tf)
    assert np.max(np.abs(tip_xyz - rolled(tip, roll)[0])) <= 1e-12
    assert same_rotation(tip_xyzw[None, :], turned(expected.tip_quaternion[None, :], roll))
    stations, station_frames = expected.pose_at(station_lengths(PAPER.length, 2))
    got = xyz([t.transform.translation for t in tf.transforms[1:]])
    assert np.max(np.abs(got - rolled(stations, roll))) <= 1e-12
    assert same_rotation(xyzw([t.transform.rotation for t in tf.transforms[1:]]),
                         turned(station_frames, roll))


def test_a_tension_takes_the_roll_at_its_stamp_and_bad_rolls_are_counted() -> None:
    port = MemoryPort(name="model_node")
    node = ModelNode(port)
    now = port.clock_ns
    assert node.rolls.at(now) == 0.0                               # none yet
    port.deliver("joint_states", joint_states(["roll"], [0.2], now - 30_000_000))
    port.deliver("joint_states", joint_states(["roll"], [0.3], now - 10_000_000))
    port.deliver("joint_states", joint_states(["roll"], [0.4], now + 10_000_000))
    port.deliver("joint_states", joint_states(["wrist"], [1.0], now - 5_000_000))  # not ours
    port.deliver("joint_states", joint_states(["roll"], [], now - 5_000_000))      # no position
    port.deliver("joint_states", joint_states(["roll"], [math.nan], now - 5_000_000))
    port.deliver("joint_states", joint_states(["roll"], [math.inf], now - 5_000_000))
    port.deliver("joint_states", joint_states(["roll"], [0.9], now - 20_000_000))  # out of order
    assert node.rolls.at(now - 20_000_000) == 0.2
    assert node.rolls.at(now) == 0.3
    assert node.rolls.at(now + 10_000_000) == 0.4
    assert node.rolls.at(now - 40_000_000) == 0.2                  # older than all: the oldest
    port.deliver("tension", wrench(10.0, now))
    node.process()
    expected = rolled(solve(PAPER, 10.0).tip_position[None, :], 0.3)
    assert np.max(np.abs(tip_of(port.messages("/tf")[-1])[0] - expected[0])) <= 1e-12
    node.diagnostics.publish()
    status = port.messages("/diagnostics")[-1].status[0]
    values = {v.key: v.value for v in status.values}
    assert values["dropped_roll_non_finite"] == "2" and status.level == 1
    assert values["dropped_roll_out_of_order"] == "1"
    assert "roll" in status.message


def test_an_unstamped_joint_state_takes_the_node_clock_and_roll_joint_is_a_parameter() -> None:
    port = MemoryPort({"roll.joint": "base_roll"}, name="model_node")
    node = ModelNode(port)
    port.deliver("joint_states", joint_states(["roll"], [1.0], 0))       # another joint
    port.deliver("joint_states", joint_states(["base_roll"], [-0.5], 0))
    assert node.rolls.at(port.clock_ns) == -0.5 and len(node.rolls) == 1
    port.deliver("joint_states", joint_states(["base_roll"], [0.5], port.clock_ns - 1))
    assert node.rolls.at(port.clock_ns) == -0.5    # older than the clock the unstamped one took
    assert node.counts["dropped_roll_out_of_order"] == 1


def test_a_peer_sees_the_rolled_tip_on_tf(runtime, context, spawn) -> None:
    """On both runtimes: the tip on /tf and tip_pose is solve()'s tip turned by the roll that
    was current at the tension's stamp, to 1e-12 m."""
    spawn("tdcm_ros.runtime.run_node", MODEL)
    port = context.create_port("roll_probe")
    frames: list[Any] = []
    tips: list[Any] = []
    port.create_subscription("/tf", "tf2_msgs/msg/TFMessage", frames.append, QoS(depth=100))
    port.create_subscription("tip_pose", "geometry_msgs/msg/PoseStamped", tips.append,
                             QoS(depth=100))
    rolls = port.create_publisher("joint_states", "sensor_msgs/msg/JointState", QoS(depth=100))
    tension = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped",
                                    QoS(depth=100))

    def stamp_of(header: Any) -> int:
        return header.stamp.sec * 10**9 + header.stamp.nanosec

    def tip_for(stamp: int) -> tuple[Any, Any] | None:
        on_tf = [m for m in frames if stamp_of(m.transforms[0].header) == stamp]
        on_topic = [m for m in tips if stamp_of(m.header) == stamp]
        return (on_tf[0], on_topic[0]) if on_tf and on_topic else None

    first = 0.6
    sent: list[int] = []

    def send() -> None:
        sent.append(time.time_ns())
        rolls.publish(joint_states(["roll"], [first], sent[-1] - 1_000_000))
        tension.publish(wrench(20.0, sent[-1]))

    expected = solve(PAPER, 20.0)
    at_first = rolled(expected.tip_position[None, :], first)[0]

    def rolled_tip_seen() -> bool:
        """A tip for a tension sent, turned by the roll sent with it: the tension and the
        joint_states routes are both matched (the first alone leaves the roll history empty,
        and the later roll would then be the oldest kept)."""
        tips_back = [got for t in sent if (got := tip_for(t)) is not None]
        return any(np.max(np.abs(tip_of(on_tf)[0] - at_first)) <= 1e-12 for on_tf, _ in tips_back)

    eventually(rolled_tip_seen, 30.0, "/tf and tip_pose turned by the roll sent (tension and "
               "joint_states matched)", spin=context, action=send, every=0.2)
    context.spin_for(0.3)
    stamp = time.time_ns()
    later = -1.1
    rolls.publish(joint_states(["roll"], [later], stamp + 200_000_000))    # after the tension
    tension.publish(wrench(20.0, stamp))
    eventually(lambda: tip_for(stamp) is not None, 15.0, "the tip at roll 0.6", spin=context)
    for roll, check in ((first, stamp), (later, None)):
        if check is None:
            check = stamp + 300_000_000  # past the later roll's stamp, < max_future_s ahead
            tension.publish(wrench(20.0, check))
            eventually(lambda at=check: tip_for(at) is not None, 15.0,
                       f"the tip at roll {roll}", spin=context)
        got = tip_for(check)
        assert got is not None
        on_tf, on_topic = got
        tip_xyz, tip_xyzw = tip_of(on_tf)
        want = rolled(expected.tip_position[None, :], roll)[0]
        assert np.max(np.abs(tip_xyz - want)) <= 1e-12, (roll, tip_xyz, want)
        assert same_rotation(tip_xyzw[None, :], turned(expected.tip_quaternion[None, :], roll))
        assert np.max(np.abs(xyz([on_topic.pose.position])[0] - want)) <= 1e-12
        assert on_tf.transforms[0].child_frame_id == "tdcm_tip"
