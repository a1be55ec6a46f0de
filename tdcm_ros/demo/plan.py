"""What the demo starts, in which order, with which parameters, all derived from one scene.

A scene with a ``trajectory`` section is a tracking run: the shape controller takes the
tension driver's setpoints, the demo publishes the circle's targets (``plan.targets``) and the
report reads the tracking topics; any other scene runs the driver's staircase schedule."""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from tdcm_ros.demo.tracking_report import REPORTED_TOPICS
from tdcm_ros.demo.trajectory import TipTrajectory, tip_trajectory
from tdcm_ros.device import StepSchedule
from tdcm_ros.errors import InputError
from tdcm_ros.metrics import settings_for_hold
from tdcm_ros.model import body_file_text, parameter_specs
from tdcm_ros.scenes import Scene

#: Nodes in start order: consumers first, so nothing published at the start is missed; the
#: device twin before the driver (the driver opens the twin's pty link).
NODE_ORDER: tuple[str, ...] = ("model_node", "mocap_node", "metrics_node", "device_twin",
                               "tension_driver")
#: Topics the recorder writes: what evaluation needs, plus the live outputs worth replaying.
RECORDED_TOPICS: tuple[str, ...] = (
    "tension", "sim/tension_true", "markers", "/tf_static", "tip_pose", "predicted_markers",
    "midline", "tendon_states", "joint_states", "device_state", "/diagnostics")
#: Topics the evaluation after the run reads.
EVALUATED_TOPICS: tuple[str, ...] = ("tension", "markers", "/tf_static")
#: A tracking run's nodes in start order: the shape controller instead of the metrics node.
TRACKING_NODE_ORDER: tuple[str, ...] = ("model_node", "mocap_node", "shape_controller",
                                        "device_twin", "tension_driver")
#: What a tracking run records: the bench, the targets and everything the controller says.
TRACKING_TOPICS: tuple[str, ...] = (
    "tension", "sim/tension_true", "joint_states", "sim/joint_states_true", "markers",
    "/tf_static", "tension_setpoint", "roll_setpoint", *REPORTED_TOPICS,
    "controller/target_tip", "controller/tracking_error", "tip_pose", "/diagnostics")
#: Topics a tracking run waits for in the bag before the first target: the bench and the
#: controller's measured tip (it is up and sees the markers).
TRACKING_READY_TOPICS: tuple[str, ...] = ("tension", "markers", "/tf_static",
                                          "controller/measured_tip")


