"""Test-side port for the tension nodes: publishes setpoints and e-stops, calls the driver's
command services, collects what the nodes publish."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

from tdcm_ros.bagio import from_dict
from tdcm_ros.runtime.diagnostics import summary
from test.support.waiting import eventually

REPO = Path(__file__).resolve().parents[2]
DRIVER = "tdcm_ros.nodes.tension_driver:TensionDriverNode"
TWIN = "tdcm_ros.nodes.device_twin:DeviceTwinNode"
#: The driver's hardware components on ``/diagnostics``.
DRIVER_COMPONENTS = ("tension_driver: serial link", "tension_driver: load cell",
                     "tension_driver: actuator")


def stamp_ns(message: Any) -> int:
    return int(message.header.stamp.sec) * 1_000_000_000 + int(message.header.stamp.nanosec)


def level(status: Any) -> int:
    """``DiagnosticStatus.level`` as an int (rosidl's Python type for ``byte`` is ``bytes``)."""
    raw = status.level
    return int.from_bytes(raw, "little") if isinstance(raw, bytes) else int(raw)


def values(status: Any) -> dict[str, str]:
    """``DiagnosticStatus.values`` as a dict."""
    return {kv.key: kv.value for kv in status.values}


def driver_params(path: Path, **changes: Any) -> str:
    """``config/tension_driver.yaml`` with ``changes`` (dotted names) applied, written to ``path``."""
    data = yaml.safe_load((REPO / "config" / "tension_driver.yaml").read_text())
    (node_key,) = data  # /**/tension_driver: the node in any namespace
    params = data[node_key]["ros__parameters"]
    for name, value in changes.items():
        *parents, leaf = name.split(".")
        node = params
        for key in parents:
            node = node.setdefault(key, {})
        node[leaf] = value
    path.write_text(yaml.safe_dump(data))
    return str(path)


class Probe:
    """Publishes setpoints/e-stops, calls command services; records ``tension``, ``device_state``, ``/diagnostics``,
    ``sim/tension_true`` and ``midline``."""

    def __init__(self, ctx: Any) -> None:
        self.ctx = ctx
        port = ctx.create_port("probe")
        self.tension: list[Any] = []
        self.states: list[Any] = []
        self.diagnostics: list[Any] = []
        self.components: list[dict[str, Any]] = []
        self.truth: list[Any] = []
        self.midlines: list[Any] = []
        port.create_subscription("tension", "geometry_msgs/msg/WrenchStamped", self.tension.append)
        port.create_subscription("device_state", "diagnostic_msgs/msg/DiagnosticStatus",
                                 self.states.append)
        port.create_subscription("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                                 self._on_diagnostics)
        port.create_subscription("sim/tension_true", "geometry_msgs/msg/WrenchStamped",
                                 self.truth.append)
        port.create_subscription("midline", "nav_msgs/msg/Path", self.midlines.append)
        self._setpoint = port.create_publisher("tension_setpoint", "std_msgs/msg/Float64")
        self._estop = port.create_publisher("estop", "std_msgs/msg/Empty")

    def _on_diagnostics(self, array: Any) -> None:
        """Keep the driver's component statuses of each array rolled into one, as
        ``device_state`` and diagnostic_aggregator roll them up."""
        parts = [{"level": level(s), "message": s.message,
                  "values": [{"key": kv.key, "value": kv.value} for kv in s.values]}
                 for s in array.status if s.name in DRIVER_COMPONENTS]
        if parts:
            self.components.append({s.name: s for s in array.status
                                    if s.name in DRIVER_COMPONENTS})
            self.diagnostics.append(from_dict("diagnostic_msgs/msg/DiagnosticStatus",
                                              summary(parts, "tension_driver", "")))

    def setpoint(self, newtons: float) -> None:
        self._setpoint.publish(from_dict("std_msgs/msg/Float64", {"data": newtons}))

    def estop(self) -> None:
        self._estop.publish(from_dict("std_msgs/msg/Empty", {}))

    def call(self, command: str, timeout: float = 10.0) -> Any:
        """Call the driver's ``std_srvs/srv/Trigger`` service ``command``; its response."""
        return self.ctx.call_service(f"/tension_driver/{command}", "std_srvs/srv/Trigger",
                                     timeout=timeout)

    def clear_faults(self) -> None:
        self.call("clear_faults")

    def component(self, name: str) -> Any:
        """The newest ``/diagnostics`` status of driver component ``name`` (None before)."""
        return self.components[-1].get(f"tension_driver: {name}") if self.components else None

    def component_level(self, name: str) -> int:
        """Its level (-1 before the first)."""
        status = self.component(name)
        return -1 if status is None else level(status)

    def state(self) -> dict[str, str]:
        """Values of the newest ``device_state`` (empty before the first)."""
        return values(self.states[-1]) if self.states else {}

    def until(self, predicate: Callable[[], bool], timeout: float, what: str,
              action: Callable[[], None] | None = None) -> None:
        """Spin until ``predicate`` (:func:`eventually`, ``timeout`` scaled); ``action`` (e.g. a
        publish) runs first and every 0.3 s meanwhile."""
        eventually(predicate, timeout, what, spin=self.ctx, action=action,
                   detail=lambda: f"last state {self.state()}")

    def hold(self, reached: Callable[[], bool], newtons: float, timeout: float = 15.0) -> None:
        """Until ``reached()``, publishing setpoint ``newtons`` and, whenever the device reports
        a latched fault, calling ``clear_faults`` first, as an operator would: on a loaded
        machine a driver process not scheduled for 0.5 s trips the device's watchdog (the
        device failing safe, not what the callers test)."""
        def ask() -> None:
            if self.state().get("faults"):
                self.clear_faults()
            self.setpoint(newtons)

        self.until(reached, timeout, f"{newtons:g} N on the tendon", action=ask)

    def connected(self, mode: str = "tension", timeout: float = 30.0,
                  action: Callable[[], None] | None = None) -> None:
        """Until the driver reports the link up with the device in ``mode`` (``action`` as in
        :meth:`until`)."""
        self.until(lambda: self.state().get("link") == "connected"
                   and self.state().get("mode") == mode, timeout, f"connected in mode {mode}",
                   action)
