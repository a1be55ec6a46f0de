"""Step detection on synthetic staircases with noise, transients and spikes (hypothesis)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.errors import InputError
from tdcm_ros.metrics.steps import (
    StepSettings,
    assign_phases,
    detect_steps,
    settings_for_hold,
)
from tdcm_ros.metrics.synthetic import staircase


@settings(max_examples=25)
@given(levels=st.lists(st.floats(1.0, 25.0), min_size=1, max_size=5).map(
           lambda v: [0.0, *sorted({round(x) for x in v})]),
       trials=st.integers(1, 3), hold_s=st.floats(2.3, 4.0), lag_s=st.floats(0.0, 0.15),
       noise=st.floats(0.0, 0.08), seed=st.integers(0, 2**16))
def test_staircases_give_their_levels_and_trials(levels: list[float], trials: int,
                                                 hold_s: float, lag_s: float, noise: float,
                                                 seed: int) -> None:
    rng = np.random.default_rng(seed)
    t, true = staircase(levels, hold_s=hold_s, trials=trials, rate_hz=500.0, lag_s=lag_s)
    x = true + rng.normal(0.0, noise, t.size)
    spikes = rng.choice(t.size, size=5, replace=False)
    x[spikes] += 3.0  # single-sample glitches of the load cell
    steps = detect_steps(t, x)
    expected = [lv for _ in range(trials) for lv in levels] + [levels[0]]
    assert [round(s.median_n) for s in steps] == [round(v) for v in expected]
    assert [s.trial for s in steps] == [k for k in range(trials) for _ in levels] + [trials - 1]
    for s in steps:
        assert s.duration_s >= 1.0
        assert abs(s.mean_n - round(s.median_n)) < 0.05 + 3 * noise
        # transients excluded: the lag has settled to within the tolerance inside every step
        held = true[s.start:s.stop]
        assert np.all(np.abs(held - round(s.median_n)) <= 0.3)


def test_holds_too_short_are_not_steps() -> None:
    t, x = staircase([0.0, 4.0, 8.0], hold_s=0.9, trials=1, rate_hz=1000.0, lag_s=0.0)
    assert detect_steps(t, x) == []
    # steady from 0.125 s after each change (half the window) plus 0.25 s settling dropped
    # up to 0.125 s before the next: 0.4 s of each 0.9 s hold is a step
    steps = detect_steps(t, x, StepSettings(min_hold_s=0.35))
    assert [round(s.median_n) for s in steps] == [0, 4, 8, 0]
    assert all(0.35 <= s.duration_s <= 0.9 for s in steps)


def test_a_slow_ramp_is_not_a_hold() -> None:
    t = np.linspace(0.0, 10.0, 5001)
    assert detect_steps(t, 2.0 * t) == []  # 2 N/s: 0.6 N band crossed in 0.3 s


def test_release_without_a_zero_hold_starts_a_trial() -> None:
    t = np.arange(0.0, 12.0, 0.002)
    x = np.select([t < 3, t < 3.2, t < 6, t < 9], [4.0, 0.0, 8.0, 4.0], 8.0)
    steps = detect_steps(t, x)
    assert [round(s.median_n) for s in steps] == [4, 8, 4, 8]
    assert [s.trial for s in steps] == [0, 1, 1, 1]


def test_settings_are_validated() -> None:
    for bad in ({"tolerance_n": 0.0}, {"min_hold_s": -1.0}, {"zero_n": float("nan")},
                {"despike_samples": 0}, {"settle_s": float("inf")}):
        with pytest.raises(InputError, match="steps."):
            StepSettings(**bad)


def test_the_return_to_zero_after_the_last_trial_is_its_unloading_step() -> None:
    """3 trials of the paper's 6 levels: 18 loading steps; the final 0 N hold unloads."""
    t, x = staircase([0.0, 4.0, 8.0, 12.0, 16.0, 20.0], hold_s=2.5, trials=3, rate_hz=200.0)
    steps = detect_steps(t, x)
    assert [s.phase for s in steps] == ["loading"] * 18 + ["unloading"]
    assert (steps[-1].trial, round(steps[-1].median_n)) == (2, 0)


def test_a_descending_staircase_unloads_and_a_zero_hold_between_trials_loads() -> None:
    t, x = staircase([0.0, 8.0, 16.0, 8.0], hold_s=2.5, trials=2, rate_hz=200.0)
    steps = detect_steps(t, x)
    assert [(s.trial, round(s.median_n), s.phase) for s in steps] == [
        (0, 0, "loading"), (0, 8, "loading"), (0, 16, "loading"), (0, 8, "unloading"),
        (1, 0, "loading"), (1, 8, "loading"), (1, 16, "loading"), (1, 8, "unloading"),
        (1, 0, "unloading")]


def test_phases_follow_the_direction_within_a_trial() -> None:
    assert assign_phases([0.0, 4.0, 4.1, 2.0, 1.9, 6.0, 0.0], [0, 0, 0, 0, 0, 0, 1], 0.3) == [
        "loading", "loading", "loading", "unloading", "unloading", "loading", "loading"]


def test_settings_for_a_hold_shrink_only_below_the_defaults() -> None:
    short = settings_for_hold(1.0)
    assert (short.settle_s, short.min_hold_s) == pytest.approx((0.1, 0.2))
    assert settings_for_hold(10.0) == StepSettings()
    t, x = staircase([0.0, 4.0, 8.0, 12.0], hold_s=1.0, trials=1, rate_hz=500.0, lag_s=0.05)
    assert len(detect_steps(t, x)) < 4
    assert [round(s.median_n) for s in detect_steps(t, x, short)] == [0, 4, 8, 12, 0]


@pytest.mark.parametrize("block", [1, 37, 1000])
def test_steadiness_taken_block_by_block_finds_the_same_steps(
        monkeypatch: pytest.MonkeyPatch, block: int) -> None:
    """The steadiness window (0.25 s: 125 samples) straddles the blocks' edges."""
    rng = np.random.default_rng(3)
    t, first = staircase([0.0, 4.0, 9.0, 13.0], hold_s=2.5, trials=2, rate_hz=500.0, lag_s=0.1)
    x = np.column_stack([first, 0.5 * first]) + rng.normal(0.0, 0.05, (t.size, 2))
    whole = detect_steps(t, x)  # the series fits in one block
    monkeypatch.setattr("tdcm_ros.metrics.steps._STEADY_BLOCK", block)
    assert len(whole) == 9 and detect_steps(t, x) == whole
