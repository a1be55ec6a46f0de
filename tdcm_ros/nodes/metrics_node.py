"""``metrics_node``: live Table I metrics of the model against motion capture.

Subscribes ``tension`` (type ``input.tension_type``: geometry_msgs/msg/WrenchStamped,
``wrench.force.z`` in N, for a body with one tendon; or sensor_msgs/msg/JointState, one effort
in N per tendon named as in the body file, as model_node takes it: required for a body with
several tendons, e.g. ``design.file: config/bodies/antagonistic_pair.yaml``; a JointState
without a finite effort for every tendon is dropped and counted), ``markers``
(mocap4r2_msgs/msg/Markers, frame ``mocap_frame_id``, labels ``markers.labels``), ``/tf_static``
(tf2_msgs/msg/TFMessage, transient local) and ``/tf`` (volatile): the TF tree that relates
``mocap_frame_id`` (``mocap``) to ``base_frame_id`` (``tdcm_base``), directly or through other
frames (a base mounted on a robot: ``mocap -> world -> ... -> tool0 -> tdcm_base``), and
``joint_states`` (sensor_msgs/msg/JointState: the roll, joint ``roll.joint``, rad; 0 until one
arrives). The per-frame errors compare at the roll current at the frame's stamp; a finished step
is scored in its bending plane at its mean roll, and left out of Table I when its roll moved
more than ``roll.tolerance_rad`` (see :mod:`tdcm_ros.metrics.streaming`). A model file
(``design.file`` from ``tdcm calibrate --out``) sets ``friction.mu``'s default and its
uncertainty: finished steps are then solved in order with stick-slip friction and
``metrics/table`` carries ``band`` (the markers inside the predicted 95 % band); the per-frame
errors stay those of the frictionless model (its lookup table).

Publishes (frame ``base_frame_id`` after ``frame_prefix``, :mod:`tdcm_ros.nodes.frames`; SI
units):

- ``metrics/marker_errors`` (mocap4r2_msgs/msg/Markers): per marker frame, each visible
  marker's measured minus predicted position (m; the model at the tension, or tension vector,
  nearest the frame's stamp within ``align.tolerance_s``: interpolated on a grid of 0.1 N per
  tendon, :mod:`tdcm_ros.metrics.lookup`), same labels and stamp as the input;
- ``metrics/tip_error`` (geometry_msgs/msg/Vector3Stamped): the same vector for the tip marker;
- ``metrics/table`` (std_msgs/msg/String): JSON of the running Table I and the finished steps,
  the ``tdcm evaluate --json`` layout (a step's ``tensions_n`` by tendon name), after each
  finished step;
- ``metrics/mape_pct``, ``metrics/rmse_m``, ``metrics/mae_m``, ``metrics/shape_error_m``,
  ``metrics/deflection_mean_m`` (std_msgs/msg/Float64): the running values, once defined;
- ``/diagnostics``: WARN when no tension or no markers arrived for ``stale_s``, or no
  registration is known yet; counters.

Registration (``registration.source``):

- ``tf``: each marker frame is placed by TF, the pose of ``base_frame_id`` in ``mocap_frame_id``
  at the frame's stamp (:class:`~tdcm_ros.mocap.TransformBuffer`: ``/tf`` edges interpolated,
  kept ``tf.cache_s``). A frame waits up to ``tf.wait_s`` (node time) for TF to cover its stamp,
  in arrival order; then it is counted (``frames_without_transform``) and not scored. When every
  edge between the two frames is static the pose is one registration (method ``tf_static``):
  frames are kept in ``mocap`` and finished steps are re-scored when it changes, as offline.
  When an edge moves (a base on a moving robot), each frame is moved into the base at its own
  stamp before it is averaged or scored (method ``tf``; the table reports the identity). A
  change between the two cases restarts the running evaluation (counted, ``restarts``).
- ``tf_static``: the same from ``/tf_static`` alone.
- ``auto``: ``tf`` once TF relates the two frames; until then frames are kept in ``mocap`` and
  the registration is estimated from a zero-tension and the largest-tension step.
- ``parameter``: ``registration.translation`` m, ``registration.rotation`` quaternion
  (x, y, z, w); ``estimate``: always estimated.
"""

