"""Plots of a tracking run (needs matplotlib, the ``plot`` extra), in mm and s.

- ``tracking_paths.png``: the target, measured and predicted tip paths seen from above (x-y of
  ``tdcm_base``) and in the bending plane's coordinates (r = hypot(x, y) against z), the
  measured tip coloured by phase (feed-forward, feedback, feed-forward with the learned gain).
- ``tracking_error.png``: ``|measured - target|`` over time with the phases and their settle
  spans marked, and, when recorded, the controller's stiffness correction ``g`` with its
  standard deviation.
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

import numpy as np

from tdcm_ros.demo.tracking_report import PhaseError, TrackingRecord, lap_of, points_at
from tdcm_ros.figures import save_figures
from tdcm_ros.plotting import FONT_SIZE
from tdcm_ros.scenes import (
    FEEDBACK,
    FEEDFORWARD,
    FEEDFORWARD_LEARNED,
    PHASES,
    CircleTrajectory,
)

MM = 1e3
"""Metres to millimetres (plots are in mm)."""
PHASE_COLOURS = {FEEDFORWARD: "#d95f02", FEEDBACK: "#1b9e77", FEEDFORWARD_LEARNED: "#e7298a"}
PHASE_LABELS = {FEEDFORWARD: "feed-forward", FEEDBACK: "feedback",
                FEEDFORWARD_LEARNED: "feed-forward, learned gain"}


def _phases(record: TrackingRecord, circle: CircleTrajectory) -> np.ndarray:
    laps = lap_of(record, record.measured.log_s)
    return np.array([circle.phase_of_lap(int(lap)) if lap > 0 else "" for lap in laps])


CAPTION_WIDTH = 150
"""Characters per caption line."""


def paths_caption(world_gain: float | None) -> str:
    """What the paths figure shows, for a newcomer; ``world_gain`` = E_model / E_world."""
    if world_gain is None or world_gain == 1.0:
        miss = "misses it by the model's error"
    else:
        more = world_gain > 1.0
        miss = (f"bends {'further' if more else 'less'} than planned: the model is "
                f"{'stiffer' if more else 'softer'} than this world (E_model / E_world = "
                f"{world_gain:.4f})")
    return ("The tip should follow the black circle. Feed-forward alone (orange: the tension the "
            f"model asks for) {miss}; feedback (green) measures the tip and learns the model's "
            "error, and feed-forward with that learned gain (pink) stays on the circle without "
            "feedback.")


def error_caption() -> str:
    """What the error figure shows, for a newcomer."""
    return ("Top: how far the measured tip is from where it should be, per phase (the settle time "
            "after a phase starts is left out of its RMSE). Bottom: the controller's estimate of "
            "how much too stiff the model is, against this simulated world's truth (dashed); its "
            "band is the estimate's standard deviation, the prior's until feedback starts.")


def paths_figure(plt: Any, record: TrackingRecord, circle: CircleTrajectory,
                 world_gain: float | None = None) -> Any:
    """Two panels: x-y (top view) and r-z of the target, measured and predicted tips, under
    :func:`paths_caption`."""
    fig, (top, side) = plt.subplots(1, 2, figsize=(11.5, 5.6))
    target = record.targets.points * MM
    phases = _phases(record, circle)
    measured = record.measured.points * MM
    predicted = record.predicted.points * MM
    lapping = np.array([lap > 0 for lap in lap_of(record, record.predicted.log_s)], dtype=bool)
    for ax, column in ((top, lambda p: (p[:, 0], p[:, 1])),
                       (side, lambda p: (np.hypot(p[:, 0], p[:, 1]), p[:, 2]))):
        for phase in PHASES:
            pick = phases == phase
            if pick.any():
                ax.plot(*column(measured[pick]), ".", ms=2.0, color=PHASE_COLOURS[phase],
                        label=f"measured tip, {PHASE_LABELS[phase]}")
        ax.plot(*column(predicted[lapping]), "-", lw=0.6, color="0.45",
                label="predicted tip (model at the measured tension and roll)")
        ax.plot(*column(target), "-", lw=1.4, color="k", label="target")
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=FONT_SIZE)
    top.set_aspect("equal")
    top.set_xlabel("x in tdcm_base (mm)", fontsize=FONT_SIZE)
    top.set_ylabel("y in tdcm_base (mm)", fontsize=FONT_SIZE)
    top.set_title("seen from above (roll turns the bending plane)", fontsize=FONT_SIZE + 1)
    side.set_xlabel("r = distance from the base z axis (mm)", fontsize=FONT_SIZE)
    side.set_ylabel("z in tdcm_base (mm)", fontsize=FONT_SIZE)
    side.set_title("in the bending plane (the bend sets r and z)", fontsize=FONT_SIZE + 1)
    side.legend(loc="best", fontsize=FONT_SIZE - 1, markerscale=4)
    fig.suptitle(textwrap.fill(paths_caption(world_gain), CAPTION_WIDTH), fontsize=FONT_SIZE)
    fig.tight_layout()
    return fig


def error_figure(plt: Any, record: TrackingRecord, errors: list[PhaseError],
                 circle: CircleTrajectory, world_gain: float | None = None) -> Any:
    """The tip's distance from its target over time (the approach's larger error off the
    scale), and the controller's estimate with the scene's ``world_gain`` if given, under
    :func:`error_caption`."""
    gain = record.gain
    rows = 2 if gain is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(10.0, 3.6 * rows + 0.6), sharex=True,
                             squeeze=False)
    ax = axes[0][0]
    measured = record.measured
    distance = np.linalg.norm(measured.points - points_at(record.targets, measured.stamps_s),
                              axis=1)
    ax.plot(measured.stamps_s, distance * MM, "-", lw=0.6, color="0.3",
            label="|measured - target|")
    for error in errors:
        colour = PHASE_COLOURS[error.phase]
        ax.axvspan(error.start_s, error.start_s + circle.settle, color=colour, alpha=0.08, lw=0)
        ax.axvspan(error.window_s[0], error.window_s[1], color=colour, alpha=0.22, lw=0,
                   label=f"{PHASE_LABELS[error.phase]}: RMSE {error.rmse_m * MM:.3f} mm, max "
                         f"{error.max_m * MM:.3f} mm")
    if errors:
        ax.set_ylim(0.0, 1.6 * max(e.max_m for e in errors) * MM)
    ax.set_ylabel("tip error (mm)", fontsize=FONT_SIZE)
    ax.set_title("tracking error (light: settle time left out; dark: evaluated; the approach "
                 "from 0 N is off the scale)",
                 fontsize=FONT_SIZE + 1)
    ax.legend(loc="upper right", fontsize=FONT_SIZE - 1)
    if gain is not None:
        gax = axes[1][0]
        times = gain[0]
        gax.plot(times, gain[1], "-", color="#7570b3", label="controller/gain")
        if record.gain_std is not None and len(record.gain_std[1]) == len(gain[1]):
            spread = record.gain_std[1]
            gax.fill_between(times, gain[1] - spread, gain[1] + spread, color="#7570b3",
                             alpha=0.2, lw=0, label="± controller/gain_std (the prior's before "
                                                    "feedback)")
        if world_gain is not None:
            gax.axhline(world_gain, color="k", ls="--", lw=1.0,
                        label=f"the scene's E_model / E_world = {world_gain:.4f}")
        gax.set_ylabel("g = E_model / E_world (-)", fontsize=FONT_SIZE)
        gax.legend(loc="best", fontsize=FONT_SIZE - 1)
    for row in axes:
        row[0].grid(True, alpha=0.3)
        row[0].tick_params(labelsize=FONT_SIZE)
    axes[-1][0].set_xlabel("time from the first target (s)", fontsize=FONT_SIZE)
    fig.suptitle(textwrap.fill(error_caption(), CAPTION_WIDTH * 10 // 12), fontsize=FONT_SIZE)
    fig.tight_layout()
    return fig


def write_tracking_plots(record: TrackingRecord, errors: list[PhaseError],
                         circle: CircleTrajectory, directory: str | Path, *,
                         world_gain: float | None = None) -> list[Path]:
    """Write ``tracking_paths.png`` and ``tracking_error.png`` into ``directory`` (created if
    missing; its parent must exist); ``world_gain`` as in :func:`error_figure`."""
    return save_figures(directory, "--out", (
        ("tracking_paths.png", lambda plt: paths_figure(plt, record, circle, world_gain)),
        ("tracking_error.png", lambda plt: error_figure(plt, record, errors, circle,
                                                        world_gain))))
