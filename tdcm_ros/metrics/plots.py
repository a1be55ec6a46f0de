"""Evaluation plots (needs matplotlib, the ``plot`` extra): shapes per step, error vs tension,
and a calibration's error before and after it with the calibrated shapes.

Every figure explains itself: a legend entry for each kind of line and marker, axis labels with
units, and (``shapes.png``) a caption saying why the markers are not on the measured midline:
they are the ball centres on the body surface, ``R_outer + ball radius`` off the midline, while
the measured midline is the spline through the markers moved back by that offset.
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from tdcm_ros.figures import save_figures
from tdcm_ros.metrics.evaluation import Evaluation

if TYPE_CHECKING:  # the metrics face imports this module; calibration loads scipy.optimize
    from tdcm_ros.metrics.calibration import Calibration

MM = 1e3
"""Metres to millimetres (plots are in mm)."""
PANEL_SIZE_IN = (3.8, 8.5)
"""Width and height of one trial's panel (inches)."""
FONT_SIZE = 10
"""Smallest font of the plots (pt): readable at 100 % zoom of a 120 dpi PNG."""


def marker_offset_m(evaluation: Evaluation) -> float:
    """Distance of the marker centres from the midline in the evaluation's layout (m)."""
    return float(evaluation.options.layout.radius(evaluation.options.design.R_outer))


def shapes_caption(evaluation: Evaluation) -> str:
    """Why the measured markers and the measured midline are apart (or not)."""
    offset_mm = marker_offset_m(evaluation) * MM
    if offset_mm < 1e-6:
        return "Markers are on the midline: the measured midline is a spline through them."
    layout = evaluation.options.layout
    source = ("on the body surface: R_outer + ball radius" if layout.radial_offset is None else
              "markers.radial_offset")
    return (f"Markers are ball centres {offset_mm:.2f} mm from the midline ({source}), "
            f"{layout.side_deg:g} deg around the body from the tendon side. The "
            "measured midline is a spline through the markers moved back by that offset, so it "
            f"runs {offset_mm:.1f} mm from them by construction; compare markers with markers "
            "and midlines with midlines.")


def tension_label(evaluation: Evaluation) -> str:
    """The axis label of a step's tension: its mean, the largest tendon's for several."""
    several = len(evaluation.options.design.tendon_list()) > 1
    return f"step mean tension{', largest tendon' if several else ''} (N)"


