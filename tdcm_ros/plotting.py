"""Plot of one solution: midline in the x-z plane and curvature along s (needs matplotlib)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.model import SolveResult

FONT_SIZE = 10
"""Smallest font of the plot (pt)."""


def solution_figure(plt: Any, result: SolveResult) -> Any:
    """Two panels: the midline (x-z plane of ``tdcm_base``, mm) with the notch centres and the
    unloaded body, and the curvature along the arc length with the notches shaded."""
    import numpy as np

    fig, (ax_shape, ax_k) = plt.subplots(1, 2, figsize=(11, 5),
                                         gridspec_kw={"width_ratios": [1, 2]})
    positions, _ = result.pose_at(np.linspace(0.0, result.design.length, 400))
    ax_shape.plot(positions[:, 0] * 1e3, positions[:, 2] * 1e3, "-", lw=2, label="midline")
    left, right = result.design.notch_bounds()
    notch_pts, _ = result.pose_at(0.5 * (left + right))
    ax_shape.plot(notch_pts[:, 0] * 1e3, notch_pts[:, 2] * 1e3, "o", ms=4, label="notch centres")
    ax_shape.plot([0, 0], [0, result.design.length * 1e3], "k--", lw=0.8,
                  label="unloaded (T = 0 N)")
    length_mm = result.design.length * 1e3
    x_mm = positions[:, 0] * 1e3
    ax_shape.set_xlim(min(-0.15 * length_mm, x_mm.min() - 2.0),  # room for the legend
                      max(0.45 * length_mm, x_mm.max() + 2.0))
    ax_shape.set_aspect("equal")
    ax_shape.set_xlabel("x in tdcm_base (mm)", fontsize=FONT_SIZE)
    ax_shape.set_ylabel("z in tdcm_base (mm)", fontsize=FONT_SIZE)
    ax_shape.set_title(f"midline at T = {result.tension_n:g} N", fontsize=FONT_SIZE + 1)
    ax_shape.legend(loc="lower right", fontsize=FONT_SIZE - 1)
    s, kappa = result.curvature_profile
    ax_k.plot(s * 1e3, kappa, "-", lw=1.2, label="curvature κ(s)")
    for index, (a, b) in enumerate(zip(left, right, strict=True)):
        ax_k.axvspan(a * 1e3, b * 1e3, color="0.85", lw=0, label="notches" if index == 0 else None)
    ax_k.set_xlabel("arc length s from the base (mm)", fontsize=FONT_SIZE)
    ax_k.set_ylabel("curvature κ (1/m)", fontsize=FONT_SIZE)
    ax_k.set_title("curvature along the midline (bending happens in the notches)",
                   fontsize=FONT_SIZE + 1)
    ax_k.legend(loc="best", fontsize=FONT_SIZE - 1)
    for ax in (ax_shape, ax_k):
        ax.tick_params(labelsize=FONT_SIZE)
    fig.tight_layout()
    return fig


def plot_solution(result: SolveResult, path: str | Path) -> Path:
    """Write :func:`solution_figure` of ``result`` to ``path`` (.png, .pdf or .svg)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise InputError("--plot needs matplotlib: pip install 'tdcm_ros[plot]'",
                         parameter="plot", value=str(path), allowed="matplotlib installed") from exc
    out = Path(path)
    fig = solution_figure(plt, result)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