from __future__ import annotations

import json
import math
import sys
from collections import Counter, deque
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict, msg_class
from tdcm_ros.errors import InputError, TdcmError
from tdcm_ros.metrics import (
    MARKER_SPECS,
    OPTION_SPECS,
    STEP_SPECS,
    EvaluateOptions,
    Evaluation,
    MarkerLayout,
    RunningEvaluation,
    StepSettings,
)
from tdcm_ros.mocap import (
    ExtrapolationError,
    Registration,
    TransformBuffer,
    TransformLookupError,
)
from tdcm_ros.model import (
    PARAMETER_SPECS,
    PRESETS,
    Design,
    InvalidRollError,
    ModelSpec,
    parameter_specs,
    read_model,
    require_paper_tendon,
)
from tdcm_ros.nodes.frames import FRAME_PREFIX_SPECS, declare_frame_prefix, robot_frame
from tdcm_ros.nodes.joint_messages import JOINT_STATE, tendon_efforts
from tdcm_ros.nodes.joint_states import joint_position
from tdcm_ros.nodes.tf_messages import TF_TYPE
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
)
from tdcm_ros.runtime.run_node import main_for
from tdcm_ros.spec import Spec, by_name

REGISTRATION_SOURCES = ("auto", "tf", "tf_static", "parameter", "estimate")
TF_SOURCES = ("auto", "tf", "tf_static")
TENSION_TYPES = ("geometry_msgs/msg/WrenchStamped", JOINT_STATE)
TABLE_TOPICS = ("mape_pct", "rmse_m", "mae_m", "shape_error_m", "deflection_mean_m")
SCORED_DEPTH = 10_000
"""History depth (messages) of the scored inputs (tension, markers, joint_states): an evaluator
must not lose data it scores, so a backlog that builds while the node is busy (an update, a
loaded machine) waits in the queue instead of pushing its oldest frames out. The sample bag's
6,758 marker frames played at x2 fit whole; a depth of 100 lost 514 of them on a loaded machine."""
#: The design preset the design.* fields start from.
PRESET_SPECS = by_name(Spec("design.preset", description="design preset the fields start from",
                            default="paper-experiment", kind="str", choices=tuple(PRESETS)),
                       Spec("design.file", description="body file (.yaml) the design fields start "
                            "from instead of design.preset, read at start ('': none)", default="",
                            kind="str"))
#: The marker layout as parameters ``markers.<field>``; ``markers.radial_offset`` defaults to
#: ``design.R_outer + markers.ball_radius`` (on the surface). ``markers.radius`` is the former
#: name of ``markers.ball_radius``.
LAYOUT_SPECS = {**MARKER_SPECS,
                "ball_radius": replace(MARKER_SPECS["ball_radius"], formerly=("radius",))}
#: Parameters fixed at start, besides the evaluation options.
FIXED_SPECS = by_name(
    Spec("input.tension_type", description="message type on `tension`: WrenchStamped "
         "(force.z, N; a body with one tendon) or JointState (one effort per tendon in N, by "
         "the body's tendon names: required for a body with several tendons)",
         default=TENSION_TYPES[0], kind="str", choices=TENSION_TYPES),
    Spec("registration.source", description="auto, tf, tf_static, parameter or estimate",
         default="auto", kind="str", choices=REGISTRATION_SOURCES),
    Spec("registration.translation", "m", "tdcm_base origin in mocap, source=parameter",
         (0.0, 0.0, 0.0), kind="vector"),
    Spec("registration.rotation", "", "tdcm_base orientation in mocap (x, y, z, w)",
         (0.0, 0.0, 0.0, 1.0), kind="vector", size=4),
    Spec("roll.joint", description="joint of `joint_states` the body rolls by (rad about "
         "the base +z axis)", default="roll", kind="str"),
    Spec("base_frame_id", description="the body's base frame: the registration's child "
         "frame and the outputs' frame", default="tdcm_base", kind="str"),
    Spec("mocap_frame_id", description="the motion-capture frame: the markers' frame, the "
         "registration's parent", default="mocap", kind="str"),
    Spec("tf.cache_s", "s", "how long a /tf edge's samples are kept", 10.0, low=0.1,
         high=3600.0),
    Spec("tf.wait_s", "s", "how long a marker frame waits for TF to cover its stamp (node "
         "time)", 1.0, low=0.0, high=60.0),
    Spec("update_period_s", "s", "period of step detection", 0.5, low=0.01, high=60.0),
    Spec("diagnostics_period_s", "s", "diagnostics period", 1.0, low=0.05, high=60.0),
    Spec("max_buffer_s", "s", "longest buffered stretch without a step", 120.0, low=1.0,
         high=3600.0))
