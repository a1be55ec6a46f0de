"""``shape_controller``: a tip target in, the driver's tension and roll setpoints out, with an
on-line correction of the model's stiffness from motion capture (core: :mod:`tdcm_ros.control`).

Subscribes ``target_point`` (geometry_msgs/msg/PointStamped, any frame ``/tf`` + ``/tf_static``
resolve to ``base_frame``), ``target_angle`` (std_msgs/msg/Float64, in-plane tip angle, rad, at
the current roll), ``markers`` (mocap4r2_msgs/msg/Markers, labels ``markers.labels``),
``tension`` (geometry_msgs/msg/WrenchStamped, ``wrench.force.z`` N), ``joint_states``
(sensor_msgs/msg/JointState, joint ``roll.joint``, rad), ``/tf`` and ``/tf_static``.

Publishes ``tension_setpoint`` (std_msgs/msg/Float64, N) and ``roll_setpoint`` (Float64, rad),
slewed at the driver's ``setpoint_rate`` and ``roll_rate`` within its ``tension_max`` and
``roll_max`` (read from the parameter services of the node ``driver``; until read, nothing is
commanded), when they change and every ``keepalive_s``; ``controller/target_tip``,
``controller/measured_tip``, ``controller/predicted_tip`` (geometry_msgs/msg/PointStamped,
``base_frame``, m), ``controller/tracking_error`` (geometry_msgs/msg/Vector3Stamped, measured -
target, m), ``controller/gain`` and ``controller/gain_std`` (Float64: the estimate of
``g = E_model / E_world`` and its standard deviation) and ``/diagnostics``.

``mode`` (run time): ``feedforward`` commands ``T_inverse(target) / g`` with ``g`` frozen;
``feedback`` also updates ``g`` from each measured tip, with the tension and roll of the marker
frame's own stamp (their messages' stamps; a frame that waited in the mocap pipeline while the
tendon moved is not paired with the newer tension). A frame newer than every tension received
waits until a tension stamped at or after it arrives (the driver's messages can be late on a
loaded machine, and the newest tension then is an older one), and is dropped, counted as
``markers_tension_late``, after ``measurement_timeout_s``. Without a measured tip for
``measurement_timeout_s`` feedback falls back to feed-forward with the last ``g`` and says so.
A refused target (not finite, unknown frame, past the roll limits, unreachable) is logged with
its value and the allowed range and leaves the current target in place. The controller never
arms the driver: a fault releases the tendon as the driver's rules say, and ``g`` stops adapting
while the measured tension is below ``adapt_min_n``.
"""

from __future__ import annotations

import math
import sys
import threading
from collections import Counter, deque
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from tdcm_ros.bagio import from_dict
from tdcm_ros.control import (
    DRIVER_LIMIT_NAMES,
    MODES,
    DriverLimits,
    GainSettings,
    PlaneTarget,
    ShapeController,
    angle_target,
    point_target,
    slew,
)
from tdcm_ros.errors import TdcmError
from tdcm_ros.mocap import TransformBuffer
from tdcm_ros.model import PARAMETER_SPECS, RollHistory, StampedHistory
from tdcm_ros.nodes.frames import FRAME_PREFIX_SPECS, declare_frame_prefix, robot_frame
from tdcm_ros.nodes.metrics_node import (
    LAYOUT_SPECS,
    PRESET_SPECS,
    declare_design_and_layout,
    marker_rows,
)
from tdcm_ros.nodes.shape_messages import stamp_ns_of
from tdcm_ros.runtime import (
    DiagnosticLevel,
    Diagnostics,
    NodeLogic,
    NodePort,
    QoS,
    Status,
    Timer,
    declare_specs,
    grouped,
    overridable_qos,
)
from tdcm_ros.runtime.param_client import ParameterClient
from tdcm_ros.runtime.run_node import main_for
from tdcm_ros.spec import Spec, by_name

