"""``metrics_node``: live Table I metrics of the model against motion capture.

Subscribes ``tension`` (geometry_msgs/msg/WrenchStamped, ``wrench.force.z`` in N), ``markers``
(mocap4r2_msgs/msg/Markers, frame ``mocap``, labels ``markers.labels``) and ``/tf_static``
(tf2_msgs/msg/TFMessage, transient local: the ``mocap`` -> ``tdcm_base`` transform).

Publishes (frame ``tdcm_base``, SI units):

- ``metrics/marker_errors`` (mocap4r2_msgs/msg/Markers): per marker frame, each visible
  marker's measured minus predicted position (m; the model at the tension nearest the frame's
  stamp within ``align.tolerance_s``), same labels and stamp as the input;
- ``metrics/tip_error`` (geometry_msgs/msg/Vector3Stamped): the same vector for the tip marker;
- ``metrics/table`` (std_msgs/msg/String): JSON of the running Table I and the finished steps,
  the ``tdcm evaluate --json`` layout, after each finished step;
- ``metrics/mape_pct``, ``metrics/rmse_m``, ``metrics/mae_m``, ``metrics/shape_error_m``,
  ``metrics/deflection_mean_m`` (std_msgs/msg/Float64): the running values, once defined;
- ``/diagnostics``: WARN when no tension or no markers arrived for ``stale_s``, or no
  registration is known yet; counters.

Registration (``registration.source``): ``auto`` (``/tf_static`` when it arrives, else estimated
from a zero-tension and the largest-tension step), ``tf_static``, ``parameter``
(``registration.translation`` m, ``registration.rotation`` quaternion x, y, z, w) or
``estimate``.
"""

from __future__ import annotations

import json
import math
import sys
from collections import Counter
from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict, msg_class
from tdcm_ros.errors import InputError
from tdcm_ros.metrics.evaluation import Evaluation
from tdcm_ros.metrics.geometry import DEFLECTION_AXES, MarkerLayout
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.registration import Registration
from tdcm_ros.metrics.steps import StepSettings
from tdcm_ros.metrics.streaming import RunningEvaluation
from tdcm_ros.model import FIELD_SPECS, preset
from tdcm_ros.model.design import PRESETS
from tdcm_ros.nodes.shape_messages import header
from tdcm_ros.runtime.parameters import one_of
from tdcm_ros.runtime.port import NodeLogic, NodePort, QoS
from tdcm_ros.runtime.run_node import main_for

REGISTRATION_SOURCES = ("auto", "tf_static", "parameter", "estimate")
TABLE_TOPICS = ("mape_pct", "rmse_m", "mae_m", "shape_error_m", "deflection_mean_m")
BASE_FRAME = "tdcm_base"


def _stamp_s(message: Any) -> float:
    return int(message.header.stamp.sec) + int(message.header.stamp.nanosec) * 1e-9


