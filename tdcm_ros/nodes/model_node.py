"""``model_node``: tendon tension in, predicted midline out (Algorithm 1 on every new tension).

Subscribes ``tension`` (``geometry_msgs/msg/WrenchStamped``: the tension is ``wrench.force.z``
in N, in a frame whose z axis runs along the tendon toward the actuator; or
``std_msgs/msg/Float64`` in N; or ``sensor_msgs/msg/JointState``, one effort in N per tendon
named as in the body file (the input of a body with several tendons: ros2_control's
convention for a set of actuators, one message for one sample of all of them), by the
``input.tension_type`` parameter). Publishes, stamped
with the input's stamp, in ``frame_id`` (default ``tdcm_base``): ``midline`` (nav_msgs/Path),
``midline_poses`` (PoseArray), ``tip_pose`` (PoseStamped), ``predicted_markers`` (PoseArray),
``body_markers`` (visualization_msgs/MarkerArray), ``joint_states`` (sensor_msgs/JointState: the body's URDF joints, ``tdcm urdf``, by
:func:`~tdcm_ros.model.urdf.joint_positions`, rad and m; the roll joint is the driver's),
``tendon_states`` (sensor_msgs/JointState:
each tendon as a prismatic joint named as in the body (``tendon_<k>`` by default), position its
actuator's stroke in m, effort its tension in N; not rolled, no frame) and ``/diagnostics`` (``model_node: input``:
dropped and coalesced inputs; ``model_node: solver``: solves and failures; each WARN while a
problem happened within the last 5 diagnostics periods, OK again after).

Roll: subscribes ``joint_states`` (``sensor_msgs/msg/JointState``) and reads the joint named by
``roll.joint`` (default ``roll``, rad about the base +z axis): every output above and the TF
below is the planar shape turned by the roll (:mod:`tdcm_ros.model.roll`). Each tension is paired
with the latest roll stamped at or before the tension's stamp (the oldest one held if all are
newer; 0 until one arrives; an unstamped JointState takes the node's clock). A JointState
without that joint (or without its position) is ignored; a non-finite roll, or one stamped
before the latest kept, is dropped and counted on the input diagnostics like a bad tension. A roll alone does not trigger a solve:
the outputs follow the tension stream, as the driver publishes both per telemetry frame.

TF (``tf2_msgs/msg/TFMessage``, see :mod:`tdcm_ros.nodes.tf_messages`): on ``/tf_static``
(transient local, depth 1, as tf2's StaticTransformBroadcaster) ``frame_id -> tf.tendon_frame_id``,
the frame ``tension`` is stamped in, sent at start and again when ``frame_id`` or the design
changes (``tf.tendon: false`` leaves it to a URDF or another node); on ``/tf`` (depth 100, as tf2's TransformBroadcaster) ``frame_id -> tf.tip_frame_id``
for every solve, stamped with the input's stamp, plus ``tf.stations`` midline frames. Every
frame named here (``frame_id``, ``tf.*``) is put after ``frame_prefix`` (read-only, ``''``;
:mod:`tdcm_ros.nodes.frames`), so two robots' frames differ on the shared ``/tf``.

Friction (``friction.mu``, default a model file's ``friction`` section, else 0): above 0 each
tension is solved after the ones before it under stick-slip capstan friction
(:class:`~tdcm_ros.model.FrictionTrack`), so the shape follows the direction of the tension's
change (loading or unloading); coalesced inputs are skipped by the history too (a reversal
among the inputs that arrive during one solve is missed), and a change of the design or of
``friction.mu`` restarts it from a slack tendon.

Uncertainty (a model file's ``uncertainty`` section, written by ``tdcm calibrate --out``): on
every solve that is drawn (``output.visual_rate_hz``) the node carries the fit's covariance to
the shape (:mod:`tdcm_ros.nodes.band_messages`: one extra solve per fitted parameter) and
publishes ``tip_pose_with_covariance`` (``geometry_msgs/msg/PoseWithCovarianceStamped``) and
``shape_band`` (``visualization_msgs/msg/Marker``, the ``band.confidence`` band of the midline).
Without the section neither topic is advertised.

Keep-latest, on arrival: a valid tension is solved as soon as the node's callback thread is
free (:meth:`~tdcm_ros.runtime.NodePort.call_soon`), warm started from the previous shape; the
tensions that arrive meanwhile (during a solve) are kept newest only, and the newest is solved
next, so a burst never builds a queue (skipped inputs are counted as coalesced). Bad inputs (non-finite, negative, above ``input.tension_max``, older than
``input.max_age_s``, stamped more than ``input.max_future_s`` ahead, or a WrenchStamped with a
zero stamp) and model limits are dropped, counted and reported on ``/diagnostics``.

Parameters: a change is checked as a whole (the design with the solver settings, the markers
against the design's length) and, once accepted, replaces the node's configuration
(:class:`~tdcm_ros.nodes.model_config.ModelConfig`) in one step; each input reads that
snapshot, never a parameter by name.
"""