#: Parameters a client may change at run time.
TUNABLE_SPECS = by_name(Spec("stale_s", "s", "inputs older than this are stale; changeable at run "
                             "time", 1.0, low=0.01, high=3600.0))


@dataclass(frozen=True)
class _Frame:
    """A marker frame: the message, its stamp (s), its rows (k, 3) m in ``mocap`` and when it
    arrived (node time, ns)."""

    message: Any
    stamp_s: float
    rows: np.ndarray
    received_ns: int


def _stamp_s(message: Any) -> float:
    return int(message.header.stamp.sec) + int(message.header.stamp.nanosec) * 1e-9


def declare_design_and_layout(port: NodePort, node: str = "metrics_node", *,
                              tendon_list: bool = False
                              ) -> tuple[Design, MarkerLayout, ModelSpec]:
    """The design (``design.preset`` then ``design.*``) and the marker layout (``markers.*``)
    as read-only parameters of the node named ``node``, and the model ``design.file`` or
    ``design.preset`` names (a model file's friction and uncertainty); bad values raise
    InputError, and so does a body with a tendon list unless ``tendon_list`` (the node takes a
    tension per tendon)."""
    start = declare_specs(port, PRESET_SPECS, read_only=True)
    model = read_model(str(start["design.file"]) or str(start["design.preset"]))
    base = model.design
    if not tendon_list:
        require_paper_tendon(base.tendons, f"{node} (one tension input)", "design.file")
    design = base.with_overrides(**declare_specs(
        port, parameter_specs(base), prefix="design.", defaults=base.to_dict(), read_only=True))
    given = {k: s for k, s in LAYOUT_SPECS.items() if k != "radial_offset"}
    fields = declare_specs(port, given, prefix="markers.", read_only=True)
    # a ROS parameter has a value: the default offset is the surface's, of the values above
    fields.update(declare_specs(
        port, {"radial_offset": LAYOUT_SPECS["radial_offset"]}, prefix="markers.",
        defaults={"radial_offset": design.R_outer + fields["ball_radius"]}, read_only=True))
    return design, MarkerLayout(**fields), model


def marker_rows(message: Any, index: dict[str, int]) -> tuple[np.ndarray, int]:
    """Marker points (k, 3) m of a ``mocap4r2_msgs/msg/Markers`` in the order of ``index``
    (label -> row; NaN rows not seen) and how many markers were ignored (unknown label or
    not finite)."""
    rows = np.full((len(index), 3), np.nan)
    ignored = 0
    for marker in message.markers:
        i = index.get(marker.marker_name)
        p = marker.translation
        if i is None or not all(math.isfinite(v) for v in (p.x, p.y, p.z)):
            ignored += 1
            continue
        rows[i] = (p.x, p.y, p.z)
    return rows, ignored


#: Every parameter of the node by full name, as declared below (parameter files are checked
#: against it).
PARAMETERS = {**grouped(FRAME_PREFIX_SPECS), **grouped(PRESET_SPECS),
              **grouped(PARAMETER_SPECS, "design."),
              **grouped(LAYOUT_SPECS, "markers."), **grouped(STEP_SPECS, "steps."),
              **grouped(OPTION_SPECS), **grouped(FIXED_SPECS), **grouped(TUNABLE_SPECS)}