#: Parameters fixed at start, besides the design and the marker layout.
FIXED_SPECS = by_name(
    Spec("driver", description="node whose parameters give the limits (tension_max, "
         "setpoint_rate, roll_max, roll_rate); relative to the namespace", kind="str",
         default="tension_driver"),
    Spec("base_frame", description="frame targets are resolved to", default="tdcm_base",
         kind="str"),
    Spec("roll.joint", description="joint of joint_states that is the roll", default="roll",
         kind="str"),
    Spec("period_s", "s", "control period (setpoints are slewed by the time since the last "
         "tick, at most 10 periods)", 0.05,
         low=0.005, high=1.0),
    Spec("keepalive_s", "s", "setpoints are sent again after this long unchanged", 1.0,
         low=0.05, high=60.0),
    Spec("limits_period_s", "s", "period of reading the driver's limits", 5.0, low=0.1,
         high=3600.0),
    Spec("diagnostics_period_s", "s", "diagnostics period", 1.0, low=0.05, high=60.0),
    Spec("target_tolerance_m", "m", "largest distance of a point target from the reachable "
         "tip path", 5e-4, low=0.0, low_open=True, high=0.05),
    Spec("adapt_min_n", "N", "smallest measured tension at which the gain adapts", 0.5,
         low=0.0, high=100.0),
    Spec("gain.initial", "", "prior of g = E_model / E_world", 1.0, low=0.01, high=100.0),
    Spec("gain.initial_std", "", "prior standard deviation of g", 0.3, low=0.0, low_open=True,
         high=100.0),
    Spec("gain.process_std", "1/sqrt(s)", "random walk of g (how fast it may drift)", 0.01,
         low=0.0, high=10.0),
    Spec("gain.noise_m", "m", "measurement noise of the tip, per coordinate", 2e-4, low=0.0,
         low_open=True, high=0.05),
    Spec("gain.min", "", "lower bound of g", 0.2, low=0.01, high=100.0),
    Spec("gain.max", "", "upper bound of g", 5.0, low=0.01, high=100.0))
#: Parameters a client may change at run time.
TUNABLE_SPECS = by_name(
    Spec("mode", description="feedforward (g frozen) or feedback (g adapts from the markers); "
         "changeable at run time", default="feedback", kind="str", choices=MODES),
    Spec("measurement_timeout_s", "s", "a tension or measured tip older than this is stale "
         "(feedback falls back to feed-forward); changeable at run time", 0.5, low=0.01,
         high=3600.0))
#: Every parameter of the node by full name, as declared below.
PARAMETERS = {**grouped(PRESET_SPECS), **grouped(PARAMETER_SPECS, "design."),
              **grouped(LAYOUT_SPECS, "markers."), **grouped(FIXED_SPECS),
              **grouped(FRAME_PREFIX_SPECS), **grouped(TUNABLE_SPECS)}
#: How long the tendon must read released while commanded before diagnostics say so (s).
RELEASED_AFTER_S = 1.0
#: Tension and roll samples kept by stamp for the marker frames (seconds at 500 Hz).
HISTORY = 2048
#: Marker frames kept waiting for the tension of their stamp (the oldest go first).
WAITING_FRAMES = 1024
#: A control tick later than its period slews by the time since the last one (late ticks are
#: skipped, as rcl's timers do, so a fixed step would slew slower than the driver's rates), but
#: by at most this many periods: a node stalled for seconds does not command a jump (the driver
#: ramps its setpoint at ``setpoint_rate`` besides).
LATE_STEPS_COUNTED = 10
NEVER = -(1 << 62)


