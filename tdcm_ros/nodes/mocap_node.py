"""``mocap_node``: labelled motion-capture markers from a Nexus CSV, a live Vicon driver or a scene.

Publishes ``markers`` (``mocap4r2_msgs/msg/Markers``, the MOCAP4ROS2 Vicon driver's type) and
``markers_poses`` (``geometry_msgs/msg/PoseArray``, same order, identity orientations), both in
``frame_id`` (``mocap``), positions in m; marker_name = label (``m1``...), marker_index = the
label's index. Occluded markers (NaN or exactly zero) and unlabelled ones are left out and
counted. The static transform ``mocap`` -> ``tdcm_base`` (``base_frame_id`` after ``frame_prefix``,
:mod:`tdcm_ros.nodes.frames`; ``frame_id`` is the room's and not prefixed) goes to ``/tf_static``
(``tf2_msgs/msg/TFMessage``, transient local) once at start. ``/diagnostics``
(``mocap_node: <source> source``) carries the counters and the source state; WARN while a source
error or rejected axis message happened within the last 5 periods, or a live source waits.

``source`` (read-only):

- ``csv``: replay ``csv.path`` (Vicon Nexus export, Trajectories section) at ``csv.rate_scale``
  times real time, ``csv.start_delay_s`` after start, optionally looping; stamps = replay time,
  frame_number = the CSV's Frame;
- ``relabel``: subscribe ``relabel.input_topic`` (a live driver's Markers; positions times
  ``relabel.input_scale`` give m), relabel and republish with the input's stamp and frame number;
- ``sim``: a scene's world (``sim.scene``): frames at the scene's mocap rate, each made from the
  true tension (``sim/tension_true``; 0 N until one arrives) and the true roll (joint
  ``sim.roll_joint`` of ``sim/joint_states_true``, ``sensor_msgs/msg/JointState``, rad; 0 until
  one arrives; messages without that joint are ignored, non-finite rolls dropped and counted) at
  the frame's own stamp, interpolated between their stamped samples: a frame waits until the truth
  covers its time (truth sent late, e.g. by a twin not scheduled for a while, still gives every
  frame its true pose), and when no truth sample has arrived for ``TRUTH_STALE_NS`` (2 s), or its
  stamps are on another clock (``TRUTH_OTHER_CLOCK_NS``, 60 s, behind: an unstamped sample), the
  truth counts as held (:mod:`tdcm_ros.mocap.truth`). The markers roll with the body about tdcm_base's z axis.
  Published ``world.delay_s("markers")`` (drawn per frame) after their stamp; the registration
  comes from the scene (``world.mocap_to_base``).
"""

from __future__ import annotations

import math
import sys
from collections import Counter
from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict
from tdcm_ros.device.twin import TRUTH_DEPTH
from tdcm_ros.errors import InputError
from tdcm_ros.mocap import (
    ArcLengthLabeller,
    CsvReplay,
    FrameClock,
    LabelledFrame,
    Labeller,
    NameLabeller,
    NameMap,
    RawFrame,
    Registration,
    SimSource,
    TruthTrack,
    estimate_from_recordings,
    given_registration,
    read_nexus_csv,
    straight_axis,
)
from tdcm_ros.nodes.frames import FRAME_PREFIX_SPECS, declare_frame_prefix, robot_frame
from tdcm_ros.nodes.joint_states import joint_position
from tdcm_ros.nodes.shape_messages import header, stamp_ns_of
from tdcm_ros.runtime import (
    DiagnosticLevel,
    Diagnostics,
    NodeLogic,
    NodePort,
    QoS,
    Status,
    declare_specs,
    grouped,
    overridable_qos,
    resolve_topic,
)
from tdcm_ros.runtime.run_node import main_for
from tdcm_ros.spec import Spec, by_name

