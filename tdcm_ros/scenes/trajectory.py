"""A scene's tip trajectory: a circle of tip targets seen from above (the x-y plane of
``tdcm_base``), followed lap by lap, first feed-forward, then with feedback, then (optionally)
feed-forward again with the stiffness correction feedback learned (SI units).

The circle is declared by its centre ``(x, y)`` (m) and radius (m) in the x-y plane; the
height ``z`` of each target is not declared, it is the one the tip reaches at that distance
from the body's axis (see :mod:`tdcm_ros.demo.trajectory`), so every target is reachable
through a roll (``atan2(y, x)``) and a bend. The circle must lie in ``x > 0`` (strictly), so
the roll stays inside (-pi/2, pi/2) rad and never flips through the z axis.

Time: ``approach_s`` holding the first target (phase angle 0, the point farthest along +x
from the centre), then ``feedforward_laps`` laps, then ``feedback_laps`` laps, then
``learned_feedforward_laps`` laps (default 0) of ``period_s`` each, counter-clockwise seen
from +z. The targets are published at ``rate_hz``. Each run of laps is a phase
(:data:`PHASES`); the last one runs the controller in mode ``feedforward`` again, which keeps
the gain the feedback laps learned (the controller freezes it, it does not reset it). The
tracking error of each phase is taken after its first ``settle_s``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.params import Param, parse_params

FEEDFORWARD, FEEDBACK = "feedforward", "feedback"
#: The controller's ``mode`` values, in the order their first phases run.
MODES = (FEEDFORWARD, FEEDBACK)
#: The phase of feed-forward laps after the feedback laps (controller mode ``feedforward``,
#: with the gain the feedback laps learned).
FEEDFORWARD_LEARNED = "feedforward_learned"
#: Phases in the order they run.
PHASES = (FEEDFORWARD, FEEDBACK, FEEDFORWARD_LEARNED)
#: The controller's ``mode`` during each phase.
PHASE_MODES = {FEEDFORWARD: FEEDFORWARD, FEEDBACK: FEEDBACK, FEEDFORWARD_LEARNED: FEEDFORWARD}

TRAJECTORY = (
    Param("centre_m", "m", "centre (x, y) of the circle of tip targets in tdcm_base",
          (0.009, 0.0), kind="vector", size=2, low=-0.5, high=0.5),
    Param("radius_m", "m", "radius of the circle in the x-y plane", 0.003, low=0.0,
          low_open=True, high=0.5),
    Param("period_s", "s", "time per lap", 20.0, low=1.0, high=3600.0),
    Param("approach_s", "s", "time holding the first target before the first lap", 3.0,
          low=0.0, high=600.0),
    Param("feedforward_laps", "", "laps run in feedforward mode (first)", 1, kind="int",
          low=1, high=1000),
    Param("feedback_laps", "", "laps run in feedback mode (after the feed-forward laps)", 2,
          kind="int", low=1, high=1000),
    Param("learned_feedforward_laps", "", "laps run in feedforward mode after the feedback laps, "
          "with the gain they learned (0: none)", 0, kind="int", low=0, high=1000),
    Param("settle_s", "s", "time at the start of each phase left out of its tracking error",
          5.0, low=0.0, high=3600.0),
    Param("rate_hz", "Hz", "rate at which the targets are published", 20.0, low=0.1,
          high=1000.0),
)


@dataclass(frozen=True)
class CircleTrajectory:
    """The declared circle and its timing; see the module docstring. Times in s from the start
    of the approach."""

    centre: tuple[float, float]
    radius: float
    period: float
    approach: float
    feedforward_laps: int
    feedback_laps: int
    learned_feedforward_laps: int
    settle: float
    rate: float

    @property
    def phase_laps(self) -> dict[str, int]:
        """Laps of each phase, in :data:`PHASES` order (phases without laps included)."""
        return {FEEDFORWARD: self.feedforward_laps, FEEDBACK: self.feedback_laps,
                FEEDFORWARD_LEARNED: self.learned_feedforward_laps}

    @property
    def lap_phases(self) -> tuple[str, ...]:
        """The phase of laps 1, 2, ... in order (lap 0 is the approach)."""
        return tuple(phase for phase, laps in self.phase_laps.items() for _ in range(laps))

    @property
    def lap_modes(self) -> tuple[str, ...]:
        """The controller mode of laps 1, 2, ... in order (lap 0 is the approach)."""
        return tuple(PHASE_MODES[phase] for phase in self.lap_phases)

    @property
    def laps(self) -> int:
        """Number of laps after the approach."""
        return sum(self.phase_laps.values())

    @property
    def duration(self) -> float:
        """Approach plus every lap (s)."""
        return self.approach + self.laps * self.period

    def lap_at(self, t: float) -> int:
        """The lap running at ``t`` (s): 0 during the approach, 1..laps, ``laps`` after the end.

        Counted in whole ns, so a lap starts exactly at approach + k periods (in floats,
        2.3 - 0.3 is 1.9999999999999998 and would start the third lap of a 0.3 s approach one
        tick late)."""
        if t < self.approach:
            return 0
        into_ns = round((t - self.approach) * 1e9)
        return min(self.laps, 1 + into_ns // round(self.period * 1e9))

    def mode_of_lap(self, lap: int) -> str:
        """The controller mode of ``lap`` (the approach runs feed-forward)."""
        return FEEDFORWARD if lap == 0 else self.lap_modes[lap - 1]

    def phase_of_lap(self, lap: int) -> str:
        """The phase of ``lap`` (1..laps; the approach, lap 0, belongs to none: ``""``)."""
        return "" if lap == 0 else self.lap_phases[lap - 1]

    def phase_angle(self, t: float) -> float:
        """Angle (rad) around the circle at ``t`` (s), 0 during the approach."""
        if t <= self.approach:
            return 0.0
        return 2.0 * math.pi * ((t - self.approach) / self.period)

    def xy(self, t: float) -> tuple[float, float]:
        """The target's ``(x, y)`` (m) in tdcm_base at ``t`` (s)."""
        angle = self.phase_angle(t)
        return (self.centre[0] + self.radius * math.cos(angle),
                self.centre[1] + self.radius * math.sin(angle))

    def deflection_range(self) -> tuple[float, float]:
        """Smallest and largest distance (m) of a target from the z axis."""
        distance = math.hypot(*self.centre)
        return distance - self.radius, distance + self.radius

    def to_dict(self) -> dict[str, Any]:
        """The scene file's keys (SI units)."""
        return {"centre_m": list(self.centre), "radius_m": self.radius,
                "period_s": self.period, "approach_s": self.approach,
                "feedforward_laps": self.feedforward_laps, "feedback_laps": self.feedback_laps,
                "learned_feedforward_laps": self.learned_feedforward_laps,
                "settle_s": self.settle, "rate_hz": self.rate}


