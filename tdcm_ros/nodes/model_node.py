"""``model_node``: tendon tension in, predicted midline out (Algorithm 1 on every new tension).

Subscribes ``tension`` (``geometry_msgs/msg/WrenchStamped``: the tension is ``wrench.force.z``
in N, in a frame whose z axis runs along the tendon toward the actuator; or
``std_msgs/msg/Float64`` in N, by the ``input.tension_type`` parameter). Publishes, stamped
with the input's stamp, in ``frame_id`` (default ``tdcm_base``): ``midline`` (nav_msgs/Path),
``midline_poses`` (PoseArray), ``tip_pose`` (PoseStamped), ``predicted_markers`` (PoseArray),
``body_markers`` (visualization_msgs/MarkerArray) and ``/diagnostics``.

Keep-latest: the subscription only stores the newest valid tension; a timer solves it, warm
started from the previous shape, so a burst never builds a queue (skipped inputs are counted
as coalesced). Bad inputs (non-finite, negative, above ``input.tension_max``, older than
``input.max_age_s``, stamped more than ``input.max_future_s`` ahead, or a WrenchStamped with a
zero stamp) and model limits are dropped, counted and reported on ``/diagnostics``.
"""

from __future__ import annotations

import math
import sys
from collections import Counter
from collections.abc import Mapping
from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError, PhysicsError
from tdcm_ros.model import FIELD_SPECS, SolveResult, SolverSettings, preset, solve
from tdcm_ros.model.design import PRESETS, Design
from tdcm_ros.nodes.shape_messages import header, midline_messages
from tdcm_ros.runtime.parameters import ParamValue, one_of
from tdcm_ros.runtime.port import NodeLogic, NodePort, QoS
from tdcm_ros.runtime.run_node import main_for

TENSION_TYPES = ("geometry_msgs/msg/WrenchStamped", "std_msgs/msg/Float64")
SOLVER_FIELDS: dict[str, ParamValue] = {"routing": "paper", "loads": "closed", "cells_per_notch": 4,
                 "cells_per_tube": 1, "quad_order": 4, "tol": 1e-10, "max_iter": 200}


