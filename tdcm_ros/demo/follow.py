"""A tracking run on the live graph: publish the circle's targets, switch the controller's mode.

The demo process publishes ``target_point`` (``geometry_msgs/msg/PointStamped``, ``tdcm_base``,
stamped with the runtime's clock) at the trajectory's rate, each the target at the elapsed time
(so a late tick publishes where the target is, not where it was), and beside it the lap on
``tracking/lap`` (``std_msgs/msg/Int32``: 0 the approach, then 1, 2, ...) for the report. At
each lap whose mode differs from the controller's it sets the shape controller's ``mode``
parameter through its parameter services first (back to ``feedforward`` for the laps with the
learned gain: the controller keeps its estimate, frozen); a refusal ends the run with the
controller's reason.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from tdcm_ros.bagio import from_dict
from tdcm_ros.demo.tracking_report import LAP_TOPIC, LAP_TYPE, POINT_TYPE, TARGET_TOPIC
from tdcm_ros.demo.trajectory import TipTrajectory
from tdcm_ros.runtime import QoS, RuntimePortError
from tdcm_ros.runtime.param_client import ParameterClient

#: The node whose ``mode`` parameter the demo switches.
CONTROLLER = "/shape_controller"
#: Longest spin (s) between two checks of the clock.
MAX_SPIN_S = 0.1


class Turn(Protocol):
    """One wait of the demo's loop: spin ``seconds``, fail on Ctrl-C, a dead child or
    ``deadline`` (s of the loop's clock, monotonic by default; ``late()`` is then the error
    message)."""

    def __call__(self, deadline: float, late: Callable[[], str], seconds: float) -> None: ...


@dataclass
class FollowState:
    """Where the run is (updated as it goes)."""

    lap: int = -1
    mode: str = ""
    phase: str = ""                #: the lap's phase ("" during the approach)
    error_m: float | None = None   #: latest |controller/tracking_error| (m)

    def line(self, elapsed: float, laps: int) -> str:
        """One progress line."""
        error = "-" if self.error_m is None else f"{self.error_m * 1e3:6.3f} mm"
        lap = "approach" if self.lap == 0 else f"lap {self.lap}/{laps}"
        return f"  t = {elapsed:5.1f} s  {lap:10s} {self.phase or self.mode:19s} tip error {error}"


def _watch_error(port: Any, state: FollowState) -> None:
    def on_error(message: Any) -> None:
        v = message.vector
        state.error_m = math.sqrt(v.x * v.x + v.y * v.y + v.z * v.z)

    port.create_subscription("controller/tracking_error", "geometry_msgs/msg/Vector3Stamped",
                             on_error, QoS(depth=10))


def set_mode(params: ParameterClient, mode: str) -> None:
    """Set the controller's ``mode``; a refusal raises with its reason."""
    result = params.set("mode", mode)
    if not result.successful:
        raise RuntimePortError(f"{CONTROLLER} refused mode = {mode!r}: {result.reason}")


def follow(targets: TipTrajectory, context: Any, port: Any, turn: Turn, *,
           say: Callable[[str], None], progress_period: float, margin_s: float,
           clock: Callable[[], int] = time.monotonic_ns) -> None:
    """Publish every target of ``targets`` in real time, switching modes at lap starts;
    ``turn`` waits between ticks, with a deadline ``margin_s`` past the trajectory's end.

    ``clock`` (ns, monotonic) paces the loop: tick ``k`` is due ``k`` periods (whole ns) after
    the start, so a clock that ``turn`` moves by exactly the seconds asked (a test's simulated
    one) publishes exactly on the ticks; a late tick publishes where the target is then, and the
    ticks it missed are skipped."""
    circle = targets.circle
    point_out = port.create_publisher(TARGET_TOPIC, POINT_TYPE)
    lap_out = port.create_publisher(LAP_TOPIC, LAP_TYPE)
    params = ParameterClient(context, CONTROLLER)
    state = FollowState()
    _watch_error(port, state)
    period_ns = round(1e9 / circle.rate)
    line_ns = round(progress_period * 1e9)
    duration_ns = round(circle.duration * 1e9)
    start = clock()
    deadline = (start + duration_ns) / 1e9 + margin_s
    next_tick, next_line = start, start
    while (now := clock()) - start < duration_ns:
        elapsed = (now - start) / 1e9
        if now >= next_tick:
            lap = circle.lap_at(elapsed)
            mode, phase = circle.mode_of_lap(lap), circle.phase_of_lap(lap)
            if mode != state.mode:
                set_mode(params, mode)
                say(f"  t = {elapsed:5.1f} s  controller mode -> {mode}"
                    + (f" ({phase} phase)" if phase else ""))
            state.lap, state.mode, state.phase = lap, mode, phase
            _publish(port, point_out, lap_out, targets.point(elapsed), lap)
            next_tick += period_ns * max(1, -(-(now - next_tick) // period_ns))
        if now >= next_line:
            say(state.line(elapsed, circle.laps))
            next_line += line_ns
        turn(deadline, lambda: f"the trajectory did not finish within {circle.duration:g} s + "
                               f"{margin_s:g} s",
             max(1e-3, min((next_tick - now) / 1e9, MAX_SPIN_S)))


def _publish(port: Any, point_out: Any, lap_out: Any, point: tuple[float, float, float],
             lap: int) -> None:
    stamp = port.now_ns()
    point_out.publish(from_dict(POINT_TYPE, {
        "header": {"stamp": {"sec": stamp // 10**9, "nanosec": stamp % 10**9},
                   "frame_id": "tdcm_base"},
        "point": {"x": point[0], "y": point[1], "z": point[2]}}))
    lap_out.publish(from_dict(LAP_TYPE, {"data": lap}))
