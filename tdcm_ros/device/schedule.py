"""Setpoint schedules: the paper's staircase of tension levels, repeated for several trials."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.errors import out_of_range


@dataclass(frozen=True)
class StepSchedule:
    """Each trial holds every level in ``levels`` (N) for ``hold`` s, in order.

    The default is the paper's 0 -> 20 N in 4 N steps. After the last trial the setpoint is 0 N.
    """

    levels: tuple[float, ...] = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0)
    hold: float = 5.0
    trials: int = 1

    def __post_init__(self) -> None:
        if not self.levels:
            raise out_of_range("levels", self.levels, "at least one level", error=DeviceInputError)
        for level in self.levels:
            if not (math.isfinite(level) and level >= 0):
                raise out_of_range("levels", level, "finite and >= 0", unit="N",
                                   error=DeviceInputError)
        if not (math.isfinite(self.hold) and self.hold > 0):
            raise out_of_range("hold", self.hold, "> 0", unit="s", error=DeviceInputError)
        if self.trials < 1:
            raise out_of_range("trials", self.trials, ">= 1", error=DeviceInputError)

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