from __future__ import annotations

import math
import sys
from collections import Counter
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from tdcm_ros.errors import InputError, PhysicsError
from tdcm_ros.model import (
    MARKER_SPECS,
    MAX_MU,
    PARAMETER_SPECS,
    PRESETS,
    SOLVER_SPECS,
    Design,
    FrictionTrack,
    InvalidRollError,
    RollHistory,
    SolveResult,
    SolverSettings,
    joint_positions,
    parameter_specs,
    read_model,
    require_paper_tendon,
    warm_up,
)
from tdcm_ros.nodes.band_messages import shape_spread, uncertainty_messages
from tdcm_ros.nodes.frames import FRAME_PREFIX_SPECS, declare_frame_prefix
from tdcm_ros.nodes.joint_messages import (
    JOINT_STATE,
    body_joint_states,
    tendon_efforts,
    tendon_states,
)
from tdcm_ros.nodes.joint_states import joint_position
from tdcm_ros.nodes.model_config import ModelConfig
from tdcm_ros.nodes.shape_messages import midline_messages, stamp_ns_of
from tdcm_ros.nodes.tf_messages import TF_TYPE, body_tf, tendon_tf
from tdcm_ros.runtime import (
    DiagnosticLevel,
    Diagnostics,
    EventWindow,
    NodeLogic,
    NodePort,
    QoS,
    Status,
    Throttled,
    declare_specs,
    grouped,
    overridable_qos,
    read_specs,
)
from tdcm_ros.runtime.run_node import main_for
from tdcm_ros.spec import Spec, by_name

TENSION_TYPES = ("geometry_msgs/msg/WrenchStamped", "std_msgs/msg/Float64", JOINT_STATE)
#: Rolls kept to pair with tensions: over a second at the driver's telemetry rate.
ROLL_HISTORY = 2048
#: Parameters fixed at start, besides the design and solver groups.
FIXED_SPECS = by_name(
    Spec("input.tension_type", description="message type on `tension`: WrenchStamped "
         "(force.z, N), Float64 (N) or JointState (one effort per tendon in N, by the body's "
         "tendon names: a body with several tendons)", default=TENSION_TYPES[0], kind="str",
         choices=TENSION_TYPES),
    Spec("design.preset", description="design preset the fields start from",
         default="paper-experiment", kind="str", choices=tuple(PRESETS)),
    Spec("design.file", description="body or model file (.yaml) the design fields start from "
         "instead of design.preset, read at start ('': none); a model file's friction sets "
         "friction.mu's default and its uncertainty turns on the band", default="", kind="str"),
    Spec("roll.joint", description="joint of `joint_states` the body rolls by (rad about "
         "the base +z axis)", default="roll", kind="str"),
    Spec("diagnostics_period_s", "s", "diagnostics period", 1.0, low=0.05, high=60.0))
#: Parameters a client may change at run time, besides the design and solver groups.
TUNABLE_SPECS = by_name(
    Spec("frame_id", description="frame of all outputs", default="tdcm_base", kind="str"),
    Spec("output.samples", description="poses along the midline", default=54, kind="int",
         low=2, high=10_000),
    Spec("output.visual_rate_hz", "Hz", "most solves a second whose shape is drawn: midline, "
         "midline_poses, predicted_markers, body_markers and joint_states follow it (by the "
         "input's stamp), tip_pose, tendon_states and /tf every solve; 0: every solve",
         default=30.0, kind="float", low=0.0, high=1e6),
    Spec("markers.arc_lengths", "m", "arc lengths of the predicted markers",
         MARKER_SPECS["arc_lengths"].default, kind="list"),
    Spec("markers.placement", description="surface or midline", default="surface", kind="str",
         choices=("surface", "midline")),
    replace(MARKER_SPECS["ball_radius"], name="markers.ball_radius",
            formerly=("markers.radius",)),
    replace(MARKER_SPECS["side_deg"], name="markers.side_deg"),
    Spec("input.tension_max", "N", "largest valid tension", 200.0, low=0.0, high=1e6),
    Spec("input.max_age_s", "s", "inputs older than this are stale; 0 disables", 0.5, low=0.0,
         high=3600.0),
    Spec("input.max_future_s", "s", "inputs stamped further ahead of the clock are dropped", 0.5,
         low=0.0, high=3600.0),
    Spec("friction.mu", description="capstan friction coefficient tendon/channel; above 0 each "
         "tension is solved after the previous ones with stick-slip friction (default: the "
         "model file's friction.mu, else 0)", default=0.0, low=0.0, high=MAX_MU),
    Spec("band.confidence", description="confidence of shape_band (with a model file's "
         "uncertainty)", default=0.95, low=0.5, high=0.999))

