"""The bench the twin simulates: linear actuator, tendon, load cell and roll servo.

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

The roll servo (a hobby servo without position feedback) turns toward the angle its pulse
commands, ``(pulse - ROLL_PULSE_CENTER_US) / ROLL_US_PER_RAD`` rad, at most ``roll_speed`` rad/s
(an argument of :class:`Plant`, not a :class:`PlantConfig` field: scenes own those);
:attr:`Plant.roll` is its true angle (rad).
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

from tdcm_ros.device import constants as c
from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.errors import out_of_range
from tdcm_ros.spec import check_fields, spec_field, specs_of


@dataclass(frozen=True)
class PlantConfig:
    """Plant parameters, SI units (m, s, N); load cell in counts."""

    stroke: float = spec_field(0.02, unit="m", low=0.0, low_open=True,
                               description="actuator travel over the pulse range")
    lag: float = spec_field(0.03, unit="s", low=0.0, low_open=True,
                            description="first-order lag of the actuator")
    rate: float = spec_field(0.025, unit="m/s", low=0.0, low_open=True,
                             description="actuator speed limit")
    stiffness: float = spec_field(2000.0, unit="N/m", low=0.0, low_open=True,
                                  description="tendon stiffness past the slack")
    slack: float = spec_field(0.002, unit="m", low=0.0, description=(
        "actuator travel before the tendon carries load"))
    counts_per_newton: float = spec_field(1000.0, unit="counts/N", low=0.0, low_open=True,
                                          description="load-cell gain")
    tare_counts: int = spec_field(8000, unit="counts", description="load-cell reading at 0 N")
    noise: float = spec_field(0.01, unit="N", low=0.0,
                              description="standard deviation of the load-cell noise")
    quantum: int = spec_field(1, unit="counts", low=1, description="load-cell resolution")
    sample_period: float = spec_field(0.0125, unit="s", low=0.0, low_open=True,
                                      description="load-cell sample period")
    seed: int = spec_field(0, description="seed of the noise generator")
    deadband: float = spec_field(0.0, unit="m", low=0.0, description=(
        "dead zone: the actuator stops this short of its command"))
    bias: float = spec_field(0.0, unit="N", description="load-cell offset")
    drift: float = spec_field(0.0, unit="N/s", description="load-cell linear drift")

    def __post_init__(self) -> None:
        check_fields(self, PLANT_SPECS, error=DeviceInputError)
        if self.deadband >= self.stroke:
            raise out_of_range("deadband", self.deadband, f"< stroke ({self.stroke} m)", unit="m",
                               error=DeviceInputError)
        if self.quantum < 1:
            raise out_of_range("quantum", self.quantum, ">= 1 count", error=DeviceInputError)

    @property
    def scale_mcpn(self) -> int:
        """The calibration scale matching this load cell, in 1e-3 counts per N."""
        return round(self.counts_per_newton * 1000)


ROLL_SPEED = 8.7  #: rad/s, default roll servo speed limit (a hobby servo: 0.12 s per 60 deg)

#: Specs of the plant parameters, by field name.
PLANT_SPECS = specs_of(PlantConfig)


class Plant:
    """State of the simulated bench; :meth:`step` advances it by ``dt`` s."""

    def __init__(self, config: PlantConfig, *, roll_speed: float = ROLL_SPEED) -> None:
        if not (math.isfinite(roll_speed) and roll_speed > 0):
            raise out_of_range("roll_speed", roll_speed, "(0, inf)", unit="rad/s",
                               error=DeviceInputError)
        self.config = config
        self.roll_speed = roll_speed  #: rad/s, roll servo speed limit
        self.position = 0.0
        self.roll = 0.0  #: rad, true angle of the roll servo
        self.time = 0.0  #: s the plant has run
        self._random = random.Random(config.seed)

    def target(self, pulse_us: int) -> float:
        """Actuator position commanded by a pulse, in m."""
        span = c.PULSE_MAX_US - c.PULSE_MIN_US
        fraction = min(max((pulse_us - c.PULSE_MIN_US) / span, 0.0), 1.0)
        return fraction * self.config.stroke

    @staticmethod
    def roll_target(roll_pulse_us: int) -> float:
        """Roll angle commanded by a roll servo pulse, in rad."""
        return (roll_pulse_us - c.ROLL_PULSE_CENTER_US) / c.ROLL_US_PER_RAD

    def step(self, pulse_us: int, dt: float, roll_pulse_us: int = c.ROLL_PULSE_CENTER_US) -> None:
        """Move the actuator and the roll servo toward their pulses' positions for ``dt`` s."""
        cfg = self.config
        turn = self.roll_speed * dt
        self.roll += min(max(self.roll_target(roll_pulse_us) - self.roll, -turn), turn)
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
