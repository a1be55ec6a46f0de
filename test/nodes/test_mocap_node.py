"""mocap_node in its own process, on the embedded runtime and on rclpy (see conftest.py): CSV
replay, live relabelling, bad configuration and the sim source rolling with the true roll.

The node's logic in detail (sim source, arc-length labelling, every configuration error) is
tested in-process in test/mocap/test_mocap_node_logic.py.
"""

from __future__ import annotations

import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tdcm_ros.bagio import from_dict
from tdcm_ros.mocap import read_nexus_csv
from test.support.waiting import eventually

MOCAP = "tdcm_ros.nodes.mocap_node:MocapNode"
SAMPLE = Path(__file__).resolve().parents[1] / "mocap" / "data" / "nexus_trial.csv"
Spawn = Callable[..., subprocess.Popen[bytes]]


def params_file(tmp_path: Path, node: str, values: dict[str, Any]) -> str:
    path = tmp_path / "mocap.yaml"
    path.write_text(yaml.safe_dump({node: {"ros__parameters": values}}))
    return str(path)


class Probe:
    """Collects mocap_node's outputs (under ``prefix``) and, once joined, the static transform."""

    def __init__(self, ctx: Any, prefix: str = "") -> None:
        from tdcm_ros.runtime.port import QoS

        self.ctx = ctx
        port = ctx.create_port("probe")
        self.port = port
        self.markers: list[Any] = []
        self.poses: list[Any] = []
        self.tf: list[Any] = []
        self.diagnostics: list[Any] = []
        port.create_subscription(f"{prefix}/markers", "mocap4r2_msgs/msg/Markers",
                                 self.markers.append, QoS(depth=1000))
        port.create_subscription(f"{prefix}/markers_poses", "geometry_msgs/msg/PoseArray",
                                 self.poses.append, QoS(depth=1000))
        port.create_subscription("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                                 self.diagnostics.append)

    def join_tf_static(self) -> None:
        """Subscribe to ``/tf_static`` from a new node, after the mocap node has sent it."""
        from tdcm_ros.runtime.port import QoS

        self.ctx.create_port("late_joiner").create_subscription(
            "/tf_static", "tf2_msgs/msg/TFMessage", self.tf.append,
            QoS(depth=1, durability="transient_local"))

    def spin_until(self, predicate: Callable[[], bool], timeout: float, what: str) -> None:
        """:func:`eventually`, spinning the probe's context."""
        eventually(predicate, timeout, what, spin=self.ctx)

    def counter(self, key: str) -> str | None:
        for array in reversed(self.diagnostics):
            for value in array.status[0].values:
                if value.key == key:
                    return str(value.value)
        return None


def xyz(marker: Any) -> list[float]:
    return [marker.translation.x, marker.translation.y, marker.translation.z]


def stamp_ns(message: Any) -> int:
    return message.header.stamp.sec * 10**9 + message.header.stamp.nanosec


def test_csv_replay_publishes_the_csv_positions_in_metres(runtime, context, spawn, tmp_path):
    quaternion = [0.0, 0.0, 0.6, 0.8]
    params = params_file(tmp_path, "mocap_node", {
        "source": "csv", "csv": {"path": str(SAMPLE), "rate_scale": 4.0, "loop": True,
                                 "start_delay_s": 0.5},
        "labelling": {"map": ["TDCM:M1=m1", "TDCM:M2=m2", "TDCM:M3=m3"]},
        "registration": {"translation": [0.25, -0.12, 0.81], "quaternion": quaternion},
        "diagnostics_period_s": 0.2})
    node = spawn("tdcm_ros.runtime.run_node", MOCAP, "--params", params)
    probe = Probe(context)
    # Two passes of 30 frames reach the probe (the first may be partly missed while connecting).
    probe.spin_until(lambda: len({(m.frame_number, stamp_ns(m)) for m in probe.markers}) >= 40,
                     30.0, "replayed Markers")
    traj = read_nexus_csv(SAMPLE)
    seen_gap = False
    for message in probe.markers:
        row = int(np.flatnonzero(traj.frames == message.frame_number)[0])
        expected = {label: traj.positions[row, column] for column, label in enumerate(
            ("m1", "m2", "m3")) if not np.isnan(traj.positions[row, column]).any()}
        assert message.header.frame_id == "mocap"
        assert [m.marker_name for m in message.markers] == list(expected)
        assert [m.marker_index for m in message.markers] == [
            ("m1", "m2", "m3").index(label) for label in expected]
        for marker in message.markers:
            assert xyz(marker) == expected[marker.marker_name].tolist()   # bit-equal, in m
        seen_gap |= len(expected) < 3
    assert seen_gap
    # Markers and poses of one frame are two messages, the poses published second: the frames
    # between the first and the newest PoseArray received must each have theirs (each
    # subscription may miss the first frames while connecting; those are not compared). The
    # check is linear: the stream goes on while it runs (quadratic, it starved the probe's spin
    # on a loaded machine until its queue dropped PoseArrays).
    def paired() -> list:
        stamps = [stamp_ns(p) for p in probe.poses]
        return [m for m in probe.markers if stamps and min(stamps) <= stamp_ns(m) <= max(stamps)]

    def every_frame_paired() -> bool:
        stamps = {stamp_ns(p) for p in probe.poses}
        frames = paired()
        return len(frames) >= 30 and all(stamp_ns(m) in stamps for m in frames)

    probe.spin_until(every_frame_paired, 10.0, "a PoseArray for every Markers frame")
    by_stamp = {stamp_ns(p): p for p in probe.poses}
    for message in paired():
        poses = by_stamp[stamp_ns(message)].poses
        assert [[p.position.x, p.position.y, p.position.z] for p in poses] == [
            xyz(m) for m in message.markers]
    # Replay time: consecutive frames of one pass are 10 ms / rate_scale apart.
    pairs = [(a, b) for a, b in zip(probe.markers, probe.markers[1:], strict=False)
             if b.frame_number == a.frame_number + 1]
    assert pairs and all(stamp_ns(b) - stamp_ns(a) == 2_500_000 for a, b in pairs)

    # /tf_static is transient local: a node joining after it was sent (at start) still gets it.
    probe.join_tf_static()
    probe.spin_until(lambda: bool(probe.tf), 10.0, "/tf_static")
    (transform,) = probe.tf[-1].transforms
    assert transform.header.frame_id == "mocap" and transform.child_frame_id == "tdcm_base"
    t, r = transform.transform.translation, transform.transform.rotation
    assert [t.x, t.y, t.z] == [0.25, -0.12, 0.81] and np.allclose([r.x, r.y, r.z, r.w], quaternion)

    probe.spin_until(lambda: int(probe.counter("markers_unlabelled") or 0) > 0
                     and int(probe.counter("markers_occluded") or 0) > 0, 10.0, "diagnostics")
    assert probe.counter("state") == "replaying" and probe.counter("registration") == "given"
    assert node.poll() is None


def driver_markers(stamp: int, frame: int, entries: list[tuple[str, list[float]]]) -> Any:
    return from_dict("mocap4r2_msgs/msg/Markers", {
        "header": {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9},
                   "frame_id": "vicon_world"},
        "frame_number": frame,
        "markers": [{"id_type": 0, "marker_index": i, "marker_name": name,
                     "translation": {"x": p[0], "y": p[1], "z": p[2]}}
                    for i, (name, p) in enumerate(entries)]})