#: TF frames, fixed at start (the parent is ``frame_id``).
TF_SPECS = by_name(
    Spec("tf.tip_frame_id", description="child frame of the tip transform on /tf",
         default="tdcm_tip", kind="str"),
    Spec("tf.tendon_frame_id", description="child frame of the static tendon transform "
         "(tension_driver's frame_id)", default="tdcm_tendon", kind="str"),
    Spec("tf.tendon", description="broadcast the static tendon transform (off where a URDF "
         "or another node does)", default=True, kind="bool"),
    Spec("tf.stations", description="midline frames on /tf at s = k L / n, k = 1..n; 0 = none",
         default=0, kind="int", low=0, high=1000),
    Spec("tf.station_prefix", description="station frame k is <prefix><k>",
         default="tdcm_station_", kind="str"))

#: Every parameter of the node by full name, as declared below (parameter files are checked
#: against it).
PARAMETERS = {**grouped(FIXED_SPECS), **grouped(FRAME_PREFIX_SPECS), **grouped(TF_SPECS),
              **grouped(PARAMETER_SPECS, "design."),
              **grouped(SOLVER_SPECS, "solver."), **grouped(TUNABLE_SPECS)}


def _check_frame_names(names: Mapping[str, Any]) -> None:
    """tf2's rule for frame ids: not empty, no leading ``/``; the two children must differ."""
    for key in ("tf.tip_frame_id", "tf.tendon_frame_id", "tf.station_prefix"):
        value = str(names[key])
        if not value or value.startswith("/"):
            raise InputError(f"{key} = {value!r} is not a tf2 frame id; allowed: a non-empty "
                             f"name without a leading '/'", parameter=key, value=value,
                             allowed="non-empty, no leading '/'")
    if names["tf.tip_frame_id"] == names["tf.tendon_frame_id"]:
        raise InputError(f"tf.tip_frame_id = tf.tendon_frame_id = {names['tf.tip_frame_id']!r}; "
                         "allowed: two different frames", parameter="tf.tip_frame_id",
                         value=names["tf.tip_frame_id"], allowed="differs from tf.tendon_frame_id")