class ModelNode(NodeLogic):
    """Predicts the midline for each new tension; see the module docstring."""

    default_name = "model_node"

    def __init__(self, port: NodePort) -> None:
        super().__init__(port)
        declare = port.declare_parameter
        self.tension_type = str(declare(
            "input.tension_type", TENSION_TYPES[0], read_only=True,
            description="message type on `tension`", validator=one_of("input.tension_type",
                                                                      TENSION_TYPES)))
        declare("frame_id", "tdcm_base", description="frame of all outputs")
        base_name = str(declare("design.preset", "paper-experiment", read_only=True,
                                description="design preset the fields start from",
                                validator=one_of("design.preset", tuple(PRESETS))))
        base = preset(base_name)
        for name, spec in FIELD_SPECS.items():
            declare(f"design.{name}", getattr(base, name), range=(spec.low, spec.high),
                    description=f"{spec.description} ({spec.unit or 'count'})")
        for name, default in SOLVER_FIELDS.items():
            declare(f"solver.{name}", default, description=f"SolverSettings.{name}")
        declare("output.samples", 54, range=(2, 10_000), description="poses along the midline")
        declare("markers.arc_lengths", [0.015, 0.033, 0.053],
                description="arc lengths (m) of the predicted markers")
        declare("markers.placement", "surface", description="surface or midline",
                validator=one_of("markers.placement", ("surface", "midline")))
        declare("markers.radius", 0.001, range=(0.0, 0.05), description="marker ball radius (m)")
        declare("markers.side_deg", 180.0, range=(-360.0, 360.0),
                description="marker side around the body z axis from the tendon side (deg)")
        declare("input.tension_max", 200.0, range=(0.0, 1e6), description="largest valid tension (N)")
        declare("input.max_age_s", 0.5, range=(0.0, 3600.0),
                description="inputs older than this are stale (s); 0 disables")
        declare("input.max_future_s", 0.5, range=(0.0, 3600.0),
                description="inputs stamped further ahead of the clock are dropped (s)")
        period = float(declare("process_period_s", 0.001, range=(1e-4, 1.0), read_only=True,
                               description="solver timer period (s)"))
        diag_period = float(declare("diagnostics_period_s", 1.0, range=(0.05, 60.0),
                                    read_only=True, description="diagnostics period (s)"))
        self.design, self.settings = self._config({})
        port.add_on_set_parameters(self._on_set)

        qos = QoS(depth=10)
        self.publishers = {topic: port.create_publisher(topic, type_name, qos) for topic, type_name
                           in (("midline", "nav_msgs/msg/Path"),
                               ("midline_poses", "geometry_msgs/msg/PoseArray"),
                               ("tip_pose", "geometry_msgs/msg/PoseStamped"),
                               ("predicted_markers", "geometry_msgs/msg/PoseArray"),
                               ("body_markers", "visualization_msgs/msg/MarkerArray"))}
        self.diagnostics = port.create_publisher("/diagnostics",
                                                 "diagnostic_msgs/msg/DiagnosticArray", qos)
        # A deep queue so every input is seen (and counted); the callback only stores the newest.
        port.create_subscription("tension", self.tension_type, self._on_tension, QoS(depth=100))
        self.pending: tuple[float, int] | None = None
        self.previous: SolveResult | None = None
        self.counts: Counter[str] = Counter()
        self.problems_reported = 0
        self.last_problem = ""
        port.create_timer(period, self.process)
        port.create_timer(diag_period, self.report)

    def _param(self, changes: Mapping[str, Any], name: str) -> Any:
        return changes[name] if name in changes else self.port.get_parameter(name)

    def _config(self, changes: Mapping[str, Any]) -> tuple[Design, SolverSettings]:
        """Design and settings from the current parameters with ``changes`` applied."""
        base = preset(str(self._param(changes, "design.preset")))
        design = base.with_overrides(**{name: self._param(changes, f"design.{name}")
                                        for name in FIELD_SPECS})
        settings = SolverSettings(**{name: self._param(changes, f"solver.{name}")
                                     for name in SOLVER_FIELDS})
        arcs = self._param(changes, "markers.arc_lengths")
        if not arcs or any(not 0.0 <= float(s) <= design.length for s in arcs):
            raise InputError(f"markers.arc_lengths = {arcs!r} out of range; allowed: values in "
                             f"[0, {design.length:g}] m", parameter="markers.arc_lengths",
                             value=arcs, allowed=f"[0, {design.length:g}] m")
        return design, settings

    def _on_set(self, changes: Mapping[str, Any]) -> None:
        """Validate a runtime change as a whole; raising keeps the old values."""
        self.design, self.settings = self._config(changes)
        self.previous = None

    def _on_tension(self, message: Any) -> None:
        """Store a valid tension (N) with its stamp (ns); an unstamped ``Float64`` takes the
        node's clock."""
        stamp_ns: int | None
        if self.tension_type == TENSION_TYPES[0]:
            tension = float(message.wrench.force.z)
            stamp_ns = int(message.header.stamp.sec) * 1_000_000_000 + int(
                message.header.stamp.nanosec)
        else:
            tension, stamp_ns = float(message.data), None
        now = self.port.now_ns()
        reason = self._reject_reason(tension, stamp_ns, now)
        if reason:
            self.counts[f"dropped_{reason}"] += 1
            self.last_problem = f"dropped tension {tension!r} N: {reason}"
            return
        if self.pending is not None:
            self.counts["coalesced"] += 1
        self.pending = (tension, now if stamp_ns is None else stamp_ns)

    def _reject_reason(self, tension: float, stamp_ns: int | None, now_ns: int) -> str:
        """Why a tension (N) stamped ``stamp_ns`` (ns; None: a type without a header) is
        dropped at ``now_ns``, or ``""``. A zero header stamp was never set: its age is
        unknown, so it is dropped as ``unstamped``."""
        if not math.isfinite(tension):
            return "non_finite"
        if tension < 0.0:
            return "negative"
        if tension > float(self.port.get_parameter("input.tension_max")):
            return "above_max"
        if stamp_ns is None:
            return ""
        if stamp_ns == 0:
            return "unstamped"
        if stamp_ns - now_ns > float(self.port.get_parameter("input.max_future_s")) * 1e9:
            return "future"
        max_age = float(self.port.get_parameter("input.max_age_s"))
        if max_age > 0.0 and now_ns - stamp_ns > max_age * 1e9:
            return "stale"
        return ""

    def process(self) -> None:
        """Solve the newest pending tension and publish the shape."""
        if self.pending is None:
            return
        tension, stamp_ns = self.pending
        self.pending = None
        try:
            result = solve(self.design, tension, settings=self.settings,
                           warm_start=self.previous)
        except (PhysicsError, InputError) as error:
            self.counts[f"model_{error.kind}"] += 1
            self.last_problem = f"tension {tension:g} N: {error}"
            return
        self.previous = result
        self.counts["solved"] += 1
        placement = self.port.get_parameter("markers.placement")
        radius = (self.design.R_outer + float(self.port.get_parameter("markers.radius"))
                  if placement == "surface" else 0.0)
        for topic, message in midline_messages(
                result, stamp_ns=stamp_ns, frame_id=str(self.port.get_parameter("frame_id")),
                samples=int(self.port.get_parameter("output.samples")),
                marker_s=np.asarray(self.port.get_parameter("markers.arc_lengths"), dtype=float),
                marker_radius=radius,
                marker_side_rad=math.radians(float(self.port.get_parameter("markers.side_deg")))):
            self.publishers[topic].publish(message)  # midline first: sent before the rest is built

    def report(self) -> None:
        """Publish the cumulative counters on ``/diagnostics``; the level is WARN, with the last
        problem as message, only if an input was dropped or failed since the previous report."""
        problems = sum(v for k, v in self.counts.items() if k.startswith(("dropped", "model")))
        recent = problems > self.problems_reported
        self.problems_reported = problems
        status = {
            "level": 1 if recent else 0,  # DiagnosticStatus WARN, OK
            "name": f"{self.port.node_name}: tension input",
            "message": self.last_problem if recent else "ok", "hardware_id": "tdcm_model",
            "values": [{"key": k, "value": str(v)} for k, v in sorted(self.counts.items())],
        }
        self.diagnostics.publish(from_dict("diagnostic_msgs/msg/DiagnosticArray", {
            "header": header(self.port.now_ns(), ""), "status": [status]}))


def main() -> int:
    """``ros2 run tdcm_ros model_node`` / ``model_node`` console script."""
    return main_for(ModelNode)


if __name__ == "__main__":
    sys.exit(main())
