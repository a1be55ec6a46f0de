"""Setpoint schedules: the paper's staircase of tension levels, repeated for several trials."""

from __future__ import annotations

from dataclasses import dataclass

from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.spec import check_fields, spec_field, specs_of


@dataclass(frozen=True)
class StepSchedule:
    """Each trial holds every level in ``levels`` (N) for ``hold`` s, in order.

    The default is the paper's 0 -> 20 N in 4 N steps. After the last trial the setpoint is 0 N.
    """

    levels: tuple[float, ...] = spec_field((0.0, 4.0, 8.0, 12.0, 16.0, 20.0), unit="N", low=0.0,
                                           description="tension setpoints of one trial, in order")
    hold: float = spec_field(5.0, name="hold_s", unit="s", low=0.01, high=86_400.0,
                             description="hold time of each level")
    trials: int = spec_field(1, low=1, high=10_000, description="repetitions of the staircase")

    def __post_init__(self) -> None:
        check_fields(self, SCHEDULE_SPECS, error=DeviceInputError)

    @property
    def duration(self) -> float:
        """Total length, in s."""
        return len(self.levels) * self.hold * self.trials

    def setpoint(self, elapsed: float) -> float | None:
        """Setpoint in N at ``elapsed`` s from the start, or ``None`` once finished."""
        if elapsed >= self.duration:
            return None
        index = int(max(elapsed, 0.0) // self.hold) % len(self.levels)
        return self.levels[index]


#: Specs of the schedule parameters, by field name.
SCHEDULE_SPECS = specs_of(StepSchedule)
