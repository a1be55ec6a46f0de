"""Step detection: holds at one tension level, grouped into trials (staircases).

The tension is one column per tendon (one column for the paper's body). A *step* is a
contiguous run of samples in which every tendon's tension stays within ``tolerance_n`` of its
own median over the run, for at least ``min_hold_s``, once the transients are excluded:

1. each tendon's tension is despiked by a ``despike_samples`` median filter (single-sample
   glitches of the load cell); samples are *steady* where each despiked tension spans at most
   ``2 tolerance_n`` over a centred window of ``settle_s``: ramps and ringing between levels
   are cut out;
2. in each steady run, the longest contiguous stretch (of the despiked tensions) with every
   tendon within ``tolerance_n`` of its median is
   taken (the medians are re-taken on the stretch until it settles); the rest of the run is
   searched again, so a slow ramp through several levels can yield several steps;
3. the first ``settle_s`` of the stretch is dropped (settling after the change); what is left
   is a step if it lasts at least ``min_hold_s``. Each tendon's median and mean are of its
   measured samples, the mean over those within ``tolerance_n`` of the median (glitches left
   out): the step's tension is the vector of those means.

A step's *level* is its largest tendon median (the median itself for one tendon): every tendon
is released at a level at or below ``zero_n``. A *trial* is one staircase: a new trial starts
at the first step at or below ``zero_n`` (or the first step after the level dipped to
``zero_n``) once the current trial has risen above ``zero_n``. Steps at zero after the last
rise stay with the last trial.

Each step is *loading* or *unloading*: a trial's first step loads; a later step in which some
tendon is more than ``tolerance_n`` above its median in the step before loads, else one in
which some tendon is more than ``tolerance_n`` below it unloads, and a step within that band on
every tendon keeps the phase of the step before. So the return to 0 N after a
trial's last level is that trial's unloading step; a zero hold between two trials is one hold,
the start (loading) of the next trial. Table I uses the loading steps (the paper's protocol).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import maximum_filter1d, median_filter, minimum_filter1d

from tdcm_ros.spec import check_fields, spec_field, specs_of

Array = NDArray[np.float64]
_MEDIAN_PASSES = 4
_STEADY_BLOCK = 1 << 16
"""Samples whose steadiness is taken at a time (:func:`_steady`)."""
#: A step's phase: reached from below (loading) or from above (unloading) within its trial.
LOADING, UNLOADING = "loading", "unloading"


@dataclass(frozen=True)
class StepSettings:
    """Parameters of step detection (SI units), validated on construction."""

    tolerance_n: float = spec_field(0.3, unit="N", low=0.0, low_open=True, description=(
        "half-width of the band around the hold's median"))
    min_hold_s: float = spec_field(1.0, unit="s", low=0.0, low_open=True, description=(
        "shortest hold, after the transient is dropped"))
    settle_s: float = spec_field(0.25, unit="s", low=0.0, low_open=True, description=(
        "steadiness window and the settling time dropped at the start of a hold"))
    zero_n: float = spec_field(0.5, unit="N", low=0.0, description=(
        "tension at or below which the tendon counts as released (trial boundaries)"))
    despike_samples: int = spec_field(5, low=1, high=1001, description=(
        "median filter length (samples) applied before the steadiness test (1 = off)"))

    def __post_init__(self) -> None:
        check_fields(self, STEP_SPECS, prefix="steps.")


#: Specs of the step detection settings, by field name.
STEP_SPECS = specs_of(StepSettings)
#: Fractions of a schedule's hold time given to the steadiness window and the shortest hold.
SETTLE_PER_HOLD, MIN_HOLD_PER_HOLD = 0.1, 0.2


def settings_for_hold(hold_s: float) -> StepSettings:
    """Step settings for a schedule holding each level ``hold_s`` (s): the defaults, with
    ``settle_s`` at most a tenth and ``min_hold_s`` at most a fifth of the hold, so a hold
    shortened by its ramp, the actuator's settling and the steadiness windows is still found."""
    base = StepSettings()
    return replace(base, settle_s=min(base.settle_s, SETTLE_PER_HOLD * hold_s),
                   min_hold_s=min(base.min_hold_s, MIN_HOLD_PER_HOLD * hold_s))