class ModelNode(NodeLogic):
    """Predicts the midline for each new tension; see the module docstring."""

    default_name = "model_node"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        fixed = declare_specs(port, FIXED_SPECS, read_only=True)
        self.tf_names = declare_specs(port, TF_SPECS, read_only=True)
        _check_frame_names(self.tf_names)
        self.prefix = declare_frame_prefix(port)
        self.tension_type = str(fixed["input.tension_type"])
        self.roll_joint = str(fixed["roll.joint"])
        model = read_model(str(fixed["design.file"]) or str(fixed["design.preset"]))
        self.base, self.uncertainty = model.design, model.uncertainty
        if self.tension_type != JOINT_STATE:
            try:
                require_paper_tendon(self.base.tendons, f"input.tension_type = "
                                     f"{self.tension_type} (one tension)", "design.file")
            except InputError as error:
                raise InputError(f"{error}; a body with several tendons takes input.tension_type"
                                 f" = {JOINT_STATE}", parameter="input.tension_type",
                                 value=self.tension_type, allowed=JOINT_STATE) from error
        self.design_specs = parameter_specs(self.base)
        declare_specs(port, self.design_specs, prefix="design.", defaults=self.base.to_dict())
        declare_specs(port, SOLVER_SPECS, prefix="solver.")
        declare_specs(port, TUNABLE_SPECS, defaults={"friction.mu": model.friction_mu})
        diag_period = float(fixed["diagnostics_period_s"])
        self.config = self._config({})
        self.track = FrictionTrack(self.config.mu)
        port.add_on_set_parameters(self._on_set)
        warm_up()  # compile the solver's kernel now, not on the first message

        qos = QoS(depth=10)
        self.publishers = {topic: port.create_publisher(topic, type_name, qos) for topic, type_name
                           in (("midline", "nav_msgs/msg/Path"),
                               ("midline_poses", "geometry_msgs/msg/PoseArray"),
                               ("tip_pose", "geometry_msgs/msg/PoseStamped"),
                               ("predicted_markers", "geometry_msgs/msg/PoseArray"),
                               ("body_markers", "visualization_msgs/msg/MarkerArray"),
                               ("tendon_states", JOINT_STATE),
                               *((("tip_pose_with_covariance",
                                   "geometry_msgs/msg/PoseWithCovarianceStamped"),
                                  ("shape_band", "visualization_msgs/msg/Marker"))
                                 if self.uncertainty is not None else ()))}
        self.tf_static = port.create_publisher("/tf_static", TF_TYPE,
                                               QoS(depth=1, durability="transient_local"))
        self.tf = port.create_publisher("/tf", TF_TYPE, QoS(depth=100))
        self.joint_states = port.create_publisher("joint_states", JOINT_STATE, qos)
        self._publish_tendon_tf()
        # A deep queue so every input is seen (and counted); the callback only stores the newest.
        port.create_subscription("tension", self.tension_type, self._on_tension,
                                 overridable_qos(port, "tension", QoS(depth=100)))
        port.create_subscription("joint_states", "sensor_msgs/msg/JointState",
                                 self._on_joint_states,
                                 overridable_qos(port, "joint_states", QoS(depth=100)))
        self.rolls = RollHistory(ROLL_HISTORY)
        self.pending: tuple[float | tuple[float, ...], int] | None = None
        self.previous: SolveResult | None = None
        self.drawn_ns: int | None = None  # stamp of the last solve whose shape was drawn
        self.counts: Counter[str] = Counter()
        self.last_problem = ""
        self.last_failure = ""
        self._drop_warnings = Throttled(clock=lambda: self.port.now_ns() / 1e9)
        self.diagnostics = Diagnostics(port, diag_period)
        self.dropped, self.failed = self.diagnostics.window(), self.diagnostics.window()
        self.diagnostics.add("input", "tdcm_model", self.check_input)
        self.diagnostics.add("solver", "tdcm_model", self.check_solver)

    def _config(self, changes: Mapping[str, Any]) -> ModelConfig:
        """The configuration of the current parameters with ``changes`` (by full name) applied."""
        design = self.base.with_overrides(**read_specs(self.port, self.design_specs, prefix="design.",
                                                  changes=changes))
        settings = SolverSettings(**read_specs(self.port, SOLVER_SPECS, prefix="solver.",
                                               changes=changes))
        return ModelConfig.of(design, settings,
                              read_specs(self.port, TUNABLE_SPECS, changes=changes), self.prefix)

    def _on_set(self, changes: Mapping[str, Any]) -> None:
        """Validate a runtime change as a whole and swap the configuration; raising keeps the
        old values."""
        self.config = self._config(changes)
        self.track = FrictionTrack(self.config.mu)
        self.previous = None
        self._publish_tendon_tf()

    def _publish_tendon_tf(self) -> None:
        """Send the static ``frame_id -> tf.tendon_frame_id`` transform of the current design
        (unless ``tf.tendon`` is off)."""
        if not self.tf_names["tf.tendon"]:
            return
        self.tf_static.publish_cdr(tendon_tf(
            self.config.design, stamp_ns=self.port.now_ns(), parent=self.config.frame_id,
            child=self.prefix + str(self.tf_names["tf.tendon_frame_id"])))

    def _on_tension(self, message: Any) -> None:
        """Store a valid tension (N; a JointState's, one per tendon) with its stamp (ns); an
        unstamped ``Float64`` takes the node's clock."""
        stamp_ns: int | None
        tension: float | tuple[float, ...]
        reason = ""
        if self.tension_type == TENSION_TYPES[0]:
            tension = float(message.wrench.force.z)
            stamp_ns = stamp_ns_of(message)
        elif self.tension_type == JOINT_STATE:
            tension, missing = tendon_efforts(message, self.config.tendon_names)
            reason = "missing_tendon" if missing else ""
            stamp_ns = stamp_ns_of(message)
        else:
            tension, stamp_ns = float(message.data), None
        now = self.port.now_ns()
        reason = reason or self._reject_reason(tension, stamp_ns, now)
        if reason:
            self.counts[f"dropped_{reason}"] += 1
            self.last_problem = f"dropped tension {tension!r} N: {reason}"
            if (suffix := self._drop_warnings.admit(reason)) is not None:
                self.port.logger.warning("dropped tension %r N: %s%s", tension,
                                         self._why_dropped(reason, stamp_ns or 0, now), suffix)
            return
        if self.pending is not None:  # a solve is queued already: it takes this one instead
            self.counts["coalesced"] += 1
        else:
            self.port.call_soon(self.process)
        self.pending = (tension, now if stamp_ns is None else stamp_ns)

    def _on_joint_states(self, message: Any) -> None:
        """Keep the roll (rad) of a JointState naming ``roll.joint``, with its stamp (ns; an
        unset stamp takes the node's clock); a non-finite roll is dropped and counted."""
        roll = joint_position(message, self.roll_joint)
        if roll is None:
            return
        reason = ""
        try:
            if not self.rolls.add(stamp_ns_of(message) or self.port.now_ns(), roll):
                reason = "out_of_order"
        except InvalidRollError:
            reason = "non_finite"
        if reason:
            self.counts[f"dropped_roll_{reason}"] += 1
            self.last_problem = f"dropped roll {roll!r} rad of joint {self.roll_joint!r}: {reason}"

    def _why_dropped(self, reason: str, stamp_ns: int, now_ns: int) -> str:
        """A dropped tension's reason in words, with the parameter that decides it."""
        config = self.config
        if reason == "unstamped":
            return ("header.stamp is 0 (never set): stamp it (tdcm topic pub: {header: auto}), or "
                    "send std_msgs/msg/Float64 with input.tension_type")
        if reason == "stale":
            return (f"stamped {(now_ns - stamp_ns) / 1e9:.3g} s before the node's clock, older "
                    f"than input.max_age_s = {config.max_age_s:g} s (a bag replay needs "
                    f"tdcm bag play --clock and use_sim_time: true on the node)")
        if reason == "future":
            return (f"stamped {(stamp_ns - now_ns) / 1e9:.3g} s after the node's clock, more than "
                    f"input.max_future_s = {config.max_future_s:g} s")
        if reason == "above_max":
            return f"above input.tension_max = {config.tension_max_n:g} N"
        if reason == "missing_tendon":
            names = ", ".join(config.tendon_names)
            return f"the JointState has no effort for every tendon ({names})"
        return f"{reason.replace('_', '-')} tension"

    def _reject_reason(self, tension: float | tuple[float, ...], stamp_ns: int | None,
                       now_ns: int) -> str:
        """Why a tension (N; or one per tendon, each checked) stamped ``stamp_ns`` (ns; None:
        a type without a header) is dropped at ``now_ns``, or ``""``. A zero header stamp was
        never set: its age is unknown, so it is dropped as ``unstamped``."""
        values = tension if isinstance(tension, tuple) else (tension,)
        config = self.config
        if not all(math.isfinite(value) for value in values):
            return "non_finite"
        if any(value < 0.0 for value in values):
            return "negative"
        if max(values) > config.tension_max_n:
            return "above_max"
        if stamp_ns is None:
            return ""
        if stamp_ns == 0:
            return "unstamped"
        if stamp_ns - now_ns > config.max_future_s * 1e9:
            return "future"
        if config.max_age_s > 0.0 and now_ns - stamp_ns > config.max_age_s * 1e9:
            return "stale"
        return ""

    def _draw_due(self, stamp_ns: int) -> bool:
        """Whether the solve stamped ``stamp_ns`` is drawn (``output.visual_rate_hz``): the first,
        one ``1 / rate`` s of stamps after the last drawn, or one stamped before it."""
        period = self.config.visual_period_ns
        last = self.drawn_ns
        if period and last is not None and 0 <= stamp_ns - last < period:
            return False
        self.drawn_ns = stamp_ns
        return True

    def process(self) -> None:
        """Solve the newest pending tension, if any, and publish the shape."""
        if self.pending is None:
            return
        tension, stamp_ns = self.pending
        self.pending = None
        config = self.config
        try:
            result = self.track.solve_at(config.design, tension, settings=config.settings,
                                         warm_start=self.previous)
        except (PhysicsError, InputError) as error:
            self.counts[f"model_{error.kind}"] += 1
            self.last_failure = f"tension {_shown(tension)} N: {error}"
            return
        self.previous = result
        self.counts["solved"] += 1
        frame_id = config.frame_id
        roll = self.rolls.at(stamp_ns)
        drawn = self._draw_due(stamp_ns)
        for topic, data in midline_messages(
                result, stamp_ns=stamp_ns, frame_id=frame_id,
                samples=config.samples, marker_s=config.marker_s,
                marker_radius=config.marker_radius_m, marker_side_rad=config.marker_side_rad,
                roll=roll, drawn=drawn):
            self.publishers[topic].publish_cdr(data)  # midline first: sent before the rest is built
        self.publishers["tendon_states"].publish_cdr(
            tendon_states(stamp_ns, result.tendons.names, result.actuator_strokes_m.tolist(),
                          result.tensions_n))
        if drawn:
            self.joint_states.publish_cdr(body_joint_states(
                stamp_ns, config.joint_names, joint_positions(result)[1:].tolist()))
            self._publish_uncertainty(result, tension, stamp_ns, config, roll)
        self.track.state.advance(result)  # after the band: it moves the parameters on this history
        self.tf.publish_cdr(body_tf(result, stamp_ns=stamp_ns, parent=frame_id,
                                    tip=self.prefix + str(self.tf_names["tf.tip_frame_id"]),
                                    station_prefix=self.prefix
                                    + str(self.tf_names["tf.station_prefix"]),
                                    stations=int(self.tf_names["tf.stations"]), roll=roll))

    def _publish_uncertainty(self, result: SolveResult, tension: float | tuple[float, ...],
                             stamp_ns: int, config: ModelConfig, roll: float) -> None:
        """The tip with covariance and the band of ``result`` (a model file's uncertainty);
        a moved parameter the model cannot solve skips them, counted as a solver failure."""
        if self.uncertainty is None:
            return

        def resolve(design: Design, mu: float) -> SolveResult:
            return self.track.solve_at(design, tension, mu=mu, settings=config.settings,
                                       warm_start=result)

        try:
            spread = shape_spread(result, self.track.mu, self.uncertainty,
                                  np.linspace(0.0, config.design.length, config.samples), resolve)
        except (PhysicsError, InputError) as error:
            self.counts[f"model_band_{error.kind}"] += 1
            self.last_failure = f"band at tension {_shown(tension)} N: {error}"
            return
        for topic, data in uncertainty_messages(
                spread, result, stamp_ns=stamp_ns, frame_id=config.frame_id, roll=roll,
                confidence=config.band_confidence):
            self.publishers[topic].publish_cdr(data)

    def check_input(self) -> Status:
        """WARN while a tension was dropped within the window (it recovers), else OK; the
        cumulative counts of dropped and coalesced inputs."""
        return self._windowed(self.dropped, "dropped", ("dropped", "coalesced"),
                              "dropped_in_window", self.last_problem)

    def check_solver(self) -> Status:
        """WARN while a solve failed within the window (it recovers), else OK; solves and
        failures by kind."""
        return self._windowed(self.failed, "model", ("model", "solved"), "failed_in_window",
                              self.last_failure)

    def _windowed(self, window: EventWindow, problems: str, shown: tuple[str, ...],
                  in_window: str, last: str) -> Status:
        """WARN with ``last`` while the counters named ``problems*`` grew within ``window``,
        else OK; values: the counters named ``shown*`` and, as ``in_window``, how many
        problems the window holds."""
        total = sum(v for k, v in self.counts.items() if k.startswith(problems))
        recent = window.recent(total, self.port.now_ns())
        values = {k: v for k, v in sorted(self.counts.items()) if k.startswith(shown)}
        values[in_window] = recent
        if recent:
            return Status(DiagnosticLevel.WARN, last, values)
        return Status(DiagnosticLevel.OK, "ok", values)

def _shown(tension: float | tuple[float, ...]) -> str:
    """A tension (N), or one per tendon, as text."""
    return ", ".join(f"{t:g}" for t in tension) if isinstance(tension, tuple) else f"{tension:g}"


def main() -> int:
    """``ros2 run tdcm_ros model_node`` / ``model_node`` console script."""
    return main_for(ModelNode)


if __name__ == "__main__":
    sys.exit(main())
