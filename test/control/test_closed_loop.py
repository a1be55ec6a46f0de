"""The controller core closed around a simulated world whose modulus is not the model's: with
feedback the tip settles within 0.3 mm of each target, feed-forward alone does not."""

from __future__ import annotations

import numpy as np
import pytest

from tdcm_ros.control import DriverLimits, rotate_z, simulate_tracking
from tdcm_ros.model import preset, solve

DESIGN = preset("paper-experiment")
LIMITS = DriverLimits(tension_max=20.0, setpoint_rate=40.0, roll_max=np.pi / 2, roll_rate=1.0)
SETTLED_S = 1.0


def model_tip(tension: float, roll: float) -> tuple[float, float, float]:
    x, _, z = solve(DESIGN, tension).tip_position
    return rotate_z((float(x), 0.0, float(z)), roll)


#: the model's tip at these tensions (N), rolled by these angles (rad)
TARGETS = [model_tip(t, r) for t, r in ((8.0, 0.4), (13.0, -0.6), (11.0, 1.0), (6.0, 0.0))]


def settled(mode: str, modulus_ratio: float) -> np.ndarray:
    run = simulate_tracking(DESIGN, TARGETS, modulus_ratio=modulus_ratio, mode=mode,
                            limits=LIMITS)
    assert np.all(np.abs(np.diff(run.tension_n)) <= LIMITS.setpoint_rate * 0.02 + 1e-12)
    assert np.all(np.abs(run.roll_rad) <= LIMITS.roll_max)
    return run.settled_error_m(SETTLED_S)


@pytest.mark.parametrize("modulus_ratio", [1.3, 0.8])
def test_feedback_settles_within_0_3_mm_where_feedforward_does_not(modulus_ratio: float) -> None:
    assert min(settled("feedforward", modulus_ratio)) > 0.3e-3
    assert max(settled("feedback", modulus_ratio)) < 0.3e-3


def test_feedback_changes_nothing_when_the_model_is_right() -> None:
    assert max(settled("feedback", 1.0)) < 0.3e-3
    assert max(settled("feedforward", 1.0)) < 1e-9


def test_the_gain_learns_the_true_ratio_and_its_std_shrinks() -> None:
    run = simulate_tracking(DESIGN, TARGETS[:2], modulus_ratio=1.3, mode="feedback",
                            limits=LIMITS)
    assert run.gain[-1] == pytest.approx(1.3, abs=max(4 * run.gain_std[-1], 1e-3))
    assert run.gain_std[-1] < 0.1 * run.gain_std[0]