@dataclass(frozen=True)
class Step:
    """One hold: samples ``[start, stop)`` of the tension series, stamps in s; each tendon's
    median and mean tension (N, a tuple in the series' column order)."""

    trial: int
    start: int
    stop: int
    start_s: float
    end_s: float
    medians_n: tuple[float, ...]
    means_n: tuple[float, ...]
    phase: str = LOADING

    @property
    def duration_s(self) -> float:
        """Length of the hold (s)."""
        return self.end_s - self.start_s

    @property
    def median_n(self) -> float:
        """The step's level: its largest tendon median (N)."""
        return max(self.medians_n)

    @property
    def mean_n(self) -> float:
        """Its largest tendon mean (N): the mean tension for one tendon."""
        return max(self.means_n)


def _true_runs(mask: NDArray[np.bool_]) -> NDArray[np.int64]:
    """(m, 2) ``[start, stop)`` of the runs of True in ``mask``."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return edges.reshape(-1, 2)


def _odd(n: int) -> int:
    return max(1, n | 1)


def _settle_window(t: Array, cfg: StepSettings) -> int:
    """Samples (odd) in ``settle_s`` at the median spacing of the stamps ``t`` (s)."""
    # the diffs are a temporary: the median may sort them in place (no second copy)
    dt = float(np.median(np.diff(t), overwrite_input=True)) if t.size > 1 else cfg.settle_s
    return _odd(round(cfg.settle_s / dt) if dt > 0 else 1)


def _steady(smooth: Array, window: int, cfg: StepSettings) -> NDArray[np.bool_]:
    """Samples where every column of ``smooth`` (n, J) spans at most ``2 tolerance_n`` over a
    centred ``window`` of samples (edges: the end samples repeated).

    Taken :data:`_STEADY_BLOCK` samples at a time, each with the half window either side: the
    filters' line buffers then hold a block, not the series (they took three times the
    series' bytes at once)."""
    half, n = window // 2, len(smooth)
    steady = np.empty(n, dtype=bool)
    for a in range(0, n, _STEADY_BLOCK):
        b = min(a + _STEADY_BLOCK, n)
        lo, hi = max(a - half, 0), min(b + half, n)
        span = maximum_filter1d(smooth[lo:hi], window, axis=0, mode="nearest")
        span -= minimum_filter1d(smooth[lo:hi], window, axis=0, mode="nearest")
        steady[a:b] = np.all(span[a - lo:b - lo] <= 2.0 * cfg.tolerance_n, axis=1)
    return steady


def _longest_band(x: Array, tol: float) -> tuple[int, int]:
    """``[a, b)`` of the longest stretch of ``x`` (m, J) with every column within ``tol`` of
    its own median (iterated)."""
    a, b = 0, len(x)
    for _ in range(_MEDIAN_PASSES):
        runs = _true_runs(np.all(np.abs(x - np.median(x[a:b], axis=0)) <= tol, axis=1))
        if runs.size == 0:
            return 0, 0
        longest = runs[np.argmax(runs[:, 1] - runs[:, 0])]
        if (longest[0], longest[1]) == (a, b):
            break
        a, b = int(longest[0]), int(longest[1])
    return a, b


def _holds(t: Array, x: Array, lo: int, hi: int, cfg: StepSettings) -> list[tuple[int, int]]:
    """Hold index ranges inside the steady run ``[lo, hi)`` of the despiked tensions ``x``
    (n, J) N."""
    found: list[tuple[int, int]] = []
    pending = [(lo, hi)]
    while pending:
        a, b = pending.pop()
        if b - a < 2 or t[b - 1] - t[a] < cfg.min_hold_s:
            continue
        ra, rb = _longest_band(x[a:b], cfg.tolerance_n)
        if rb <= ra:
            continue
        start, stop = a + ra, a + rb
        trimmed = int(np.searchsorted(t, t[start] + cfg.settle_s, side="left"))
        if trimmed < stop and t[stop - 1] - t[trimmed] >= cfg.min_hold_s:
            found.append((trimmed, stop))
        pending.extend([(a, start), (stop, b)])
    return found