SOURCES = ("csv", "relabel", "sim")
LABELLING_MODES = ("name", "arc_length")
AXES = ("straight", "predicted")
REGISTRATION_MODES = ("quaternion", "rpy", "estimate")
MARKERS_TYPE = "mocap4r2_msgs/msg/Markers"
USE_BOTH = 2   # mocap4r2_msgs/Marker.id_type: name and index are both meaningful
#: Every parameter of the node (all fixed at start).
MOCAP_SPECS = by_name(
    Spec("source", description="csv, relabel or sim", default="csv", kind="str", choices=SOURCES),
    Spec("frame_id", description="frame of the markers (Vicon world)", default="mocap",
         kind="str"),
    Spec("base_frame_id", description="child frame of the published registration",
         default="tdcm_base", kind="str"),
    Spec("csv.path", description="Vicon Nexus CSV export (source csv)", default="", kind="str"),
    Spec("csv.rate_scale", description="replay speed, times real time", default=1.0, low=0.01,
         high=100.0),
    Spec("csv.loop", description="replay again from the start", default=False, kind="bool"),
    Spec("csv.start_delay_s", "s", "wait before the first frame, lets subscribers connect", 1.0,
         low=0.0, high=3600.0),
    Spec("relabel.input_topic", description="Markers topic of the live Vicon driver "
         "(source relabel)", default="/markers", kind="str"),
    Spec("relabel.input_scale", description="m per input position unit (0.001 if the driver "
         "sends mm)", default=1.0, low=1e-6, high=1e3),
    Spec("sim.scene", description="scene name or YAML path (sim)", default="ideal", kind="str"),
    Spec("sim.roll_joint", description="joint of sim/joint_states_true the body rolls by (sim)",
         default="roll", kind="str"),
    Spec("labelling.mode", description="name or arc_length", default="name", kind="str",
         choices=LABELLING_MODES),
    Spec("labelling.labels", description="published labels, base to tip",
         default=("m1", "m2", "m3"), kind="names"),
    Spec("labelling.map", description="'Vicon name=label' entries; name: Subject:Marker or "
         "Marker", default=("m1=m1", "m2=m2", "m3=m3"), kind="names"),
    Spec("labelling.arc_lengths", "m", "arc length of each label", (0.015, 0.033, 0.053),
         kind="list", low=0.0, high=2.0),
    Spec("labelling.axis", description="arc_length axis: straight or predicted (latest axis "
         "topic)", default="straight", kind="str", choices=AXES),
    Spec("labelling.axis_topic", description="PoseArray midline in base_frame_id (axis "
         "predicted)", default="midline_poses", kind="str"),
    Spec("labelling.body_length", "m", "length of the straight axis", 0.053, low=1e-3, high=2.0),
    Spec("labelling.max_distance", "m", "largest marker distance from the label's axis point",
         0.03, low=1e-4, high=1.0),
    Spec("registration.mode", description="quaternion, rpy or estimate (ignored by source sim)",
         default="quaternion", kind="str", choices=REGISTRATION_MODES),
    Spec("registration.translation", "m", "tdcm_base origin in mocap", (0.0, 0.0, 0.0),
         kind="vector", low=-1e3, high=1e3),
    Spec("registration.quaternion", description="tdcm_base orientation in mocap (x, y, z, w)",
         default=(0.0, 0.0, 0.0, 1.0), kind="vector", size=4, low=-1.0, high=1.0),
    Spec("registration.rpy", "rad", "roll, pitch, yaw (fixed axes)", (0.0, 0.0, 0.0),
         kind="vector", low=-2 * math.pi, high=2 * math.pi),
    Spec("registration.zero_csv", description="zero-tension Nexus CSV (mode estimate)",
         default="", kind="str"),
    Spec("registration.bent_csv", description="bent-body Nexus CSV fixing the roll (mode "
         "estimate)", default="", kind="str"),
    Spec("registration.x_hint", "", "mocap direction of +x if no bent_csv (mode estimate; "
         "0 = unset)", (0.0, 0.0, 0.0), kind="vector", low=-1e3, high=1e3),
    Spec("markers.radial_offset", "m", "marker centre distance from the midline", 0.00492,
         low=0.0, high=0.1, formerly=("markers.radius",)),
    Spec("markers.side_deg", "deg", "marker side around the body z axis from the tendon side",
         180.0, low=-360.0, high=360.0),
    Spec("diagnostics_period_s", "s", "diagnostics period", 1.0, low=0.05, high=60.0))

