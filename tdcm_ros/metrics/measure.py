"""Measured side of the evaluation: marker frames assigned to tension steps, averaged per step.

Each marker frame takes the tension sample nearest its stamp within ``align_tolerance_s``; the
frame belongs to the step holding that sample. Per step, each marker's position is the mean over
the frames where it was visible; a marker never visible in a step leaves a NaN row and flags
the step.

Roll: each frame takes the roll at its stamp (:meth:`~tdcm_ros.metrics.series.RollSeries.at`;
0 without a roll series); a step's roll is the mean over its frames (the frames its markers are
averaged over) and its *roll spread* the largest minus the smallest of them. The evaluation
leaves a step out whose spread exceeds ``roll.tolerance_rad``
(:func:`tdcm_ros.metrics.evaluation.roll_note`) rather than average markers taken at different
rolls.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.metrics.align import nearest_within
from tdcm_ros.metrics.errors import MetricsError, NoStepsError
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.series import MarkerSeries, RollSeries, TensionSeries
from tdcm_ros.metrics.steps import Step, detect_steps

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class MeasuredStep:
    """A step with its mean tensions (N, one per tendon in the body's order) and mean marker
    positions (k, 3) m in the markers' frame (NaN rows: never visible in the step); ``frames``
    marker frames fell in the step; its roll (rad, the mean over those frames) and roll spread
    (rad, their largest minus smallest roll; see the module docstring)."""

    step: Step
    tensions_n: tuple[float, ...]
    markers: Array
    frames: int
    labels: tuple[str, ...]
    roll_rad: float = 0.0
    roll_spread_rad: float = 0.0

    @property
    def tension_n(self) -> float:
        """The largest of its tensions (N): the mean tension for one tendon."""
        return max(self.tensions_n)

    @property
    def missing(self) -> tuple[str, ...]:
        """Labels of the markers never visible during the step."""
        return tuple(lb for lb, row in zip(self.labels, self.markers, strict=True)
                     if np.isnan(row[0]))


def measure_steps(tension: TensionSeries, markers: MarkerSeries, options: EvaluateOptions,
                  roll: RollSeries | None = None) -> list[MeasuredStep]:
    """Detect the steps and average the markers (frame of ``markers``) and the roll (``None``:
    0 throughout) over each; ``tension`` has a column per tendon of ``options.design``, named as
    in its body file."""
    tendons = tuple(t.name for t in options.design.tendon_list())
    if (tension.names or tendons[:1]) != tendons:  # an unnamed series is the one tendon's
        raise MetricsError(
            f"tension columns {', '.join(tension.names) or '(one, unnamed)'} do not match the "
            f"design's tendons {', '.join(tendons)}; allowed: one column per tendon, in the "
            "body file's order", parameter="tension", value=tension.names,
            allowed=", ".join(tendons))
    markers.require_visible()
    steps = detect_steps(tension.stamps_s, tension.tension_n, options.steps)
    if not steps:
        cfg = options.steps
        every = " of every tendon" if tension.names else ""
        raise NoStepsError(
            f"no tension hold{every} within {cfg.tolerance_n:g} N for {cfg.min_hold_s:g} s in "
            f"{len(tension.stamps_s)} samples over {np.ptp(tension.stamps_s):.3g} s; adjust "
            "steps.tolerance_n / steps.min_hold_s", parameter="steps.min_hold_s",
            value=cfg.min_hold_s, allowed="a hold at least this long in the data")
    return average_markers(tension, markers, steps, options, roll)


def average_markers(tension: TensionSeries, markers: MarkerSeries, steps: Sequence[Step],
                    options: EvaluateOptions, roll: RollSeries | None = None
                    ) -> list[MeasuredStep]:
    """Mean marker positions and roll per step (steps index ``tension``'s samples, in time
    order and disjoint, as :func:`detect_steps` finds them; ``roll`` ``None``: 0 throughout)."""
    nearest = nearest_within(markers.stamps_s, tension.stamps_s, options.align_tolerance_s)
    frame_step = _step_of(nearest, steps)
    n = len(steps)
    counts = np.zeros((n, len(markers.labels)))
    sums = np.zeros((n, len(markers.labels), 3))
    frames = np.bincount(frame_step[frame_step >= 0], minlength=n)
    used = frame_step >= 0
    visible = markers.visible()[used]  # the frames in steps only: no copy of every frame
    np.add.at(counts, frame_step[used], visible)
    seen = markers.positions[used]  # a copy: the frames in steps, zero where not visible
    seen[~visible] = 0.0
    np.add.at(sums, frame_step[used], seen)
    with np.errstate(invalid="ignore", divide="ignore"):
        means = np.where(counts[:, :, None] > 0, sums / counts[:, :, None], np.nan)
    rolls = _step_rolls(roll, markers.stamps_s[used], frame_step[used], n)
    return [MeasuredStep(step, step.means_n, means[k], int(frames[k]), markers.labels,
                         *rolls[k]) for k, step in enumerate(steps)]


def _step_of(samples: NDArray[np.int64], steps: Sequence[Step]) -> NDArray[np.int64]:
    """The step (index into ``steps``: in time order, disjoint ``[start, stop)``) holding each
    tension sample index of ``samples``; -1 for an index in none or -1 (no sample)."""
    if not steps:
        return np.full(samples.shape, -1, dtype=np.int64)
    starts = np.array([step.start for step in steps], dtype=np.int64)
    stops = np.array([step.stop for step in steps], dtype=np.int64)
    k = np.searchsorted(starts, samples, side="right") - 1
    inside = (samples >= 0) & (k >= 0) & (samples < stops[np.maximum(k, 0)])
    return np.where(inside, k, -1)


def _step_rolls(roll: RollSeries | None, stamps_s: Array, step_of_frame: NDArray[np.int64],
                n: int) -> list[tuple[float, float]]:
    """Per step of ``n``: the mean roll (rad) over its frames (stamps s, ``step_of_frame`` their
    step) and the roll spread (rad); (0, 0) without ``roll`` or frames."""
    if roll is None:
        return [(0.0, 0.0)] * n
    at = roll.at(stamps_s)
    out = []
    for k in range(n):
        own = at[step_of_frame == k]
        out.append((float(np.mean(own)), float(np.ptp(own))) if own.size else (0.0, 0.0))
    return out