def _stamp(ns: int) -> dict[str, int]:
    return {"sec": ns // 10**9, "nanosec": ns % 10**9}


def _xyz(point: tuple[float, float, float]) -> dict[str, float]:
    return dict(zip("xyz", point, strict=True))


class WaitingFrame(NamedTuple):
    """A marker frame waiting for the tension of its stamp: ``taken_ns`` (its stamp),
    ``rows`` (k, 3) in ``base_frame`` (m), its message ``header``, ``arrived_ns`` (node clock)."""

    taken_ns: int
    rows: np.ndarray
    header: dict[str, Any]
    arrived_ns: int


def driver_name(namespace: str, driver: str) -> str:
    """The driver's fully qualified name: ``driver`` if absolute, else under ``namespace``."""
    if driver.startswith("/"):
        return driver
    return f"{namespace.rstrip('/')}/{driver}"


class LimitsReader:
    """Reads the driver's limits through its parameter services on a thread of its own (a
    service call blocks), at start and every ``period_s`` (every ``min(period_s, 1)`` s while
    unread); ``limits`` is ``None`` until read, ``problem`` says why not.

    With ``on_timer`` it reads at start and then on a timer of the port instead of a thread:
    only for a port whose service calls return at once (:class:`MemoryPort`), where it is then
    deterministic on the port's clock."""

    def __init__(self, port: NodePort, driver_fqn: str, period_s: float, *,
                 on_timer: bool = False) -> None:
        self.client = ParameterClient(port, driver_fqn, timeout=min(period_s, 2.0))
        self.driver, self.period_s, self.port = driver_fqn, period_s, port
        self.limits: DriverLimits | None = None
        self.problem = f"not read from {driver_fqn} yet"
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._timer: Timer | None = None
        if on_timer:
            self._next_ns = port.now_ns() + round(self.read() * 1e9)
            self._timer = port.create_timer(min(period_s, 1.0), self._tick)
        else:
            self._thread = threading.Thread(target=self._run, name="driver-limits", daemon=True)
            self._thread.start()

    def read(self) -> float:
        """Read the limits once; the time (s) until the next read."""
        try:
            values = self.client.get_values(list(DRIVER_LIMIT_NAMES))
            self.limits, self.problem = DriverLimits.from_values(values), ""
        except TdcmError as error:
            self.problem = f"cannot read {self.driver}'s limits: {error}"
        return self.period_s if self.limits else min(self.period_s, 1.0)

    def _run(self) -> None:
        while not self._stop.wait(self.read()):
            pass

    def _tick(self) -> None:
        if self.port.now_ns() >= self._next_ns:
            self._next_ns = self.port.now_ns() + round(self.read() * 1e9)

    def close(self) -> None:
        """Stop reading (waits for a call under way)."""
        self._stop.set()
        if self._timer is not None:
            self._timer.cancel()
        if self._thread is not None:
            self._thread.join(timeout=3.0)


class ShapeControllerNode(NodeLogic):
    """See the module docstring."""

    default_name = "shape_controller"

    def __init__(self, port: NodePort, *, limits_on_timer: bool = False) -> None:
        """``limits_on_timer``: read the driver's limits on the port's timer, not a thread
        (see :class:`LimitsReader`; for a :class:`MemoryPort` only)."""
        super().__init__(port)
        # the controller's model is frictionless: a model file's friction is not used here
        design, layout, _ = declare_design_and_layout(port, "shape_controller")
        fixed = declare_specs(port, FIXED_SPECS, read_only=True)
        declare_specs(port, TUNABLE_SPECS)
        gain = GainSettings(float(fixed["gain.initial"]), float(fixed["gain.initial_std"]),
                            float(fixed["gain.process_std"]), float(fixed["gain.noise_m"]),
                            (float(fixed["gain.min"]), float(fixed["gain.max"])))
        self.core = ShapeController(design, layout, gain=gain,
                                    tolerance_m=float(fixed["target_tolerance_m"]),
                                    adapt_min_n=float(fixed["adapt_min_n"]))
        self.base_frame = robot_frame(declare_frame_prefix(port), str(fixed["base_frame"]))
        self.roll_joint = str(fixed["roll.joint"])
        self.period_s, self.keepalive_s = float(fixed["period_s"]), float(fixed["keepalive_s"])
        self.index = {label: i for i, label in enumerate(layout.labels)}
        self.tf = TransformBuffer()
        self.counts: Counter[str] = Counter()
        self.last_ns: dict[str, int] = {}
        self.tension_n = 0.0
        self.roll_rad = 0.0  # measured; 0 until joint_states names the roll joint
        # by their stamps, so a marker frame meets the tension and roll of its own instant
        self.tensions, self.rolls = StampedHistory(HISTORY), RollHistory(HISTORY)
        self.waiting: deque[WaitingFrame] = deque()
        self.command: tuple[float, float] | None = None
        self.slewed_ns: int | None = None  # the clock at the last slew
        self.sent: tuple[float, float, int] | None = None  # tension, roll, when
        self.released_since_ns: int | None = None
        self.refusal = ""
        qos = QoS(depth=10)
        self.setpoint = port.create_publisher("tension_setpoint", "std_msgs/msg/Float64", qos)
        self.roll_setpoint = port.create_publisher("roll_setpoint", "std_msgs/msg/Float64", qos)
        point = "geometry_msgs/msg/PointStamped"
        self.target_tip = port.create_publisher("controller/target_tip", point,
                                                QoS(depth=1, durability="transient_local"))
        self.measured_tip = port.create_publisher("controller/measured_tip", point, qos)
        self.predicted_tip = port.create_publisher("controller/predicted_tip", point, qos)
        self.tracking_error = port.create_publisher("controller/tracking_error",
                                                    "geometry_msgs/msg/Vector3Stamped", qos)
        self.gain = port.create_publisher("controller/gain", "std_msgs/msg/Float64", qos)
        self.gain_std = port.create_publisher("controller/gain_std", "std_msgs/msg/Float64", qos)
        port.create_subscription("target_point", point, self._on_target_point, qos)
        port.create_subscription("target_angle", "std_msgs/msg/Float64", self._on_target_angle,
                                 qos)
        port.create_subscription("markers", "mocap4r2_msgs/msg/Markers", self._on_markers,
                                 overridable_qos(port, "markers", QoS(depth=10)))
        port.create_subscription("tension", "geometry_msgs/msg/WrenchStamped", self._on_tension,
                                 overridable_qos(port, "tension", QoS(depth=100)))
        port.create_subscription("joint_states", "sensor_msgs/msg/JointState",
                                 self._on_joint_states,
                                 overridable_qos(port, "joint_states", QoS(depth=10)))
        port.create_subscription("/tf", "tf2_msgs/msg/TFMessage", self._on_tf, QoS(depth=100))
        port.create_subscription("/tf_static", "tf2_msgs/msg/TFMessage", self._on_tf_static,
                                 QoS(depth=10, durability="transient_local"))
        self.limits = LimitsReader(port, driver_name(port.namespace, str(fixed["driver"])),
                                   float(fixed["limits_period_s"]), on_timer=limits_on_timer)
        port.create_timer(self.period_s, self.step)
        self.diagnostics = Diagnostics(port, float(fixed["diagnostics_period_s"]))
        self.diagnostics.add("controller", "tdcm_controller", self.check)

    # --- inputs -----------------------------------------------------------------------------
    def _fresh(self, name: str) -> bool:
        timeout_s = float(self.port.get_parameter("measurement_timeout_s"))
        return self.port.now_ns() - self.last_ns.get(name, NEVER) <= timeout_s * 1e9

    def _on_tension(self, message: Any) -> None:
        value = float(message.wrench.force.z)
        if not math.isfinite(value):
            self.counts["tension_non_finite"] += 1
            return
        self.counts["tension"] += 1
        self.tension_n, self.last_ns["tension"] = value, self.port.now_ns()
        self.tensions.add(stamp_ns_of(message) or self.last_ns["tension"], value)
        self._pair_waiting()

    def _on_joint_states(self, message: Any) -> None:
        names = list(message.name)
        if self.roll_joint not in names:
            return
        i = names.index(self.roll_joint)
        value = float(message.position[i]) if i < len(message.position) else math.nan
        if not math.isfinite(value):
            self.counts["roll_non_finite"] += 1
            return
        self.roll_rad, self.last_ns["roll"] = value, self.port.now_ns()
        self.rolls.add(stamp_ns_of(message) or self.last_ns["roll"], value)
        self._pair_waiting()

    def _on_tf(self, message: Any) -> None:
        self._add_transforms(message, static=False)

    def _on_tf_static(self, message: Any) -> None:
        self._add_transforms(message, static=True)

    def _add_transforms(self, message: Any, *, static: bool) -> None:
        for problem in self.tf.add_message(message, static=static):
            self.counts["tf_rejected"] += 1
            self.port.logger.warning("transform ignored: %s", problem)

    def _refuse(self, what: str, error: TdcmError) -> None:
        self.counts["targets_refused"] += 1
        self.refusal = f"{what} refused: {error}"
        self.last_ns["refusal"] = self.port.now_ns()
        self.port.logger.warning("%s", self.refusal)

    def _current_roll(self) -> float:
        return self.command[1] if self.command is not None else self.roll_rad

    def _set_target(self, what: str, make: Callable[[DriverLimits], PlaneTarget]) -> None:
        limits = self.limits.limits
        if limits is None:
            self.counts["targets_refused"] += 1
            self.refusal = f"{what} refused: driver limits unknown ({self.limits.problem})"
            self.port.logger.warning("%s", self.refusal)
            return
        try:
            resolved = self.core.resolve(make(limits), limits)
        except TdcmError as error:
            self._refuse(what, error)
            return
        self.counts["targets"] += 1
        self.target_tip.publish(from_dict("geometry_msgs/msg/PointStamped", {
            "header": {"stamp": _stamp(self.port.now_ns()), "frame_id": self.base_frame},
            "point": _xyz(resolved.tip_base)}))

    def _on_target_point(self, message: Any) -> None:
        p = message.point
        shown = f"target_point ({p.x:g}, {p.y:g}, {p.z:g}) m in {message.header.frame_id!r}"

        def make(limits: DriverLimits) -> PlaneTarget:
            to_base = self.tf.lookup(message.header.frame_id or self.base_frame, self.base_frame,
                                     None)
            x, y, z = (float(v) for v in to_base.to_base([p.x, p.y, p.z]))
            return point_target((x, y, z), self._current_roll(), limits.roll_max)

        self._set_target(shown, make)

    def _on_target_angle(self, message: Any) -> None:
        angle = float(message.data)
        self._set_target(f"target_angle {angle:g} rad",
                         lambda _limits: angle_target(angle, self._current_roll()))

    def _on_markers(self, message: Any) -> None:
        self.counts["marker_frames"] += 1
        if not self._fresh("tension"):
            self.counts["markers_without_tension"] += 1
            return
        try:
            registration = self.tf.lookup(message.header.frame_id, self.base_frame, None)
        except TdcmError:
            self.counts["markers_without_registration"] += 1
            return
        rows, ignored = marker_rows(message, self.index)
        if ignored:
            self.counts["markers_ignored"] += ignored
        now = self.port.now_ns()
        header = {"stamp": {"sec": int(message.header.stamp.sec),
                            "nanosec": int(message.header.stamp.nanosec)},
                  "frame_id": self.base_frame}
        taken = stamp_ns_of(message) or now  # the frame's instant: the bench's state then
        if len(self.waiting) == WAITING_FRAMES:
            self._drop_oldest_waiting()
        self.waiting.append(WaitingFrame(taken, registration.to_base(rows), header, now))
        self._pair_waiting()

    def _paired(self, taken_ns: int) -> bool:
        """Whether the tension (and the roll, unless stale) of the instant ``taken_ns`` are
        known: a sample stamped at or after it has arrived."""
        newest = self.tensions.newest_stamp
        if newest is None or newest < taken_ns:
            return False
        newest_roll = self.rolls.newest_stamp
        return newest_roll is None or newest_roll >= taken_ns or not self._fresh("roll")

    def _pair_waiting(self) -> None:
        """Observe the waiting frames whose tension has arrived, oldest first; drop the ones
        that waited longer than ``measurement_timeout_s``."""
        if not self.waiting:  # the usual case, on every tension: read no parameter
            return
        timeout_ns = float(self.port.get_parameter("measurement_timeout_s")) * 1e9
        while self.waiting:
            frame = self.waiting[0]
            if self._paired(frame.taken_ns):
                self.waiting.popleft()
                self._observe(frame)
            elif self.port.now_ns() - frame.arrived_ns > timeout_ns:
                self._drop_oldest_waiting()
            else:
                return

    def _drop_oldest_waiting(self) -> None:
        """Drop the oldest waiting frame: its tension has not come; counted and said."""
        self.waiting.popleft()
        self.counts["markers_tension_late"] += 1
        self.last_ns["tension_late"] = self.port.now_ns()

    def _observe(self, frame: WaitingFrame) -> None:
        now = self.port.now_ns()
        dt_s = (now - self.last_ns.get("observed", now)) * 1e-9
        adapt = str(self.port.get_parameter("mode")) == "feedback"
        try:
            observation = self.core.observe(self.tensions.at(frame.taken_ns),
                                            self.rolls.at(frame.taken_ns), frame.rows, dt_s,
                                            adapt=adapt)
        except TdcmError as error:  # a tension past a model limit: no prediction for it
            self.counts[f"model_{error.kind}"] += 1
            return
        self.last_ns["observed"] = now
        header = frame.header
        self._publish_point(self.predicted_tip, header, observation.predicted)
        if observation.adapted:
            self.counts["adapted"] += 1
        if observation.measured is not None:
            self.last_ns["measured"] = now
            self._publish_point(self.measured_tip, header, observation.measured)
            target = self.core.target
            if target is not None:
                offset = (m - t for m, t in zip(observation.measured, target.tip_base,
                                                strict=True))
                self.tracking_error.publish(from_dict("geometry_msgs/msg/Vector3Stamped", {
                    "header": header, "vector": dict(zip("xyz", offset, strict=True))}))
        estimator = self.core.estimator
        self.gain.publish(from_dict("std_msgs/msg/Float64", {"data": estimator.gain}))
        self.gain_std.publish(from_dict("std_msgs/msg/Float64", {"data": estimator.std}))

    @staticmethod
    def _publish_point(publisher: Any, header: dict[str, Any],
                       point: tuple[float, float, float]) -> None:
        publisher.publish(from_dict("geometry_msgs/msg/PointStamped",
                                    {"header": header, "point": _xyz(point)}))

    # --- output -----------------------------------------------------------------------------
    def step(self) -> None:
        """Slew the command toward the target's goal within the driver's limits; send it."""
        self._pair_waiting()  # drops the frames whose tension never came
        limits = self.limits.limits
        goal = self.core.goal(limits) if limits is not None else None
        self._watch_release()
        if limits is None or goal is None:
            return
        if self.command is None:
            start = self.tension_n if self._fresh("tension") else 0.0
            self.command = (min(max(start, 0.0), limits.tension_max), self.roll_rad)
        now = self.port.now_ns()
        step_s = self.period_s if self.slewed_ns is None else min(
            (now - self.slewed_ns) * 1e-9, LATE_STEPS_COUNTED * self.period_s)
        self.slewed_ns = now
        tension = slew(self.command[0], goal[0], limits.setpoint_rate, step_s)
        roll = slew(self.command[1], goal[1], limits.roll_rate, step_s)
        self.command = (tension, roll)
        if (self.sent is not None and (self.sent[0], self.sent[1]) == self.command
                and now - self.sent[2] < self.keepalive_s * 1e9):
            return
        self.setpoint.publish(from_dict("std_msgs/msg/Float64", {"data": tension}))
        self.roll_setpoint.publish(from_dict("std_msgs/msg/Float64", {"data": roll}))
        self.sent = (tension, roll, now)
        self.counts["setpoints"] += 1

    def _watch_release(self) -> None:
        commanded = self.command is not None and self.command[0] >= 2.0 * self.core.adapt_min_n
        released = commanded and self.tension_n < self.core.adapt_min_n
        if not released:
            self.released_since_ns = None
        elif self.released_since_ns is None:
            self.released_since_ns = self.port.now_ns()

    def check(self) -> Status:
        """WARN while commanding nothing (no driver limits), falling back to feed-forward, the
        tendon reads released while commanded, or a target was refused lately; else OK."""
        now = self.port.now_ns()
        mode = str(self.port.get_parameter("mode"))
        timeout_s = float(self.port.get_parameter("measurement_timeout_s"))
        estimator = self.core.estimator
        problems = []
        if self.limits.limits is None:
            problems.append(f"commanding nothing: driver limits unknown ({self.limits.problem})")
        if mode == "feedback" and not self._fresh("measured"):
            problems.append(f"no measured tip for more than {timeout_s:g} s (markers, tension "
                            f"or the registration missing): feed-forward with the last gain "
                            f"{estimator.gain:.4g}")
        if now - self.last_ns.get("tension_late", NEVER) < 5 * self.diagnostics.period_s * 1e9:
            problems.append(f"marker frames dropped: no tension stamped at or after them within "
                            f"{timeout_s:g} s (the tension late, or stamped on another clock)")
        if (self.released_since_ns is not None
                and now - self.released_since_ns > RELEASED_AFTER_S * 1e9):
            problems.append(f"tendon released ({self.tension_n:.3g} N measured, "
                            f"{self.command[0] if self.command else 0.0:.3g} N commanded): the "
                            "driver's safety rules are in charge (fault or disarmed; arm it "
                            "with clear_faults); the gain does not adapt")
        if now - self.last_ns.get("refusal", NEVER) < 5 * self.diagnostics.period_s * 1e9:
            problems.append(self.refusal)
        target = self.core.target
        values: dict[str, object] = {
            **dict(sorted(self.counts.items())), "mode": mode,
            "gain": f"{estimator.gain:.6g}", "gain_std": f"{estimator.std:.3g}",
            "target_tip": "none" if target is None else
            "(" + ", ".join(f"{v:.6g}" for v in target.tip_base) + ") m",
            "command": "none" if self.command is None else
            f"{self.command[0]:.4g} N, {self.command[1]:.4g} rad"}
        if self.limits.limits is not None:
            values.update({name: getattr(self.limits.limits, name)
                           for name in DRIVER_LIMIT_NAMES})
        if problems:
            return Status(DiagnosticLevel.WARN, "; ".join(problems), values)
        return Status(DiagnosticLevel.OK, f"{mode}" + ("" if target else ": no target yet"),
                      values)

    def close(self) -> None:
        """Stop reading the driver's limits."""
        self.limits.close()


def main() -> int:
    """``ros2 run tdcm_ros shape_controller`` / ``tdcm_shape_controller`` console script."""
    return main_for(ShapeControllerNode)


if __name__ == "__main__":
    sys.exit(main())
