"""Simulated recordings for tests, benchmarks and demos: a tension staircase (one level per
step, or for a body with several tendons one tension vector per step) and the markers the model
predicts for it, seen through a ``mocap`` registration with noise and occlusions.

Everything here is simulated; nothing is measured.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.signal import lfilter

from tdcm_ros.errors import out_of_range
from tdcm_ros.metrics.lookup import MarkerTable
from tdcm_ros.metrics.series import MarkerSeries, RollSeries, TensionSeries
from tdcm_ros.mocap import Registration
from tdcm_ros.model import (
    Design,
    MarkerLayout,
    SolverSettings,
    roll_points,
    solve,
    surface_points,
)

Array = NDArray[np.float64]
PAPER_LEVELS = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0)


@dataclass(frozen=True)
class Recording:
    """A simulated trial: measured tension, marker frames (``mocap``), the true tension (N,
    (n,) or (n, J) as the measured one) and the roll (None: roll 0 throughout, no roll
    samples)."""

    tension: TensionSeries
    markers: MarkerSeries
    true_tension_n: Array
    registration: Registration
    roll: RollSeries | None = None


def staircase(levels: Sequence[float] | Sequence[Sequence[float]] = PAPER_LEVELS, *,
              hold_s: float = 5.0, trials: int = 3, rate_hz: float = 1000.0, lag_s: float = 0.1,
              start_s: float = 0.0) -> tuple[Array, Array]:
    """Stamps (s) and the true tension (N; (n,) for levels of one tendon, (n, J) for levels
    that are vectors of J tendons): each trial steps through ``levels`` holding each
    ``hold_s``, then returns to the first level; a first-order lag ``lag_s`` smooths each change."""
    if not (trials >= 1 and hold_s > 0.0 and rate_hz > 0.0 and lag_s >= 0.0 and len(levels)):
        raise out_of_range("staircase", (trials, hold_s, rate_hz, lag_s, len(levels)),
                           "trials >= 1, hold_s > 0, rate_hz > 0, lag_s >= 0, levels given")
    steps = np.asarray(levels, dtype=float)
    command = np.concatenate([np.tile(steps, (trials,) + (1,) * (steps.ndim - 1)), steps[:1]])
    per_hold = round(hold_s * rate_hz)
    cmd = np.repeat(command, per_hold, axis=0)
    stamps = start_s + np.arange(len(cmd)) / rate_hz
    if lag_s > 0.0:
        a = np.exp(-1.0 / (rate_hz * lag_s))
        cmd = lfilter([1.0 - a], [1.0, -a], cmd - cmd[0], axis=0) + cmd[0]
    return stamps, cmd


def _model_markers(design: Design, layout: MarkerLayout, tensions: Array, max_n: float,
                   settings: SolverSettings | None) -> Array:
    """The model's marker points (frames, k, 3) m at each frame's tensions ((frames,) N, by a
    :class:`MarkerTable` up to ``max_n``; or (frames, J) N, solved at each distinct vector)."""
    if tensions.ndim == 1:
        return MarkerTable(design, layout, settings=settings, max_n=max_n).markers(
            np.maximum(tensions, 0.0))
    distinct, which = np.unique(np.maximum(tensions, 0.0), axis=0, return_inverse=True)
    radius = layout.radius(design.R_outer)
    points = [surface_points(solve(design, row, settings=settings or SolverSettings()), layout.s,
                             radius, layout.side_rad)[0] for row in distinct.tolist()]
    return np.asarray(points)[which.ravel()]


def simulate(design: Design, *, registration: Registration | None = None,
             layout: MarkerLayout | None = None,
             levels: Sequence[float] | Sequence[Sequence[float]] = PAPER_LEVELS,
             hold_s: float = 5.0, trials: int = 3, tension_hz: float = 1000.0,
             mocap_hz: float = 100.0, tension_noise_n: float = 0.03, marker_noise_m: float = 5e-5,
             occlusion: float = 0.0, seed: int = 0, lag_s: float = 0.1,
             settings: SolverSettings | None = None) -> Recording:
    """Simulate a recording of ``design`` (its ``E`` is the truth) over a staircase (lag
    ``lag_s``, s); a design with J > 1 tendons takes ``levels`` as tension vectors (J,) N, and
    its recording's tension has a column per tendon, named as in the design.

    Gaussian noise: ``tension_noise_n`` (N) on the load cell, ``marker_noise_m`` (m) per marker
    coordinate; each marker is hidden in a frame with probability ``occlusion``.
    """
    if not 0.0 <= occlusion < 1.0:
        raise out_of_range("occlusion", occlusion, "[0, 1)")
    names = tuple(t.name for t in design.tendon_list())
    per_step = (len(names),) if len(names) > 1 else ()
    if np.shape(levels)[1:] != per_step:
        raise out_of_range("levels", levels, f"steps of shape {per_step}: a tension (N) per "
                           f"tendon of the design ({', '.join(names)})")
    rng = np.random.default_rng(seed)
    layout = layout or MarkerLayout()
    reg = registration or Registration((0.4, -0.2, 0.9), (0.1, 0.7, -0.1, 0.7))
    stamps, true = staircase(levels, hold_s=hold_s, trials=trials, rate_hz=tension_hz,
                             lag_s=lag_s)
    measured = true + rng.normal(0.0, tension_noise_n, true.shape)
    frame_s = np.arange(0.0, stamps[-1], 1.0 / mocap_hz)
    frame_true = np.column_stack([np.interp(frame_s, stamps, column) for column in
                                  true.T]) if true.ndim > 1 else np.interp(frame_s, stamps, true)
    base = _model_markers(design, layout, frame_true, max(float(np.max(levels)), 1.0), settings)
    mocap = reg.to_mocap(base) + rng.normal(0.0, marker_noise_m, base.shape)
    mocap[rng.random(base.shape[:2]) < occlusion] = np.nan
    return Recording(TensionSeries.of(stamps, measured, names if true.ndim > 1 else ()),
                     MarkerSeries.of(frame_s, layout.labels, mocap), true, reg)


def rolled(recording: Recording, roll: RollSeries) -> Recording:
    """``recording`` with the body rolled by ``roll`` (rad about the base +z axis): each marker
    frame turned about ``tdcm_base``'s +z axis by the roll at its stamp, noise and all, and
    ``roll`` its roll samples (frames at roll 0 kept as they are). A recording at roll 0 thus
    gives the same frames in the bending plane at any roll."""
    markers = recording.markers
    reg = recording.registration
    at = roll.at(markers.stamps_s)
    turned = np.array([reg.to_mocap(roll_points(reg.to_base(frame), phi)) if phi else frame
                       for frame, phi in zip(markers.positions, at.tolist(), strict=True)])
    return replace(recording, markers=replace(markers, positions=turned), roll=roll)
