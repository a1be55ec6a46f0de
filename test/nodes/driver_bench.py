"""``tension_driver`` in-process: the node on a :class:`MemoryPort`, joined by a
:class:`~tdcm_ros.device.loopback.Loopback` to a :class:`DeviceTwin`, both on one simulated clock.

:meth:`DriverBench.advance` moves time in 1 ms steps: the twin (firmware tick, plant, telemetry),
then the port (the node's 5 ms step timer, ``/diagnostics``, ``device_state``), so 2 s of the
bench cost milliseconds of CPU and every time is exact. The driver's clock is the port's, in s
since the bench was built; the twin's clock started at the same instant, so both read the same.
"""

from __future__ import annotations

import logging
from typing import Any

from tdcm_ros.bagio import from_dict
from tdcm_ros.device import Mode
from tdcm_ros.device.loopback import Loopback, LoopbackLink
from tdcm_ros.device.plant import PlantConfig
from tdcm_ros.device.twin import DeviceTwin
from tdcm_ros.nodes.tension_driver import TensionDriverNode
from tdcm_ros.runtime.memory_port import MemoryPort
from test.nodes.tension_probe import level, values

URL = "loop://twin"          #: the ``port`` parameter of the bench's node
MS = 1_000_000               #: ns
COMPONENTS = ("serial link", "load cell", "actuator")


class LogRecords(logging.Handler):
    """Keeps the formatted messages of one logger."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())

    @property
    def text(self) -> str:
        return "\n".join(self.lines)


class DriverBench:
    """The driver node (parameters ``overrides``, ``/diagnostics`` at 5 Hz) on a twin."""

    def __init__(self, overrides: dict[str, Any] | None = None, *, seed: int = 5,
                 twin: DeviceTwin | None = None) -> None:
        self.twin = twin or DeviceTwin(PlantConfig(seed=seed))
        self.loop = Loopback(self.twin)
        self.port = MemoryPort({"port": URL, "diagnostics_period_s": 0.2, **(overrides or {})},
                               name="tension_driver")
        self.log = LogRecords()
        self.port.logger.addHandler(self.log)
        self.port.logger.setLevel(logging.DEBUG)
        self.start_ns = self.port.clock_ns
        self.open_attempts: list[int] = []  #: host ms of each attempt to open the port
        self.node = TensionDriverNode(self.port, clock=self.clock, open_port=self._open)
        self.released_at: int | None = None
        self.released_last_rx: int | None = None

    def close(self) -> None:
        self.port.logger.removeHandler(self.log)

    def _open(self, url: str) -> LoopbackLink:
        self.open_attempts.append(self.ms)
        return self.loop.open(url)

    # --- time ------------------------------------------------------------------------------
    def clock(self) -> float:
        """The node's clock: s since the bench was built."""
        return (self.port.clock_ns - self.start_ns) / 1e9

    @property
    def ms(self) -> int:
        """The host's clock in whole ms since the bench was built."""
        return (self.port.clock_ns - self.start_ns) // MS

    def advance(self, seconds: float, *, device: bool = True, host: bool = True) -> None:
        """Run ``seconds`` in 1 ms steps: the twin (unless ``device`` is False: a stalled
        simulation, the bench and firmware paused), then the node's timers (unless ``host`` is
        False: a stopped host process, its timers late; see :meth:`resume_host`)."""
        for _ in range(round(seconds * 1000)):
            if device:
                self.twin.advance(0.001)
                self.loop.tick()
            if host:
                self.port.advance(0.001)
            else:
                self.port.clock_ns += MS  # time goes on; the stopped process runs nothing

    def resume_host(self) -> None:
        """A stopped host runs again: each late timer fires once now, then on its period."""
        for timer in self.port.timers:
            timer.due_ns = max(timer.due_ns, self.port.clock_ns)
        self.port.advance(0.0)

    def until(self, predicate: Any, seconds: float, what: str, *, device: bool = True) -> int:
        """Advance 1 ms at a time (the device paused unless ``device``) until ``predicate()``;
        the host ms it first held at."""
        for _ in range(round(seconds * 1000) + 1):
            if predicate():
                return self.ms
            self.advance(0.001, device=device)
        raise AssertionError(f"no {what} within {seconds:g} s (at {self.ms} ms); "
                             f"state {self.state()}")

    def watch_release(self) -> None:
        """From now on, :attr:`released_at` gets the device ms of its first control tick in mode
        R and :attr:`released_last_rx` the device ms of the host's last byte then."""
        core = self.twin.core
        tick = core.tick
        self.released_at = None

        def watch(now_ms: int) -> None:
            tick(now_ms)
            if self.released_at is None and core.mode is Mode.RELEASE:
                self.released_at, self.released_last_rx = now_ms, core.last_rx_ms

        core.tick = watch  # type: ignore[method-assign]

    # --- inputs ----------------------------------------------------------------------------
    def setpoint(self, newtons: float) -> None:
        self.port.deliver("tension_setpoint", from_dict("std_msgs/msg/Float64", {"data": newtons}))

    def roll(self, radians: float) -> None:
        self.port.deliver("roll_setpoint", from_dict("std_msgs/msg/Float64", {"data": radians}))

    def estop(self) -> None:
        self.port.deliver("estop", from_dict("std_msgs/msg/Empty", {}))

    def call(self, command: str) -> Any:
        """The node's ``~/command`` Trigger service's response."""
        return self.port.call(f"~/{command}")

    def connected(self, seconds: float = 5.0) -> int:
        """Advance until the link is connected with the device holding (mode T); the host ms."""
        return self.until(lambda: self.state().get("link") == "connected"
                          and self.state().get("mode") == "tension", seconds, "connected link")

    def hold(self, newtons: float) -> None:
        """Connect and hold ``newtons`` on the tendon (within 0.25 N)."""
        self.connected()
        self.setpoint(newtons)
        self.until(lambda: abs(self.twin.plant.tension - newtons) < 0.25, 5.0,
                   f"{newtons:g} N on the tendon")

    # --- outputs ---------------------------------------------------------------------------
    def state(self) -> dict[str, str]:
        """The node's statuses rolled into one, as now (what ``device_state`` would carry)."""
        return {kv["key"]: kv["value"] for s in self.node.diagnostics.statuses()
                for kv in s["values"]}

    def states(self) -> list[Any]:
        return self.port.messages("device_state")

    def components(self) -> list[dict[str, Any]]:
        """Each ``/diagnostics`` array as ``{component: status}``."""
        return [{s.name.removeprefix("tension_driver: "): s for s in array.status}
                for array in self.port.messages("/diagnostics")]

    def component(self, name: str) -> Any:
        """The newest published status of ``name``."""
        return self.components()[-1][name]

    def component_level(self, name: str) -> int:
        return level(self.component(name))

    def actuator(self) -> dict[str, str]:
        return values(self.component("actuator"))
