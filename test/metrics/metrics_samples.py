"""Simulated recordings shared by the metrics tests (uniquely named so imports never collide)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tdcm_ros.metrics.streaming import RunningEvaluation
from tdcm_ros.metrics.synthetic import Recording, simulate
from tdcm_ros.model import Design, named_design, preset

TRUE_E = 0.7e9  #: Pa, the simulated robot's modulus
DESIGN = preset("paper-experiment").with_overrides(E=TRUE_E)
#: The antagonistic pair's body file (tendons flexor, extensor), as ``--design`` takes it.
PAIR_BODY = str(Path(__file__).resolve().parents[2] / "config" / "bodies" /
                "antagonistic_pair.yaml")
PAIR = named_design(PAIR_BODY)
#: Each trial's holds, N (flexor, extensor): bend to +x, balanced, bend to -x; the last hold
#: is the final return to (0, 0).
PAIR_LEVELS = ((0.0, 0.0), (8.0, 0.0), (16.0, 0.0), (8.0, 8.0), (0.0, 12.0))


def small_recording(**kw: object) -> object:
    """2 trials of 0, 8, 16 N held 2 s; tension 250 Hz, mocap 50 Hz; ``kw`` overrides."""
    args = {"levels": (0.0, 8.0, 16.0), "hold_s": 2.0, "trials": 2, "tension_hz": 250.0,
            "mocap_hz": 50.0, "marker_noise_m": 5e-5, "seed": 1}
    args.update(kw)
    return simulate(DESIGN, **args)


def pair_recording(design: Design = PAIR, **kw: object) -> Recording:
    """The antagonistic pair (``design``: its E is the truth), 2 trials of :data:`PAIR_LEVELS`
    held 2 s; tension 250 Hz, mocap 50 Hz; by default noise-free with no lag, so each hold's
    markers are the model's own at the hold's true tension vector; ``kw`` overrides."""
    args = {"levels": PAIR_LEVELS, "hold_s": 2.0, "trials": 2, "tension_hz": 250.0,
            "mocap_hz": 50.0, "tension_noise_n": 0.0, "marker_noise_m": 0.0, "lag_s": 0.0,
            "seed": 1}
    args.update(kw)
    return simulate(design, **args)


def rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle (rad) of the rotation between two rotation matrices (3, 3)."""
    return float(np.arccos(np.clip((np.trace(a.T @ b) - 1.0) / 2.0, -1.0, 1.0)))


def stream(rec: Recording, running: RunningEvaluation, every_s: float = 0.5) -> None:
    """Feed ``rec`` into ``running`` in stamp order (tension samples, and before each the roll
    samples, if any, and marker frames stamped at or before it), updating every ``every_s``
    (s) of tension stamps and once at the end."""
    frames, fi, ri, next_update = rec.markers.stamps_s, 0, 0, every_s
    roll_s, roll_rad = ((rec.roll.stamps_s, rec.roll.roll_rad) if rec.roll is not None
                        else (np.empty(0), np.empty(0)))
    for t, x in zip(rec.tension.stamps_s, rec.tension.tension_n, strict=True):
        running.add_tension(t, x)
        while ri < roll_s.size and roll_s[ri] <= t:
            running.add_roll(roll_s[ri], roll_rad[ri])
            ri += 1
        while fi < frames.size and frames[fi] <= t:
            running.add_markers(frames[fi], rec.markers.positions[fi])
            fi += 1
        if t >= next_update:
            running.update()
            next_update += every_s
    running.update()