def test_relabel_republishes_relabelled_markers_from_a_live_driver(runtime, context, spawn,
                                                                  tmp_path):
    params = params_file(tmp_path, "/tdcm/mocap_node", {
        "source": "relabel", "relabel": {"input_scale": 0.001},
        "labelling": {"map": ["Robot:Base=m1", "Mid=m2", "Tip=m3"]},
        "registration": {"mode": "rpy", "rpy": [3.14159, 0.0, 0.0]},
        "diagnostics_period_s": 0.2})
    spawn("tdcm_ros.runtime.run_node", MOCAP, "--namespace", "/tdcm",
          "--params", params)
    probe = Probe(context, prefix="/tdcm")
    driver = probe.port.create_publisher("/markers", "mocap4r2_msgs/msg/Markers")
    entries = [("Robot:Tip", [10.0, 20.0, 53.0]), ("Robot:Stray", [1.0, 2.0, 3.0]),
               ("Robot:Base", [10.0, 20.0, 15.0]), ("Robot:Mid", [0.0, 0.0, 0.0])]
    frames = iter(range(8, 10**6))

    def send() -> None:
        frame = next(frames)
        driver.publish(driver_markers(1_700_000_000_123_456_789 + frame, frame, entries))

    eventually(lambda: probe.markers, 20.0, "relabelled Markers", spin=context, action=send,
               every=0.2)
    message = probe.markers[-1]
    assert message.header.frame_id == "mocap"
    assert stamp_ns(message) == 1_700_000_000_123_456_789 + message.frame_number
    # Mid is occluded (zeros), Stray has no label: m1 then m3, positions mm -> m.
    assert [m.marker_name for m in message.markers] == ["m1", "m3"]
    assert np.allclose([xyz(m) for m in message.markers], [[0.01, 0.02, 0.015],
                                                           [0.01, 0.02, 0.053]], rtol=0,
                       atol=1e-15)
    probe.spin_until(lambda: probe.counter("state") == "relabelling"
                     and int(probe.counter("markers_occluded") or 0) >= 1
                     and int(probe.counter("markers_unlabelled") or 0) >= 1, 10.0, "diagnostics")
    probe.join_tf_static()
    probe.spin_until(lambda: bool(probe.tf), 10.0, "/tf_static")
    rotation = probe.tf[-1].transforms[0].transform.rotation
    assert np.allclose([rotation.x, rotation.y, rotation.z, rotation.w],
                       [np.sin(3.14159 / 2), 0.0, 0.0, np.cos(3.14159 / 2)])


