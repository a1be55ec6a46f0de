"""The driver's own limits and the controller's slew toward a command within them."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from tdcm_ros.errors import out_of_range

#: The driver parameters the controller reads (names as the driver declares them).
DRIVER_LIMIT_NAMES = ("tension_max", "setpoint_rate", "roll_max", "roll_rate")
_UNITS = {"tension_max": "N", "setpoint_rate": "N/s", "roll_max": "rad", "roll_rate": "rad/s"}


@dataclass(frozen=True)
class DriverLimits:
    """``tension_max`` (N), ``setpoint_rate`` (N/s), ``roll_max`` (rad), ``roll_rate``
    (rad/s): what the driver accepts; each finite and > 0."""

    tension_max: float
    setpoint_rate: float
    roll_max: float
    roll_rate: float

    def __post_init__(self) -> None:
        for name in DRIVER_LIMIT_NAMES:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0.0):
                raise out_of_range(f"driver {name}", value, f"(0, inf) {_UNITS[name]}")

    @classmethod
    def from_values(cls, values: Mapping[str, Any]) -> DriverLimits:
        """From the driver's parameter values by name."""
        return cls(**{name: float(values[name]) for name in DRIVER_LIMIT_NAMES})


def clamp(value: float, low: float, high: float) -> float:
    """``value`` within ``[low, high]``."""
    return min(max(value, low), high)


def slew(current: float, goal: float, rate: float, dt_s: float) -> float:
    """One step from ``current`` toward ``goal`` moving at most ``rate * dt_s``."""
    step = rate * max(dt_s, 0.0)
    return current + clamp(goal - current, -step, step)
