"""Simulated recordings shared by the metrics tests (uniquely named so imports never collide)."""

from __future__ import annotations

from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.model import preset

TRUE_E = 0.7e9  #: Pa, the simulated robot's modulus
DESIGN = preset("paper-experiment").with_overrides(E=TRUE_E)


def small_recording(**kw: object) -> object:
    """2 trials of 0, 8, 16 N held 2 s; tension 250 Hz, mocap 50 Hz; ``kw`` overrides."""
    args = {"levels": (0.0, 8.0, 16.0), "hold_s": 2.0, "trials": 2, "tension_hz": 250.0,
            "mocap_hz": 50.0, "marker_noise_m": 5e-5, "seed": 1}
    args.update(kw)
    return simulate(DESIGN, **args)