@pytest.mark.parametrize(("values", "phrase"), [
    ({"source": "csv", "csv": {"path": "/nonexistent/trial.csv"}}, "cannot read file"),
    ({"source": "relabel", "relabel": {"input_topic": "markers"}}, "own output"),
])
def test_bad_configuration_exits_with_one_line(runtime, spawn, tmp_path, values, phrase):
    params = params_file(tmp_path, "mocap_node", values)
    node = spawn("tdcm_ros.runtime.run_node", MOCAP, "--params", params)
    eventually(lambda: node.poll() is not None, 20.0, "the node to exit")
    stderr = node.stderr.read().decode()
    assert node.returncode == 2 and phrase in stderr and "Traceback" not in stderr


def test_sim_markers_roll_with_the_true_roll(runtime, context, spawn, tmp_path):
    """Source sim on both runtimes: with sim/joint_states_true at 0.5 rad the markers, mapped
    to tdcm_base through the published registration, are the scene's planar markers at the
    true tension turned by 0.5 rad about tdcm_base z."""
    import math

    from tdcm_ros.mocap.registration import Registration
    from tdcm_ros.model import solve, surface_points
    from tdcm_ros.runtime.port import QoS
    from tdcm_ros.scenes import load_scene

    params = params_file(tmp_path, "mocap_node", {"source": "sim", "sim": {"scene": "ideal"}})
    spawn("tdcm_ros.runtime.run_node", MOCAP, "--params", params)
    probe = Probe(context)
    tension = probe.port.create_publisher("sim/tension_true", "geometry_msgs/msg/WrenchStamped",
                                          QoS(depth=10))
    rolls = probe.port.create_publisher("sim/joint_states_true", "sensor_msgs/msg/JointState",
                                        QoS(depth=10))
    scene = load_scene("ideal")
    arcs = np.asarray(scene.marker_arc_lengths)
    flat, _ = surface_points(solve(scene.true_design, 12.0), arcs, scene.marker_radius,
                             scene.marker_side_rad)
    roll = 0.5
    c, s = math.cos(roll), math.sin(roll)
    expected = flat @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
    probe.join_tf_static()
    probe.spin_until(lambda: bool(probe.tf), 20.0, "the registration on /tf_static")
    t = probe.tf[-1].transforms[0].transform
    registration = Registration((t.translation.x, t.translation.y, t.translation.z),
                                (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w))

    def rolled_seen() -> bool:
        tension.publish(from_dict("geometry_msgs/msg/WrenchStamped",
                                  {"wrench": {"force": {"z": 12.0}}}))
        rolls.publish(from_dict("sensor_msgs/msg/JointState",
                                {"name": ["roll"], "position": [roll]}))
        if not probe.markers or len(probe.markers[-1].markers) != len(arcs):
            return False
        seen = registration.to_base(np.array([xyz(m) for m in probe.markers[-1].markers]))
        return bool(np.max(np.abs(seen - expected)) <= 1e-12)

    probe.spin_until(rolled_seen, 30.0, "markers rolled by 0.5 rad")
    seen = registration.to_base(np.array([xyz(m) for m in probe.markers[-1].markers]))
    flat_seen = np.max(np.abs(seen - flat))
    assert flat_seen > 1e-3, flat_seen          # the roll moved them by millimetres
