"""The bench the twin simulates: linear actuator, tendon and load cell.

The actuator maps the servo pulse linearly onto ``stroke`` metres of travel between
``PULSE_MIN_US`` and ``PULSE_MAX_US``; its position follows the command through a first-order
lag (``lag`` s) and a speed limit (``rate`` m/s); within ``deadband`` m of the command it does
not move (a dead zone: the lag acts on the error beyond the deadband, so the actuator stops
``deadband`` short of the command). The tendon carries no load for the first ``slack`` metres,
then ``stiffness`` N per metre of further travel. The load cell reads
``tare_counts + counts_per_newton * (tension + bias + drift * t + noise)`` rounded to a multiple
of ``quantum`` counts, every ``sample_period`` s, where ``t`` is the plant's running time (s),
``bias`` an offset (N) and ``drift`` a linear drift (N/s); the noise is Gaussian with ``noise`` N
standard deviation drawn from a generator seeded with ``seed``. :attr:`Plant.tension` is the true
tendon tension, which bias, drift and noise do not touch.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, fields

from tdcm_ros.device import constants as c
from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.errors import out_of_range

_POSITIVE = ("stroke", "lag", "rate", "stiffness", "counts_per_newton", "sample_period")


@dataclass(frozen=True)
class PlantConfig:
    """Plant parameters, SI units (m, s, N); load cell in counts."""

    stroke: float = 0.02
    lag: float = 0.03
    rate: float = 0.025
    stiffness: float = 2000.0
    slack: float = 0.002
    counts_per_newton: float = 1000.0
    tare_counts: int = 8000
    noise: float = 0.01
    quantum: int = 1
    sample_period: float = 0.0125
    seed: int = 0
    deadband: float = 0.0
    bias: float = 0.0
    drift: float = 0.0

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            if not math.isfinite(value):
                raise out_of_range(field.name, value, "a finite number", error=DeviceInputError)
            if field.name in _POSITIVE and value <= 0:
                raise out_of_range(field.name, value, "> 0", error=DeviceInputError)
        for name in ("slack", "noise", "deadband"):
            if getattr(self, name) < 0:
                raise out_of_range(name, getattr(self, name), ">= 0", error=DeviceInputError)
        if self.deadband >= self.stroke:
            raise out_of_range("deadband", self.deadband, f"< stroke ({self.stroke} m)", unit="m",
                               error=DeviceInputError)
        if self.quantum < 1:
            raise out_of_range("quantum", self.quantum, ">= 1 count", error=DeviceInputError)

    @property
    def scale_mcpn(self) -> int:
        """The calibration scale matching this load cell, in 1e-3 counts per N."""
        return round(self.counts_per_newton * 1000)


class Plant:
    """State of the simulated bench; :meth:`step` advances it by ``dt`` s."""

    def __init__(self, config: PlantConfig) -> None:
        self.config = config
        self.position = 0.0
        self.time = 0.0  #: s the plant has run
        self._random = random.Random(config.seed)

    def target(self, pulse_us: int) -> float:
        """Actuator position commanded by a pulse, in m."""
        span = c.PULSE_MAX_US - c.PULSE_MIN_US
        fraction = min(max((pulse_us - c.PULSE_MIN_US) / span, 0.0), 1.0)
        return fraction * self.config.stroke

    def step(self, pulse_us: int, dt: float) -> None:
        """Move the actuator toward the pulse's position for ``dt`` s."""
        cfg = self.config
        target = self.target(pulse_us)
        substeps = max(1, math.ceil(dt / cfg.lag))  # explicit Euler stays stable for h <= lag
        h = dt / substeps
        for _ in range(substeps):
            error = target - self.position
            beyond = math.copysign(max(abs(error) - cfg.deadband, 0.0), error)
            speed = min(max(beyond / cfg.lag, -cfg.rate), cfg.rate)
            self.position += speed * h
        self.time += dt

    @property
    def tension(self) -> float:
        """True tendon tension, in N."""
        return self.config.stiffness * max(0.0, self.position - self.config.slack)

    @property
    def offset(self) -> float:
        """What the load cell adds to the true tension now (bias + drift), in N."""
        return self.config.bias + self.config.drift * self.time

    def read_counts(self) -> int:
        """One load-cell reading, in counts."""
        cfg = self.config
        noisy = self.tension + (self._random.gauss(0.0, cfg.noise) if cfg.noise else 0.0)
        counts = cfg.tare_counts + cfg.counts_per_newton * (noisy + self.offset)
        return round(counts / cfg.quantum) * cfg.quantum
