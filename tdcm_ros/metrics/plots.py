"""Evaluation plots (needs matplotlib, the ``plot`` extra): shapes per step, error vs tension."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from tdcm_ros.errors import InputError
from tdcm_ros.figures import output_folder
from tdcm_ros.metrics.evaluation import Evaluation


def _pyplot(target: Path) -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise InputError("--plots needs matplotlib: pip install 'tdcm_ros[plot]'",
                         parameter="plots", value=str(target),
                         allowed="matplotlib installed") from exc
    return plt


def write_plots(evaluation: Evaluation, directory: str | Path) -> list[Path]:
    """Write ``shapes.png`` (measured and predicted midlines and markers, x-z plane of
    ``tdcm_base``, one panel per trial) and ``error_vs_tension.png`` into ``directory`` (created
    if missing; its parent must exist)."""
    plt = _pyplot(Path(directory))
    out = output_folder("--plots", directory)
    records = evaluation.records
    trials = sorted({r.trial for r in records})
    fig, axes = plt.subplots(1, len(trials), figsize=(4 * len(trials), 5), squeeze=False,
                             sharey=True)
    for ax, trial in zip(axes[0], trials, strict=True):
        for r in (r for r in records if r.trial == trial):
            if r.predicted_midline is not None:
                line = ax.plot(r.predicted_midline[:, 0] * 1e3, r.predicted_midline[:, 2] * 1e3,
                               "-", lw=1.2, label=f"{r.tension_n:.1f} N model")[0]
                colour = line.get_color()
            else:
                colour = "k"
            if r.measured_midline is not None:
                ax.plot(r.measured_midline[:, 0] * 1e3, r.measured_midline[:, 2] * 1e3, "--",
                        lw=1.2, color=colour)
            ax.plot(r.measured_markers[:, 0] * 1e3, r.measured_markers[:, 2] * 1e3, "o",
                    ms=4, mfc="none", color=colour)
        ax.set_title(f"trial {trial}: model (solid), measured (dashed, markers o)", fontsize=8)
        ax.set_xlabel("x (mm)")
        ax.set_aspect("equal")
        ax.legend(fontsize=6, loc="best")
    axes[0][0].set_ylabel("z (mm)")
    fig.tight_layout()
    shapes = out / "shapes.png"
    fig.savefig(shapes, dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 4))
    usable = [r for r in records if r.usable]
    for trial in trials:
        rows = [r for r in usable if r.trial == trial]
        tension = np.array([r.tension_n for r in rows])
        error = np.array([(r.predicted_deflection_m or 0.0) - (r.measured_deflection_m or 0.0)
                          for r in rows])
        ax.plot(tension, error * 1e3, "o-", label=f"trial {trial}")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("tension (N)")
    ax.set_ylabel("tip deflection error, predicted - measured (mm)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    errors = out / "error_vs_tension.png"
    fig.savefig(errors, dpi=120)
    plt.close(fig)
    return [shapes, errors]