#: ns of the node's clock without a simulated truth sample arriving before the truth counts as
#: held (see the module docstring): beyond the 1.8 s seen from a starved twin beside a CPU hog.
TRUTH_STALE_NS = 2_000_000_000
#: ns behind the node's clock past which a truth stamp is on another clock (an unstamped sample
#: reads 1970), not a backlog still to be covered: such truth is held too.
TRUTH_OTHER_CLOCK_NS = 60_000_000_000
#: Every parameter of the node by full name (parameter files are checked against it).
PARAMETERS = {**grouped(MOCAP_SPECS), **grouped(FRAME_PREFIX_SPECS)}


class MocapNode(NodeLogic):
    """Labels, registers and publishes motion-capture markers; see the module docstring."""

    default_name = "mocap_node"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        declare_specs(port, MOCAP_SPECS, read_only=True)
        prefix = declare_frame_prefix(port)
        get = port.get_parameter
        self.source_name = str(get("source"))
        self.frame_id = str(get("frame_id"))
        self.base_frame_id = robot_frame(prefix, str(get("base_frame_id")))
        self.counts: Counter[str] = Counter()
        self.state = "starting"
        self.last_problem = ""
        self.labels = tuple(str(v) for v in get("labelling.labels"))
        self.name_map = NameMap.parse([str(v) for v in get("labelling.map")],
                                      self.labels)
        # Reliable with a deep history: a keep-last writer drops samples a busy subscriber has not
        # acknowledged yet (on DDS too), and metrics_node scores every frame (10 s at 100 Hz).
        qos = QoS(depth=1000)
        self.markers_pub = port.create_publisher("markers", MARKERS_TYPE, qos)
        self.poses_pub = port.create_publisher("markers_poses", "geometry_msgs/msg/PoseArray", qos)
        self.tf_pub = port.create_publisher("/tf_static", "tf2_msgs/msg/TFMessage",
                                            QoS(depth=1, durability="transient_local"))
        start = {"csv": self._start_csv, "relabel": self._start_relabel, "sim": self._start_sim}
        self.registration = start[self.source_name]()
        self.labeller = self._labeller()
        self._publish_tf()
        self.diagnostics = Diagnostics(port, float(get("diagnostics_period_s")))
        self.problems = self.diagnostics.window()
        self.diagnostics.add(f"{self.source_name} source", "tdcm_mocap", self.check_source)

    # -- registration and labelling ---------------------------------------------------------

    def _given_registration(self) -> Registration:
        get = self.port.get_parameter
        mode = str(get("registration.mode"))
        translation = [float(v) for v in get("registration.translation")]
        if mode == "quaternion":
            return given_registration(translation, quaternion=[
                float(v) for v in get("registration.quaternion")])
        if mode == "rpy":
            return given_registration(translation, rpy=[
                float(v) for v in get("registration.rpy")])
        zero_csv = str(get("registration.zero_csv"))
        if not zero_csv:
            raise InputError("registration.mode = 'estimate' needs registration.zero_csv",
                             parameter="registration.zero_csv", value="",
                             allowed="a zero-tension Nexus CSV recording")
        hint = [float(v) for v in get("registration.x_hint")]
        return estimate_from_recordings(
            zero_csv, self.name_map, [float(v) for v in get("labelling.arc_lengths")],
            radius=float(get("markers.radial_offset")),
            side_rad=math.radians(float(get("markers.side_deg"))),
            bent_csv=str(get("registration.bent_csv")) or None,
            x_hint=hint if any(hint) else None)

    def _labeller(self) -> Labeller:
        get = self.port.get_parameter
        if get("labelling.mode") == "name":
            return NameLabeller(self.name_map)
        labeller = ArcLengthLabeller(
            self.labels, [float(v) for v in get("labelling.arc_lengths")],
            self.registration, straight_axis(float(get("labelling.body_length"))),
            float(get("labelling.max_distance")))
        if get("labelling.axis") == "predicted":
            self.port.create_subscription(str(get("labelling.axis_topic")),
                                          "geometry_msgs/msg/PoseArray", self._on_axis,
                                          QoS(depth=1))
        return labeller

    def _on_axis(self, message: Any) -> None:
        if message.header.frame_id != self.base_frame_id or len(message.poses) < 2:
            self.counts["axis_rejected"] += 1
            self.last_problem = (f"axis message in frame {message.header.frame_id!r} with "
                                 f"{len(message.poses)} poses; need {self.base_frame_id!r}, >= 2")
            return
        points = np.array([[p.position.x, p.position.y, p.position.z] for p in message.poses])
        if isinstance(self.labeller, ArcLengthLabeller) and np.all(np.isfinite(points)):
            self.labeller.set_axis(points)
            self.counts["axis_updates"] += 1

    # -- sources ----------------------------------------------------------------------------

    def _start_csv(self) -> Registration:
        get = self.port.get_parameter
        path = str(get("csv.path"))
        if not path:
            raise InputError("source 'csv' (the default) needs csv.path = a Vicon Nexus CSV "
                             "export; for a live Vicon bridge set source = relabel (and "
                             "relabel.input_topic), for the simulated world source = sim",
                             parameter="csv.path", value="", allowed="a Vicon Nexus CSV export")
        trajectories = read_nexus_csv(path)
        if get("labelling.mode") == "name":
            self.name_map.require(trajectories.names, path)
        scale = float(get("csv.rate_scale"))
        start = self.port.now_ns() + round(float(get("csv.start_delay_s")) * 1e9)
        self.replay = CsvReplay(trajectories, rate_scale=scale, loop=bool(get("csv.loop")),
                                start_ns=start)
        self.state = "waiting to start replay"
        period = min(max(1.0 / (trajectories.rate_hz * scale), 1e-3), 0.05)
        self.port.create_timer(period, self._replay_tick)
        return self._given_registration()

    def _replay_tick(self) -> None:
        if self.replay.finished:
            return
        for frame in self.replay.due(self.port.now_ns()):
            self.state = "replaying"
            self._publish(frame)
        if self.replay.finished:
            self.state = f"finished replay of {len(self.replay.trajectories.frames)} frames"

    def _start_relabel(self) -> Registration:
        get = self.port.get_parameter
        topic = str(get("relabel.input_topic"))
        ns, name = self.port.namespace, self.port.node_name
        if resolve_topic(topic, ns, name) == resolve_topic("markers", ns, name):
            raise InputError(
                f"relabel.input_topic = {topic!r} is this node's own output "
                f"{resolve_topic('markers', ns, name)!r}; allowed: another topic, or run the node "
                "in a namespace", parameter="relabel.input_topic", value=topic,
                allowed="a topic other than the output")
        self.input_scale = float(get("relabel.input_scale"))
        self.port.create_subscription(topic, MARKERS_TYPE, self._on_markers,
                                      overridable_qos(self.port, topic, QoS(depth=100)))
        self.state = f"waiting for {resolve_topic(topic, ns, name)}"
        return self._given_registration()

    def _on_markers(self, message: Any) -> None:
        self.counts["frames_received"] += 1
        self.state = "relabelling"
        positions = np.array([[m.translation.x, m.translation.y, m.translation.z]
                              for m in message.markers], dtype=float).reshape(-1, 3)
        names = tuple(str(m.marker_name) for m in message.markers)
        self._publish(RawFrame(stamp_ns_of(message) or self.port.now_ns(),
                               int(message.frame_number), names, positions * self.input_scale))

    def _start_sim(self) -> Registration:
        from tdcm_ros.scenes import load_scene

        scene = load_scene(str(self.port.get_parameter("sim.scene")))
        world = scene.world()
        self.sim = SimSource(world, delay=lambda: world.delay_s("markers"))
        self.true_tension = TruthTrack()
        self.true_roll = TruthTrack()
        self.frame_clock = FrameClock(float(scene.mocap_rate_hz))
        self.roll_joint = str(self.port.get_parameter("sim.roll_joint"))
        self.truth_arrived_ns: int | None = None  # node clock at the last true tension
        self.port.create_subscription("sim/tension_true", "geometry_msgs/msg/WrenchStamped",
                                      self._on_true_tension, QoS(depth=TRUTH_DEPTH))
        self.port.create_subscription("sim/joint_states_true", "sensor_msgs/msg/JointState",
                                      self._on_true_joint_states, QoS(depth=TRUTH_DEPTH))
        self.port.create_timer(1.0 / float(scene.mocap_rate_hz), self._sim_tick)
        self.drain_timer: Any = None
        self.state = f"simulating scene {scene.name!r}; no sim/tension_true yet (0 N)"
        translation, quaternion = world.mocap_to_base
        return Registration(tuple(np.asarray(translation, dtype=float)),
                            tuple(np.asarray(quaternion, dtype=float)), method="scene")

    def _on_true_tension(self, message: Any) -> None:
        tension = float(message.wrench.force.z)
        if not math.isfinite(tension):
            self.counts["dropped_non_finite_tension"] += 1
            return
        if not self.true_tension:
            self.state = "simulating"
        self.true_tension.add(stamp_ns_of(message), tension)
        self.truth_arrived_ns = self.port.now_ns()

    def _on_true_joint_states(self, message: Any) -> None:
        roll = joint_position(message, self.roll_joint)
        if roll is None:
            return
        if not math.isfinite(roll):
            self.counts["dropped_non_finite_roll"] += 1
            return
        self.true_roll.add(stamp_ns_of(message), roll)

    def _sim_tick(self) -> None:
        """Sample every frame time the truth now covers (see the module docstring)."""
        now = self.port.now_ns()
        covered = now
        arrived = self.truth_arrived_ns
        if (self.true_tension and arrived is not None and now - arrived <= TRUTH_STALE_NS
                and now - self.true_tension.newest_ns <= TRUTH_OTHER_CLOCK_NS):
            covered = min(now, self.true_tension.newest_ns)
        for stamp_ns in self.frame_clock.until(covered):
            tension = self.true_tension.at(stamp_ns) if self.true_tension else 0.0
            roll = self.true_roll.at(stamp_ns) if self.true_roll else 0.0
            try:
                self.sim.sample(stamp_ns, tension, roll)
            except InputError as error:
                self.counts["source_errors"] += 1
                self.last_problem = str(error)
        self._sim_drain()
        if self.sim.pending and self.drain_timer is None:  # delayed frames fall due between ticks
            self.drain_timer = self.port.create_timer(0.002, self._sim_drain)

    def _sim_drain(self) -> None:
        for frame in self.sim.due(self.port.now_ns()):
            self._publish(frame)

    # -- output -----------------------------------------------------------------------------

    def _publish(self, raw: RawFrame) -> None:
        frame: LabelledFrame = self.labeller(raw.names, raw.positions)
        self.counts["frames_published"] += 1
        self.counts["markers_published"] += len(frame.labels)
        self.counts["markers_occluded"] += frame.occluded
        self.counts["markers_unlabelled"] += frame.unlabelled
        hdr = header(raw.stamp_ns, self.frame_id)
        points = [{"x": float(p[0]), "y": float(p[1]), "z": float(p[2])} for p in frame.positions]
        self.markers_pub.publish(from_dict(MARKERS_TYPE, {
            "header": hdr, "frame_number": raw.frame_number % 2**32,
            "markers": [{"id_type": USE_BOTH, "marker_index": self.labels.index(label),
                         "marker_name": label, "translation": point}
                        for label, point in zip(frame.labels, points, strict=True)]}))
        self.poses_pub.publish(from_dict("geometry_msgs/msg/PoseArray", {
            "header": hdr, "poses": [{"position": point, "orientation": {"w": 1.0}}
                                     for point in points]}))

    def _publish_tf(self) -> None:
        t, q = self.registration.translation, self.registration.quaternion
        self.tf_pub.publish(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
            "header": header(self.port.now_ns(), self.frame_id),
            "child_frame_id": self.base_frame_id,
            "transform": {"translation": {"x": t[0], "y": t[1], "z": t[2]},
                          "rotation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}}}]}))

    def check_source(self) -> Status:
        """WARN while source errors or rejected axis messages happened within the window, or
        while a live source still waits for input; counters, source state and registration."""
        waiting = self.state.startswith("waiting") or "no sim/tension_true" in self.state
        recent = self.problems.recent(self.counts["source_errors"] + self.counts["axis_rejected"],
                                      self.port.now_ns())
        values = {**dict(sorted(self.counts.items())),
                  "source": self.source_name, "state": self.state,
                  "registration": self.registration.method,
                  "registration_residual_m": f"{self.registration.residual_m:.6g}"}
        warn = recent or (waiting and self.source_name != "csv")
        level = DiagnosticLevel.WARN if warn else DiagnosticLevel.OK
        return Status(level, (self.last_problem if recent else "") or self.state, values)

def main() -> int:
    """``ros2 run tdcm_ros mocap_node`` / ``mocap_node`` console script."""
    return main_for(MocapNode)


if __name__ == "__main__":
    sys.exit(main())