def parse_trajectory(raw: Mapping[str, Any] | None) -> CircleTrajectory:
    """The ``trajectory`` section validated; :class:`InvalidSceneError` names the key."""
    values = parse_params("trajectory", TRAJECTORY, raw)
    trajectory = CircleTrajectory(
        centre=values["centre_m"], radius=values["radius_m"], period=values["period_s"],
        approach=values["approach_s"], feedforward_laps=values["feedforward_laps"],
        feedback_laps=values["feedback_laps"],
        learned_feedforward_laps=values["learned_feedforward_laps"], settle=values["settle_s"],
        rate=values["rate_hz"])
    x = trajectory.centre[0]
    if x <= trajectory.radius:
        raise InvalidSceneError(
            f"trajectory.centre_m = {list(trajectory.centre)!r} with radius_m = "
            f"{trajectory.radius:g} m reaches x <= 0; allowed: centre x > {trajectory.radius:g} m "
            "(= radius_m: the circle in x > 0, so the roll stays inside (-pi/2, pi/2) rad)",
            parameter="trajectory.centre_m", value=list(trajectory.centre),
            allowed=f"x > {trajectory.radius:g} m")
    shortest = min(laps for laps in trajectory.phase_laps.values() if laps) * trajectory.period
    if trajectory.settle >= shortest:
        raise InvalidSceneError(
            f"trajectory.settle_s = {trajectory.settle:g} s leaves nothing of the shortest "
            f"phase ({shortest:g} s); allowed: [0, {shortest:g}) s",
            parameter="trajectory.settle_s", value=trajectory.settle,
            allowed=f"[0, {shortest:g}) s")
    return trajectory