@dataclass(frozen=True)
class DemoPlan:
    """One demo run: the scene, its (possibly shortened) schedule and where outputs go."""

    scene: Scene
    scene_ref: str          #: shipped name or YAML path, as the nodes load it
    schedule: StepSchedule
    out: Path
    bag: Path                            #: the rosbag2 folder the recorder writes
    recorded_topics: tuple[str, ...] = RECORDED_TOPICS
    targets: TipTrajectory | None = None  #: a tracking run's targets; None: the schedule

    @property
    def node_order(self) -> tuple[str, ...]:
        """The nodes this run starts, in order."""
        return NODE_ORDER if self.targets is None else TRACKING_NODE_ORDER

    @property
    def ready_topics(self) -> tuple[str, ...]:
        """Topics the bag must hold before the schedule or the first target starts."""
        return EVALUATED_TOPICS if self.targets is None else TRACKING_READY_TOPICS

    @property
    def link(self) -> str:
        """The device twin's pty link, unique per run."""
        return os.path.join(tempfile.gettempdir(), f"tdcm_demo_twin_{os.getpid()}")

    def node_overrides(self) -> dict[str, dict[str, Any]]:
        """Per-node parameters (ROS names), on top of each node's defaults; a per-notch design,
        or one with polygon or given sections, goes to the nodes as a body file written to
        ``out/design.yaml``."""
        scene = self.scene
        specs = parameter_specs(scene.design)
        design: dict[str, Any] = {f"design.{name}": value for name, value
                                  in scene.design.to_dict().items() if name in specs}
        # per-notch values and sections given whole (no profile parameter) are a body file's
        if not scene.design.is_uniform or "profile" not in specs:
            body = self.out / "design.yaml"
            body.parent.mkdir(parents=True, exist_ok=True)
            body.write_text(body_file_text(scene.design), encoding="utf-8")
            design["design.file"] = str(body)
        markers = {"markers.arc_lengths": [float(s) for s in scene.marker_arc_lengths],
                   "markers.side_deg": float(scene.marker_side_deg)}
        top = max(self.schedule.levels)
        steps = settings_for_hold(self.schedule.hold)
        live = {"steps.settle_s": steps.settle_s, "steps.min_hold_s": steps.min_hold_s}
        if scene.marker_radial_offset is not None:
            live["markers.radial_offset"] = scene.marker_radial_offset
        nodes: dict[str, dict[str, Any]] = {
            # The bag's /tf_static carries only the registration the evaluation reads.
            "model_node": {**design, **markers, "markers.ball_radius": scene.marker_ball_radius,
                           "tf.tendon": False},
            "mocap_node": {"source": "sim", "sim.scene": self.scene_ref,
                           "labelling.labels": list(scene.marker_labels),
                           "labelling.arc_lengths": [float(s) for s in scene.marker_arc_lengths]},
            "metrics_node": {**design, **markers, "markers.ball_radius": scene.marker_ball_radius,
                             "markers.labels": list(scene.marker_labels), **live},
            "device_twin": {"scene": self.scene_ref, "link": self.link},
            "tension_driver": {"port": self.link, "tension_max": top,
                               "schedule.levels": [float(v) for v in self.schedule.levels],
                               "schedule.hold_s": float(self.schedule.hold),
                               "schedule.trials": int(self.schedule.trials),
                               "schedule.autostart": False},  # the demo starts it
            "shape_controller": {**design, **markers, "markers.ball_radius": scene.marker_ball_radius,
                                 "markers.labels": list(scene.marker_labels),
                                 "mode": "feedforward", "driver": "tension_driver"},
        }
        return {name: nodes[name] for name in self.node_order}


def make_plan(scene: Scene, scene_ref: str, out: Path, *, trials: int | None = None,
              hold_s: float | None = None, bag: Path | None = None,
              recorded_topics: tuple[str, ...] | None = None) -> DemoPlan:
    """The plan for ``scene``: outputs in ``out`` (the bag in ``bag``, default ``out/bag``), the
    schedule's trials and hold time optionally shortened, ``recorded_topics`` in the bag
    (default :data:`RECORDED_TOPICS`, for a tracking scene :data:`TRACKING_TOPICS`). A tracking
    scene's targets must be reachable by the model within the driver's ``tension_max`` (the
    schedule's top level), else the model's ``UnreachableTargetError``."""
    schedule = scene.schedule
    if trials is not None or hold_s is not None:
        schedule = replace(schedule, trials=schedule.trials if trials is None else trials,
                           hold=schedule.hold if hold_s is None else hold_s)
    if max(schedule.levels) <= 0:
        raise InputError(f"schedule levels {schedule.levels!r} never tension the tendon; "
                         "allowed: at least one level > 0 N", parameter="schedule.levels",
                         value=list(schedule.levels), allowed="a level > 0 N")
    targets = None
    read = EVALUATED_TOPICS
    if scene.trajectory is not None:
        targets = tip_trajectory(scene.trajectory, scene.design, tension_max=max(schedule.levels))
        read = (*REPORTED_TOPICS, *TRACKING_READY_TOPICS)
    if recorded_topics is None:
        recorded_topics = RECORDED_TOPICS if targets is None else TRACKING_TOPICS
    missing = [t for t in read if t not in recorded_topics]
    if missing:
        raise InputError(f"recorded topics {list(recorded_topics)} lack {missing}, which the "
                         f"report reads; allowed: any list including {list(read)}",
                         parameter="--record", value=list(recorded_topics),
                         allowed=f"includes {', '.join(read)}")
    return DemoPlan(scene, scene_ref, schedule, out, bag or out / "bag", recorded_topics, targets)