class MetricsNode(NodeLogic):
    """Per-sample errors and running Table I; see the module docstring."""

    default_name = "metrics_node"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.options = self._options()
        fixed = declare_specs(port, FIXED_SPECS, read_only=True)
        prefix = declare_frame_prefix(port)
        declare_specs(port, TUNABLE_SPECS)
        self.source = str(fixed["registration.source"])
        self.tension_type = str(fixed["input.tension_type"])
        self.tendons = tuple(t.name for t in self.options.design.tendon_list())
        if len(self.tendons) > 1 and self.tension_type != JOINT_STATE:
            raise InputError(
                f"input.tension_type = {self.tension_type} carries one tension, but the body "
                f"has {len(self.tendons)} tendons ({', '.join(self.tendons)}); allowed: "
                f"{JOINT_STATE} (an effort in N per tendon, by name)",
                parameter="input.tension_type", value=self.tension_type, allowed=JOINT_STATE)
        self.roll_joint = str(fixed["roll.joint"])
        self.base_frame = robot_frame(prefix, str(fixed["base_frame_id"]))
        self.mocap_frame = str(fixed["mocap_frame_id"]).lstrip("/")
        translation, rotation = fixed["registration.translation"], fixed["registration.rotation"]
        update_s = float(fixed["update_period_s"])
        diag_s = float(fixed["diagnostics_period_s"])
        buffer_s = float(fixed["max_buffer_s"])
        given = None
        if self.source == "parameter":
            given = Registration(tuple(translation), tuple(rotation), method="parameter")
        self.running = RunningEvaluation(self.options, given, max_buffer_s=buffer_s,
                                         estimate=self.source in ("auto", "estimate"))
        self.tf = (TransformBuffer(float(fixed["tf.cache_s"])) if self.source in TF_SOURCES
                   else None)
        self.wait_ns = round(float(fixed["tf.wait_s"]) * 1e9)
        self.pending: deque[_Frame] = deque()
        self.moving = False  # frames are moved into the base one by one (a moving TF edge)
        self.tf_problem = ""  # why TF did not place the last frame, or rejected an edge
        qos = QoS(depth=10)
        self.marker_errors = port.create_publisher("metrics/marker_errors",
                                                   "mocap4r2_msgs/msg/Markers", qos)
        self.tip_error = port.create_publisher("metrics/tip_error",
                                               "geometry_msgs/msg/Vector3Stamped", qos)
        self.table = port.create_publisher("metrics/table", "std_msgs/msg/String",
                                           QoS(depth=1, durability="transient_local"))
        self.values = {name: port.create_publisher(f"metrics/{name}", "std_msgs/msg/Float64",
                                                   qos) for name in TABLE_TOPICS}
        # what it scores is queued, not dropped, while it is busy (see SCORED_DEPTH)
        scored = QoS(depth=SCORED_DEPTH, reliability="reliable")
        port.create_subscription("tension", self.tension_type, self._on_tension,
                                 overridable_qos(port, "tension", scored))
        port.create_subscription("markers", "mocap4r2_msgs/msg/Markers", self._on_markers,
                                 overridable_qos(port, "markers", scored))
        port.create_subscription("joint_states", "sensor_msgs/msg/JointState",
                                 self._on_joint_states, overridable_qos(port, "joint_states", scored))
        if self.tf is not None:  # tf2's listener QoS
            port.create_subscription("/tf_static", TF_TYPE, self._on_tf_static,
                                     QoS(depth=100, durability="transient_local"))
            if self.source != "tf_static":
                port.create_subscription("/tf", TF_TYPE, self._on_tf, QoS(depth=100))
        self.counts: Counter[str] = Counter()
        self.last_ns: dict[str, int] = {}
        self.index = {label: i for i, label in enumerate(self.options.layout.labels)}
        port.create_timer(update_s, self.update)
        self.diagnostics = Diagnostics(port, diag_s)
        self.diagnostics.add("inputs", "tdcm_metrics", self.check_inputs)

    def _options(self) -> EvaluateOptions:
        """Evaluation options from the (read-only) parameters; bad values raise InputError."""
        port = self.port
        design, layout, model = declare_design_and_layout(port, tendon_list=True)
        steps = StepSettings(**declare_specs(port, STEP_SPECS, prefix="steps.", read_only=True))
        return EvaluateOptions(design=design, steps=steps, layout=layout,
                               uncertainty=model.uncertainty,
                               **declare_specs(port, OPTION_SPECS, read_only=True,
                                               defaults={"friction_mu": model.friction_mu}))

    def _on_tension(self, message: Any) -> None:
        """Buffer a tension sample (N, one per tendon); one without a finite tension for every
        tendon is counted (``tension_missing_tendon``, ``tension_non_finite``) and dropped."""
        if self.tension_type == JOINT_STATE:
            values, missing = tendon_efforts(message, self.tendons)
            if missing:
                self.counts["tension_missing_tendon"] += 1
                return
        else:
            values = (float(message.wrench.force.z),)
        if not all(math.isfinite(value) for value in values):
            self.counts["tension_non_finite"] += 1
            return
        self.counts["tension"] += 1
        self.last_ns["tension"] = self.port.now_ns()
        self.running.add_tension(_stamp_s(message), values)

    def _on_joint_states(self, message: Any) -> None:
        roll = joint_position(message, self.roll_joint)
        if roll is None:
            return
        try:
            kept = self.running.add_roll(_stamp_s(message) or self.port.now_ns() * 1e-9, roll)
        except InvalidRollError:
            self.counts["roll_non_finite"] += 1
            return
        self.counts["roll" if kept else "roll_out_of_order"] += 1

    def _on_markers(self, message: Any) -> None:
        self.counts["marker_frames"] += 1
        self.last_ns["markers"] = self.port.now_ns()
        rows, ignored = marker_rows(message, self.index)
        if ignored:
            self.counts["markers_ignored"] += ignored
        frame = _Frame(message, _stamp_s(message), rows, self.port.now_ns())
        if self.tf is None:
            self._score(frame, rows)
            return
        self.pending.append(frame)
        self._release()

    def _release(self) -> None:
        """Place the waiting marker frames, in arrival order, as TF covers their stamps; a
        frame TF cannot place within ``tf.wait_s`` is counted and dropped (``auto`` before TF
        ever placed one: kept in ``mocap`` for the estimate)."""
        assert self.tf is not None
        while self.pending:
            frame = self.pending[0]
            try:
                pose = self.tf.lookup(self.mocap_frame, self.base_frame, frame.stamp_s)
            except TransformLookupError as error:
                estimating = self.source == "auto" and self.running.registration is None
                not_yet = isinstance(error, ExtrapolationError) and error.future
                waited = self.port.now_ns() - frame.received_ns > self.wait_ns
                if not waited and (not_yet or not estimating):
                    return
                self.pending.popleft()
                if estimating:
                    self._score(frame, frame.rows)
                    continue
                self.counts["frames_without_transform"] += 1
                self.tf_problem = f"markers at {frame.stamp_s:.3f} s not placed by TF: {error}"
                continue
            self.pending.popleft()
            self.tf_problem = ""
            self._place(frame, pose)

    def _place(self, frame: _Frame, pose: Registration) -> None:
        """Score a frame TF placed: by one registration on a static path, else moved into the
        base at its stamp (see the module docstring)."""
        assert self.tf is not None
        moving = not self.tf.is_static(self.mocap_frame, self.base_frame)
        if moving != self.moving or (moving and self.running.registration is None):
            self._restart(moving)
        if moving:
            self._score(frame, pose.to_base(frame.rows))
            return
        self._use_static(pose)
        self._score(frame, frame.rows)

    def _use_static(self, pose: Registration) -> None:
        """Use the pose of a static path as the registration (finished steps re-scored when it
        changes)."""
        registration = replace(pose, method="tf_static")
        if self.running.registration != registration:
            self.counts["registrations"] += 1
            self.running.set_registration(registration)

    def _restart(self, moving: bool) -> None:
        """Restart the running evaluation's markers: frames in the base (``moving``) or in
        ``mocap``; tension and roll samples stay."""
        if self.running.has_markers:
            self.counts["restarts"] += 1
        self.moving = moving
        self.running.restart_markers(Registration.identity("tf") if moving else None)

    def _score(self, frame: _Frame, rows: np.ndarray) -> None:
        """Buffer one marker frame (rows in ``mocap``, or in the base when moving) and publish
        its errors."""
        message, stamp = frame.message, frame.stamp_s
        self.running.add_markers(stamp, rows)
        try:
            errors = self.running.sample_errors(stamp, rows)
        except TdcmError:  # no model at that tension: as offline, the frame is not scored
            self.counts["frames_model_failed"] += 1
            return
        if errors is None:
            self.counts["frames_without_error"] += 1
            return
        self._publish_errors(message, errors)

    def _publish_errors(self, message: Any, errors: np.ndarray) -> None:
        hdr = msg_class("std_msgs/msg/Header")(stamp=message.header.stamp, frame_id=self.base_frame)
        point, marker = msg_class("geometry_msgs/msg/Point"), msg_class(
            "mocap4r2_msgs/msg/Marker")
        labels = self.options.layout.labels
        items = [marker(id_type=2, marker_index=i, marker_name=labels[i],
                        translation=point(x=float(e[0]), y=float(e[1]), z=float(e[2])))
                 for i, e in enumerate(errors) if not np.isnan(e[0])]
        self.marker_errors.publish(msg_class("mocap4r2_msgs/msg/Markers")(
            header=hdr, frame_number=message.frame_number, markers=items))
        tip = errors[-1]
        if not np.isnan(tip[0]):
            self.tip_error.publish(msg_class("geometry_msgs/msg/Vector3Stamped")(
                header=hdr, vector=msg_class("geometry_msgs/msg/Vector3")(
                    x=float(tip[0]), y=float(tip[1]), z=float(tip[2]))))

    def _on_tf_static(self, message: Any) -> None:
        self._add_transforms(message, static=True)

    def _on_tf(self, message: Any) -> None:
        self._add_transforms(message, static=False)

    def _add_transforms(self, message: Any, *, static: bool) -> None:
        """Put a TFMessage's edges in the buffer (a bad edge is counted, ``tf_rejected``, and
        reported) and place the marker frames waiting for them."""
        assert self.tf is not None
        topic = "/tf_static" if static else "/tf"
        problems = self.tf.add_message(message, static=static)
        self.counts[topic.lstrip("/")] += len(message.transforms) - len(problems)
        if problems:
            self.counts["tf_rejected"] += len(problems)
            self.tf_problem = f"{topic}: {problems[-1]}"
        if self.tf.is_static(self.mocap_frame, self.base_frame) and not self.moving:
            # a static path holds at every time: the registration is known before any frame
            self._use_static(self.tf.lookup(self.mocap_frame, self.base_frame, None))
        self._release()

    def update(self) -> None:
        """Place marker frames that waited too long for TF; finish ended steps; publish the
        running table when a step finished."""
        if self.tf is not None:
            self._release()
        finished = self.running.update()
        if not finished or self.running.metrics is None:
            return
        self.counts["steps"] = len(self.running.records)
        regs = (self.running.used_registration,) if self.running.used_registration else ()
        ev = Evaluation(tuple(self.running.records), self.running.metrics, regs, self.options,
                        (), ("live",) * len(regs))
        self.table.publish(from_dict("std_msgs/msg/String", {"data": json.dumps(ev.to_json())}))
        for name, pub in self.values.items():
            value = getattr(self.running.metrics, name)
            if value is not None:
                pub.publish(from_dict("std_msgs/msg/Float64", {"data": float(value)}))

    def check_inputs(self) -> Status:
        """WARN while tension or markers are stale or no registration is known, else OK:
        staleness, registration and counters."""
        now = self.port.now_ns()
        stale_s = float(self.port.get_parameter("stale_s"))
        problems = [f"no {name} for more than {stale_s:g} s"
                    for name in ("tension", "markers")
                    if now - self.last_ns.get(name, -(1 << 62)) > stale_s * 1e9]
        reg = self.running.used_registration
        if reg is None:
            problems.append(f"no registration yet (waiting for TF {self.mocap_frame} -> "
                            f"{self.base_frame} or a zero-tension and a bent step)")
        if self.tf_problem:
            problems.append(self.tf_problem)
        message = "; ".join(problems) or self.running.problem or "ok"
        values = {**dict(sorted(self.counts.items())),
                  "registration": reg.method if reg else "none"}
        level = DiagnosticLevel.WARN if problems else DiagnosticLevel.OK
        return Status(level, message, values)

def main() -> int:
    """``ros2 run tdcm_ros metrics_node`` / ``metrics_node`` console script."""
    return main_for(MetricsNode)


if __name__ == "__main__":
    sys.exit(main())
