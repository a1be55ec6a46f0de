"""A scene's world recorded in-process: a staircase of true tensions and the world's marker
frames (its mechanics and sensing effects; no device, no latency), as the metrics read a bag."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tdcm_ros.metrics.series import MarkerSeries, TensionSeries
from tdcm_ros.metrics.synthetic import Recording, staircase
from tdcm_ros.mocap import Registration
from tdcm_ros.scenes import Scene


def scene_recording(scene: Scene, levels: Sequence[float], *, hold_s: float = 2.0,
                    trials: int = 1, tension_hz: float = 200.0, mocap_hz: float = 25.0,
                    lag_s: float = 0.05) -> Recording:
    """The tension (exact: the world's true tension, N), the world's marker frames (``mocap``,
    m) over a staircase through ``levels`` (each held ``hold_s`` s), ``trials`` times, and the
    world's true registration (``given``)."""
    world = scene.world()
    stamps, true = staircase(levels, hold_s=hold_s, trials=trials, rate_hz=tension_hz,
                             lag_s=lag_s)
    frame_s = np.arange(0.0, stamps[-1], 1.0 / mocap_hz)
    frames = [world.markers(float(t), float(np.interp(t, stamps, true))).positions
              for t in frame_s]
    translation, quaternion = world.true_mocap_to_base
    return Recording(TensionSeries.of(stamps, true),
                     MarkerSeries.of(frame_s, world.bench.marker_labels, np.asarray(frames)),
                     true, Registration(tuple(translation), tuple(quaternion), method="given"))
