"""Simulated recordings for tests, benchmarks and demos: a tension staircase and the markers the
model predicts for it, seen through a ``mocap`` registration with noise and occlusions.

Everything here is simulated; nothing is measured.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.signal import lfilter

from tdcm_ros.errors import out_of_range
from tdcm_ros.metrics.lookup import MarkerTable
from tdcm_ros.metrics.series import MarkerSeries, TensionSeries
from tdcm_ros.mocap import Registration
from tdcm_ros.model import Design, MarkerLayout, SolverSettings

Array = NDArray[np.float64]
PAPER_LEVELS = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0)


@dataclass(frozen=True)
class Recording:
    """A simulated trial: measured tension, marker frames (``mocap``) and the true tension."""

    tension: TensionSeries
    markers: MarkerSeries
    true_tension_n: Array
    registration: Registration


def staircase(levels: Sequence[float] = PAPER_LEVELS, *, hold_s: float = 5.0, trials: int = 3,
              rate_hz: float = 1000.0, lag_s: float = 0.1, start_s: float = 0.0
              ) -> tuple[Array, Array]:
    """Stamps (s) and the true tension (N): each trial steps through ``levels`` holding each
    ``hold_s``, then returns to the first level; a first-order lag ``lag_s`` smooths each change."""
    if not (trials >= 1 and hold_s > 0.0 and rate_hz > 0.0 and lag_s >= 0.0 and levels):
        raise out_of_range("staircase", (trials, hold_s, rate_hz, lag_s, len(levels)),
                           "trials >= 1, hold_s > 0, rate_hz > 0, lag_s >= 0, levels given")
    command = np.tile(np.asarray(levels, dtype=float), trials)
    command = np.append(command, float(levels[0]))
    per_hold = round(hold_s * rate_hz)
    cmd = np.repeat(command, per_hold)
    stamps = start_s + np.arange(cmd.size) / rate_hz
    if lag_s > 0.0:
        a = np.exp(-1.0 / (rate_hz * lag_s))
        cmd = lfilter([1.0 - a], [1.0, -a], cmd - cmd[0]) + cmd[0]
    return stamps, cmd


def simulate(design: Design, *, registration: Registration | None = None,
             layout: MarkerLayout | None = None, levels: Sequence[float] = PAPER_LEVELS,
             hold_s: float = 5.0, trials: int = 3, tension_hz: float = 1000.0,
             mocap_hz: float = 100.0, tension_noise_n: float = 0.03, marker_noise_m: float = 5e-5,
             occlusion: float = 0.0, seed: int = 0,
             settings: SolverSettings | None = None) -> Recording:
    """Simulate a recording of ``design`` (its ``E`` is the truth) over a staircase.

    Gaussian noise: ``tension_noise_n`` (N) on the load cell, ``marker_noise_m`` (m) per marker
    coordinate; each marker is hidden in a frame with probability ``occlusion``.
    """
    if not 0.0 <= occlusion < 1.0:
        raise out_of_range("occlusion", occlusion, "[0, 1)")
    rng = np.random.default_rng(seed)
    layout = layout or MarkerLayout()
    reg = registration or Registration((0.4, -0.2, 0.9), (0.1, 0.7, -0.1, 0.7))
    stamps, true = staircase(levels, hold_s=hold_s, trials=trials, rate_hz=tension_hz)
    measured = true + rng.normal(0.0, tension_noise_n, true.size)
    frame_s = np.arange(0.0, stamps[-1], 1.0 / mocap_hz)
    frame_true = np.interp(frame_s, stamps, true)
    table = MarkerTable(design, layout, settings=settings, max_n=max(float(max(levels)), 1.0))
    base = table.markers(np.maximum(frame_true, 0.0))
    mocap = reg.to_mocap(base) + rng.normal(0.0, marker_noise_m, base.shape)
    mocap[rng.random(base.shape[:2]) < occlusion] = np.nan
    return Recording(TensionSeries.of(stamps, measured),
                     MarkerSeries.of(frame_s, layout.labels, mocap), true, reg)