def shapes_figure(plt: Any, evaluation: Evaluation,
                  heading: str = "Measured and model shapes at each step") -> Any:
    """Measured and predicted midlines and markers, x-z plane of ``tdcm_base``, one panel per
    trial, colour = the step's mean tension; ``heading`` above the caption."""
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D

    records = evaluation.records
    trials = sorted({r.trial for r in records}) or [1]
    offset_mm = marker_offset_m(evaluation) * MM
    tensions = [r.tension_n for r in records] or [0.0]
    norm = Normalize(vmin=min(tensions), vmax=max(max(tensions), min(tensions) + 1e-9))
    cmap = plt.get_cmap("viridis")
    fig = plt.figure(figsize=(PANEL_SIZE_IN[0] * len(trials) + 1.5, PANEL_SIZE_IN[1]),
                     layout="constrained")
    axes = fig.subplots(1, len(trials), squeeze=False, sharey=True)
    for ax, trial in zip(axes[0], trials, strict=True):
        for r in (r for r in records if r.trial == trial):
            colour = cmap(norm(r.tension_n))
            if r.predicted_midline is not None:
                ax.plot(r.predicted_midline[:, 0] * MM, r.predicted_midline[:, 2] * MM, "-",
                        lw=1.4, color=colour)
            if r.measured_midline is not None:
                ax.plot(r.measured_midline[:, 0] * MM, r.measured_midline[:, 2] * MM, "--",
                        lw=1.4, color=colour)
            ax.plot(r.measured_markers[:, 0] * MM, r.measured_markers[:, 2] * MM, "o", ms=6,
                    mfc="none", mew=1.4, color=colour)
            if r.predicted_markers is not None:
                ax.plot(r.predicted_markers[:, 0] * MM, r.predicted_markers[:, 2] * MM, "x",
                        ms=6, mew=1.4, color=colour)
        ax.set_title(f"trial {trial}", fontsize=FONT_SIZE + 1)
        ax.set_xlabel("x in tdcm_base (mm)", fontsize=FONT_SIZE)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=FONT_SIZE)
    axes[0][0].set_ylabel("z in tdcm_base (mm)", fontsize=FONT_SIZE)
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=list(axes[0]), shrink=0.8)
    bar.set_label(tension_label(evaluation), fontsize=FONT_SIZE)
    handles = [
        Line2D([], [], color="k", ls="-", lw=1.4, label="model midline"),
        Line2D([], [], color="k", ls="none", marker="x", ms=6, label="model markers"),
        Line2D([], [], color="k", ls="--", lw=1.4,
               label=f"measured midline (spline through the markers moved {offset_mm:.1f} mm "
                     "to the midline)"),
        Line2D([], [], color="k", ls="none", marker="o", mfc="none", ms=6,
               label=f"measured markers (ball centres, {offset_mm:.1f} mm off the midline)"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=2, fontsize=FONT_SIZE)
    width = int(12 * fig.get_figwidth())  # characters of FONT_SIZE - 1 per line
    fig.suptitle(heading + "\n" + textwrap.fill(
        shapes_caption(evaluation), width), fontsize=FONT_SIZE - 1)
    return fig


def step_errors(evaluation: Evaluation, trial: int) -> tuple[np.ndarray, np.ndarray]:
    """A trial's usable steps: mean tension (N) and tip deflection error, predicted - measured
    (m)."""
    rows = [r for r in evaluation.records if r.usable and r.trial == trial]
    return (np.array([r.tension_n for r in rows]),
            np.array([(r.predicted_deflection_m or 0.0) - (r.measured_deflection_m or 0.0)
                      for r in rows]))


def calibration_figure(plt: Any, fit: Calibration) -> Any:
    """Tip deflection error per step before calibration (the nominal design) and after (the
    fitted one), per trial, with a sentence on what calibration did."""
    fig, ax = plt.subplots(figsize=(7.5, 5.0))
    fitted = ", ".join(f"{p.name} {p.initial:.4g} -> {p.value:.4g} {p.unit}".rstrip()
                       for p in fit.parameters)
    for k, trial in enumerate(sorted({r.trial for r in fit.before.records})):
        for evaluation, style, when in ((fit.before, "o--", "before"), (fit.after, "s-", "after")):
            tension, error = step_errors(evaluation, trial)
            ax.plot(tension, error * MM, style, color=f"C{k}", mfc="none" if when == "before"
                    else None, label=f"trial {trial}, {when} calibration")
    _error_axes(ax, fit.before)
    unexplained = "noise" if any(p.name == "mu" for p in fit.parameters) else "friction, noise"
    ax.set_title("Calibration fits " + fitted + "; what error is left after it is what the fitted "
                 f"model cannot explain ({unexplained})", fontsize=FONT_SIZE, wrap=True)
    fig.tight_layout()
    return fig


def write_calibration_plots(fit: Calibration, directory: str | Path, *, option: str = "--out"
                            ) -> list[Path]:
    """Write ``calibration.png`` (:func:`.calibration_figure`) and ``shapes_calibrated.png``
    (:func:`.shapes_figure` of the fitted model) of ``fit`` (a
    :class:`~tdcm_ros.metrics.calibration.Calibration`) into ``directory`` (created if
    missing)."""
    fitted = ", ".join(f"{p.name} = {p.value:.4g} {p.unit}" for p in fit.parameters)
    return save_figures(directory, option, (
        ("calibration.png", lambda plt: calibration_figure(plt, fit)),
        ("shapes_calibrated.png", lambda plt: shapes_figure(
            plt, fit.after, f"Measured and calibrated-model shapes ({fitted})"))))


def error_figure(plt: Any, evaluation: Evaluation) -> Any:
    """Tip deflection error (predicted - measured) against the step's mean tension, per trial."""
    fig, ax = plt.subplots(figsize=(7.0, 4.5))
    for trial in sorted({r.trial for r in evaluation.records}):
        tension, error = step_errors(evaluation, trial)
        ax.plot(tension, error * MM, "o-", label=f"trial {trial}")
    _error_axes(ax, evaluation)
    ax.set_title("model error at each step", fontsize=FONT_SIZE + 1)
    fig.tight_layout()
    return fig


def _error_axes(ax: Any, evaluation: Evaluation) -> None:
    """The zero line, labels (tension in ``evaluation``'s terms, error in mm), grid and legend
    of a tip-error-per-step plot."""
    ax.axhline(0.0, color="k", lw=0.8, label="no error")
    ax.set_xlabel(tension_label(evaluation), fontsize=FONT_SIZE)
    ax.set_ylabel("tip deflection error,\npredicted - measured (mm)", fontsize=FONT_SIZE)
    ax.tick_params(labelsize=FONT_SIZE)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=FONT_SIZE - 1)


def write_plots(evaluation: Evaluation, directory: str | Path, *, option: str = "--out"
                ) -> list[Path]:
    """Write ``shapes.png`` (:func:`.shapes_figure`) and ``error_vs_tension.png``
    (:func:`.error_figure`) into ``directory`` (created if missing; its parent must exist;
    ``option`` names it in errors)."""
    return save_figures(directory, option, (
        ("shapes.png", lambda plt: shapes_figure(plt, evaluation)),
        ("error_vs_tension.png", lambda plt: error_figure(plt, evaluation))))
