"""Plots of model results (need matplotlib): one solution (midline in the x-z plane and
curvature along s), and an inverse-design search (the designs that meet the target and their
Pareto set)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tdcm_ros.model import DesignSearch, SolveResult, body_outline
from tdcm_ros.plot_backend import load_pyplot

FONT_SIZE = 10
"""Smallest font of the plot (pt)."""
MAX_SHOWN = 20_000
"""Most ``meets`` designs a search plot draws (an even subsample beyond; the Pareto set is
always drawn)."""


def solution_figure(plt: Any, result: SolveResult) -> Any:
    """Two panels: the body as it is cut (:func:`~tdcm_ros.model.body_outline`) with
    its midline, the notch centres and the unloaded axis (x-z plane of ``tdcm_base``, mm), and
    the curvature along the arc length with the notches shaded."""
    import numpy as np

    fig, (ax_shape, ax_k) = plt.subplots(1, 2, figsize=(11, 5),
                                         gridspec_kw={"width_ratios": [1, 2]})
    outline = body_outline(result)
    edge = np.concatenate([outline.tendon_side, outline.far_side[::-1]]) * 1e3
    ax_shape.fill(edge[:, 0], edge[:, 1], color="0.8", ec="0.4", lw=0.6, label="body, as cut")
    positions, _ = result.pose_at(np.linspace(0.0, result.design.length, 400))
    ax_shape.plot(positions[:, 0] * 1e3, positions[:, 2] * 1e3, "-", lw=2, label="midline")
    left, right = result.design.notch_bounds()
    notch_pts, _ = result.pose_at(0.5 * (left + right))
    ax_shape.plot(notch_pts[:, 0] * 1e3, notch_pts[:, 2] * 1e3, "o", ms=4, label="notch centres")
    ax_shape.plot([0, 0], [0, result.design.length * 1e3], "k--", lw=0.8,
                  label="unloaded (T = 0 N)")
    ax_shape.set_xlim(edge[:, 0].min() - 2.0,  # the body whole, room to bend toward +x
                      max(0.45 * result.design.length * 1e3, edge[:, 0].max() + 2.0))
    ax_shape.set_aspect("equal")
    ax_shape.set_xlabel("x in tdcm_base (mm)", fontsize=FONT_SIZE)
    ax_shape.set_ylabel("z in tdcm_base (mm)", fontsize=FONT_SIZE)
    ax_shape.set_title(f"body at T = {result.tension_n:g} N", fontsize=FONT_SIZE + 1)
    ax_shape.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2,
                    fontsize=FONT_SIZE - 1)  # below the axes: never over the body
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
    plt = load_pyplot("--plot", path)
    out = Path(path)
    fig = solution_figure(plt, result)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def plot_search(search: DesignSearch, path: str | Path) -> Path:
    """Write two panels to ``path`` (.png, .pdf or .svg): tension needed against peak strain at
    the target, and reach against tension needed; every design that meets the target in grey,
    the Pareto set coloured by reach."""
    import numpy as np

    plt = load_pyplot("--out", path)
    meets = np.flatnonzero(search.outcome == "meets")
    shown = meets[:: max(1, -(-meets.size // MAX_SHOWN))]
    front = search.pareto
    reach_scale, unit = (1e3, "mm") if search.unit == "m" else (1.0, "rad")
    fig, (ax_strain, ax_reach) = plt.subplots(1, 2, figsize=(11, 4.6))
    ax_strain.scatter(search.peak_strain[shown] * 100, search.tension_n[shown], s=3, c="0.75",
                      lw=0, label=f"meet the target ({meets.size})")
    dots = ax_strain.scatter(search.peak_strain[front] * 100, search.tension_n[front], s=28,
                             c=search.reach[front] * reach_scale, cmap="viridis",
                             edgecolors="k", lw=0.5, label=f"Pareto set ({front.size})")
    ax_strain.axvline(search.allowable_strain * 100, color="r", lw=0.8, ls="--",
                      label="allowable strain")
    ax_strain.set_xlabel("peak notch strain at the target (%)", fontsize=FONT_SIZE)
    ax_strain.set_ylabel("tension needed (N)", fontsize=FONT_SIZE)
    ax_strain.legend(loc="best", fontsize=FONT_SIZE - 1)
    fig.colorbar(dots, ax=ax_strain).set_label(f"reach ({unit})", fontsize=FONT_SIZE)
    ax_reach.scatter(search.tension_n[shown], search.reach[shown] * reach_scale, s=3, c="0.75",
                     lw=0)
    ax_reach.scatter(search.tension_n[front], search.reach[front] * reach_scale, s=28,
                     c="C1", edgecolors="k", lw=0.5, label="Pareto set")
    ax_reach.axhline(search.target * reach_scale, color="r", lw=0.8, ls="--", label="target")
    ax_reach.set_xlabel("tension needed (N)", fontsize=FONT_SIZE)
    ax_reach.set_ylabel(f"reach within 0-{search.tension_max_n:g} N ({unit})",
                        fontsize=FONT_SIZE)
    ax_reach.legend(loc="best", fontsize=FONT_SIZE - 1)
    target = search.target * reach_scale
    fig.suptitle(f"{search.target_kind.replace('_', ' ')} {target:g} {unit}: "
                 f"{search.outcome.size} candidates", fontsize=FONT_SIZE + 1)
    for ax in (ax_strain, ax_reach):
        ax.tick_params(labelsize=FONT_SIZE)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