class MetricsNode(NodeLogic):
    """Per-sample errors and running Table I; see the module docstring."""

    default_name = "metrics_node"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        self.options = self._options()
        declare = port.declare_parameter
        self.source = str(declare("registration.source", "auto", read_only=True,
                                  description="auto, tf_static, parameter or estimate",
                                  validator=one_of("registration.source",
                                                    REGISTRATION_SOURCES)))
        translation = declare("registration.translation", [0.0, 0.0, 0.0], read_only=True,
                              description="tdcm_base origin in mocap (m), source=parameter")
        rotation = declare("registration.rotation", [0.0, 0.0, 0.0, 1.0], read_only=True,
                           description="tdcm_base orientation in mocap (x, y, z, w)")
        declare("stale_s", 1.0, range=(0.01, 3600.0),
                description="inputs older than this are stale (s); changeable at run time")
        update_s = float(declare("update_period_s", 0.5, range=(0.01, 60.0), read_only=True,
                                 description="period of step detection (s)"))
        diag_s = float(declare("diagnostics_period_s", 1.0, range=(0.05, 60.0), read_only=True,
                               description="diagnostics period (s)"))
        buffer_s = float(declare("max_buffer_s", 120.0, range=(1.0, 3600.0), read_only=True,
                                 description="longest buffered stretch without a step (s)"))
        given = None
        if self.source == "parameter":
            given = Registration(tuple(translation), tuple(rotation), method="parameter")
        self.running = RunningEvaluation(self.options, given, max_buffer_s=buffer_s,
                                         estimate=self.source in ("auto", "estimate"))
        qos = QoS(depth=10)
        self.marker_errors = port.create_publisher("metrics/marker_errors",
                                                   "mocap4r2_msgs/msg/Markers", qos)
        self.tip_error = port.create_publisher("metrics/tip_error",
                                               "geometry_msgs/msg/Vector3Stamped", qos)
        self.table = port.create_publisher("metrics/table", "std_msgs/msg/String",
                                           QoS(depth=1, durability="transient_local"))
        self.values = {name: port.create_publisher(f"metrics/{name}", "std_msgs/msg/Float64",
                                                   qos) for name in TABLE_TOPICS}
        self.diagnostics = port.create_publisher("/diagnostics",
                                                 "diagnostic_msgs/msg/DiagnosticArray", qos)
        port.create_subscription("tension", "geometry_msgs/msg/WrenchStamped", self._on_tension,
                                 QoS(depth=1000))
        port.create_subscription("markers", "mocap4r2_msgs/msg/Markers", self._on_markers,
                                 QoS(depth=100))
        if self.source in ("auto", "tf_static"):
            port.create_subscription("/tf_static", "tf2_msgs/msg/TFMessage", self._on_tf,
                                     QoS(depth=10, durability="transient_local"))
        self.counts: Counter[str] = Counter()
        self.last_ns: dict[str, int] = {}
        self.index = {label: i for i, label in enumerate(self.options.layout.labels)}
        port.create_timer(update_s, self.update)
        port.create_timer(diag_s, self.report)

    def _options(self) -> EvaluateOptions:
        """Evaluation options from the (read-only) parameters; bad values raise InputError."""
        declare = self.port.declare_parameter
        name = str(declare("design.preset", "paper-experiment", read_only=True,
                           description="design preset the fields start from",
                           validator=one_of("design.preset", tuple(PRESETS))))
        base = preset(name)
        fields = {f: declare(f"design.{f}", getattr(base, f), read_only=True,
                             range=(spec.low, spec.high),
                             description=f"{spec.description} ({spec.unit or 'count'})")
                  for f, spec in FIELD_SPECS.items()}
        layout = MarkerLayout(
            labels=tuple(declare("markers.labels", ["m1", "m2", "m3"], read_only=True,
                                 description="marker labels, base to tip")),
            arc_lengths=tuple(declare("markers.arc_lengths", [0.015, 0.033, 0.053],
                                      read_only=True, description="marker arc lengths (m)")),
            ball_radius=float(declare("markers.radius", 0.001, range=(0.0, 0.05),
                                      read_only=True, description="marker ball radius (m)")),
            side_deg=float(declare("markers.side_deg", 180.0, range=(-360.0, 360.0),
                                   read_only=True, description="marker side (deg)")))
        defaults = StepSettings()
        steps = StepSettings(**{
            f: declare(f"steps.{f}", getattr(defaults, f), read_only=True,
                       description=f"step detection: {f}")
            for f in ("tolerance_n", "min_hold_s", "settle_s", "zero_n", "despike_samples")})
        return EvaluateOptions(
            design=base.with_overrides(**fields), steps=steps, layout=layout,
            align_tolerance_s=float(declare("align.tolerance_s", 0.02, range=(0.0, 10.0),
                                            read_only=True,
                                            description="nearest-stamp tolerance (s)")),
            mape_threshold_m=float(declare("mape_threshold_m", 1e-3, range=(1e-9, 1.0),
                                           read_only=True,
                                           description="MAPE leaves out smaller deflections (m)")),
            stations=int(declare("stations", 50, range=(2, 10_000), read_only=True,
                                 description="arc-length stations of the shape error")),
            deflection_axis=str(declare("deflection_axis", "marker", read_only=True,
                                        description="marker or body",
                                        validator=one_of("deflection_axis", DEFLECTION_AXES))))

    def _on_tension(self, message: Any) -> None:
        value = float(message.wrench.force.z)
        if not math.isfinite(value):
            self.counts["tension_non_finite"] += 1
            return
        self.counts["tension"] += 1
        self.last_ns["tension"] = self.port.now_ns()
        self.running.add_tension(_stamp_s(message), value)

    def _on_markers(self, message: Any) -> None:
        self.counts["marker_frames"] += 1
        self.last_ns["markers"] = self.port.now_ns()
        rows = np.full((len(self.index), 3), np.nan)
        for marker in message.markers:
            i = self.index.get(marker.marker_name)
            p = marker.translation
            if i is None or not all(math.isfinite(v) for v in (p.x, p.y, p.z)):
                self.counts["markers_ignored"] += 1
                continue
            rows[i] = (p.x, p.y, p.z)
        stamp = _stamp_s(message)
        self.running.add_markers(stamp, rows)
        errors = self.running.sample_errors(stamp, rows)
        if errors is None:
            self.counts["frames_without_error"] += 1
            return
        self._publish_errors(message, errors)

    def _publish_errors(self, message: Any, errors: np.ndarray) -> None:
        hdr = msg_class("std_msgs/msg/Header")(stamp=message.header.stamp, frame_id=BASE_FRAME)
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

    def _on_tf(self, message: Any) -> None:
        for tf in message.transforms:
            if tf.child_frame_id.lstrip("/") != BASE_FRAME:
                continue
            t, q = tf.transform.translation, tf.transform.rotation
            try:
                reg = Registration((t.x, t.y, t.z), (q.x, q.y, q.z, q.w), method="tf_static")
            except InputError as error:
                self.counts["tf_rejected"] += 1
                self.running.problem = f"/tf_static: {error}"
                continue
            self.counts["tf_static"] += 1
            self.running.set_registration(reg)

    def update(self) -> None:
        """Finish ended steps; publish the running table when a step finished."""
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

    def report(self) -> None:
        """``/diagnostics``: staleness, registration and counters."""
        now = self.port.now_ns()
        stale_s = float(self.port.get_parameter("stale_s"))
        problems = [f"no {name} for more than {stale_s:g} s"
                    for name in ("tension", "markers")
                    if now - self.last_ns.get(name, -(1 << 62)) > stale_s * 1e9]
        reg = self.running.used_registration
        if reg is None:
            problems.append("no registration yet (waiting for /tf_static or a zero-tension and "
                            "a bent step)")
        message = "; ".join(problems) or self.running.problem or "ok"
        values = {**{k: str(v) for k, v in sorted(self.counts.items())},
                  "registration": reg.method if reg else "none"}
        self.diagnostics.publish(from_dict("diagnostic_msgs/msg/DiagnosticArray", {
            "header": header(now, ""), "status": [{
                "level": 1 if problems else 0, "name": f"{self.port.node_name}: inputs",
                "message": message, "hardware_id": "tdcm_metrics",
                "values": [{"key": k, "value": v} for k, v in values.items()]}]}))


def main() -> int:
    """``ros2 run tdcm_ros metrics_node`` / ``metrics_node`` console script."""
    return main_for(MetricsNode)


if __name__ == "__main__":
    sys.exit(main())