def _hold_ranges(t: Array, x: Array, cfg: StepSettings) -> list[tuple[int, int]]:
    """Index ranges of the holds in the tensions ``x`` (n, J) N at stamps ``t`` (s), in time
    order (steps 1-3 of the module docstring, on the despiked tensions: freed on return)."""
    window = _settle_window(t, cfg)  # before the despiked copy: their temporaries never meet
    # each column on its own (a window along axis 0), into one array: no per-column copies
    smooth = median_filter(x, size=(cfg.despike_samples, 1), mode="nearest") \
        if cfg.despike_samples > 1 else x
    ranges: list[tuple[int, int]] = []
    for lo, hi in _true_runs(_steady(smooth, window, cfg)):
        ranges.extend(_holds(t, smooth, int(lo), int(hi), cfg))
    return sorted(ranges)


def sample_levels(tension_n: ArrayLike) -> Array:
    """Each sample's level (N): its largest tendon tension (``tension_n`` (n,) for one tendon or
    (n, J)); see the module docstring."""
    x = np.asarray(tension_n, dtype=float)
    return x if x.ndim == 1 else x.max(axis=1)


def detect_steps(stamps_s: Array, tension_n: Array, settings: StepSettings | None = None
                 ) -> list[Step]:
    """Steps of a tension series (stamps ascending, s; tensions N, (n,) for one tendon or
    (n, J) a column per tendon), in time order, with trials."""
    cfg = settings or StepSettings()
    t = np.asarray(stamps_s, dtype=float)
    if t.size < 2:
        return []
    x = np.asarray(tension_n, dtype=float).reshape(t.size, -1)
    ranges = _hold_ranges(t, x, cfg)
    medians = [tuple(float(np.median(column)) for column in x[a:b].T) for a, b in ranges]
    levels = sample_levels(x)
    previous_stops = [0, *(b for _, b in ranges)][:len(ranges)]
    dips = [float(levels[prev:a].min()) if a > prev else np.inf
            for (a, _), prev in zip(ranges, previous_stops, strict=True)]
    trials = assign_trials([max(m) for m in medians], dips, cfg.zero_n)
    steps = []
    for (start, stop), median, trial, phase in zip(
            ranges, medians, trials, assign_phases(medians, trials, cfg.tolerance_n),
            strict=True):
        means = tuple(float(np.mean(held[np.abs(held - m) <= cfg.tolerance_n]))
                      for held, m in zip(x[start:stop].T, median, strict=True))
        steps.append(Step(trial, start, stop, float(t[start]), float(t[stop - 1]), median, means,
                          phase))
    return steps


def assign_trials(levels: ArrayLike, dips: ArrayLike, zero_n: float) -> list[int]:
    """Trial (0-based) of each step from its level (N, see the module docstring) and the lowest
    level between it and the previous step (``dips``, N). Zero holds after the last rise stay
    with the last staircase (its unloading); a live stream re-assigns them when the next rise
    comes."""
    trials: list[int] = []
    trial, risen = 0, False
    for level, dip in zip(np.asarray(levels, dtype=float).tolist(),
                          np.asarray(dips, dtype=float).tolist(), strict=True):
        if risen and (level <= zero_n or dip <= zero_n):
            trial, risen = trial + 1, False
        risen = risen or level > zero_n
        trials.append(trial)
    if trial > 0 and not risen:
        trials = [k - 1 if k == trial else k for k in trials]
    return trials


def assign_phases(medians: ArrayLike, trials: ArrayLike, tolerance_n: float) -> list[str]:
    """Phase (:data:`LOADING` or :data:`UNLOADING`) of each step from its median tensions (N:
    (steps,) for one tendon, (steps, J) a column per tendon) and trial: a trial's first step
    loads; a later step loads where some tendon lies more than ``tolerance_n`` above the step
    before, else unloads where some tendon lies more than ``tolerance_n`` below it, and keeps
    its phase within that band."""
    rows = np.asarray(medians, dtype=float)
    rows = rows.reshape(len(rows), -1) if rows.size else rows.reshape(0, 1)
    trial = np.asarray(trials, dtype=int).tolist()
    phases: list[str] = []
    for k, (row, current) in enumerate(zip(rows, trial, strict=True)):
        if k == 0 or trial[k - 1] != current or np.any(row > rows[k - 1] + tolerance_n):
            phases.append(LOADING)
        elif np.any(row < rows[k - 1] - tolerance_n):
            phases.append(UNLOADING)
        else:
            phases.append(phases[-1])
    return phases
