"""Plots of model results (need matplotlib): one solution (midline in the x-z plane and
curvature along s), an inverse-design search (the designs that meet the target and their
Pareto set) and a shape design (target against achieved shape)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tdcm_ros.model import (
    CurveTarget,
    DesignSearch,
    NotchAngleTarget,
    ShapeDesign,
    SolveResult,
    TipTarget,
    body_outline,
)
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
    the Pareto set coloured by reach (one Pareto design: its reach in the legend)."""
    import numpy as np

    plt = load_pyplot("--out", path)
    meets = np.flatnonzero(search.outcome == "meets")
    shown = meets[:: max(1, -(-meets.size // MAX_SHOWN))]
    front = search.pareto
    reach_scale, unit = (1e3, "mm") if search.unit == "m" else (1.0, "rad")
    fig, (ax_strain, ax_reach) = plt.subplots(1, 2, figsize=(11, 4.6))
    ax_strain.scatter(search.peak_strain[shown] * 100, search.tension_n[shown], s=3, c="0.75",
                      lw=0, label=f"meet the target ({meets.size})")
    if front.size > 1:  # coloured by reach; one design has no range to colour
        dots = ax_strain.scatter(search.peak_strain[front] * 100, search.tension_n[front],
                                 s=28, c=search.reach[front] * reach_scale, cmap="viridis",
                                 edgecolors="k", lw=0.5, label=f"Pareto set ({front.size})")
        fig.colorbar(dots, ax=ax_strain).set_label(f"reach ({unit})", fontsize=FONT_SIZE)
    else:
        reach = ", ".join(f"reach {v * reach_scale:.3g} {unit}" for v in search.reach[front])
        ax_strain.scatter(search.peak_strain[front] * 100, search.tension_n[front], s=28,
                          c="C1", edgecolors="k", lw=0.5,
                          label=f"Pareto set ({front.size}{': ' + reach if reach else ''})")
    ax_strain.axvline(search.allowable_strain * 100, color="r", lw=0.8, ls="--",
                      label="allowable strain")
    ax_strain.set_xlabel("peak notch strain at the target (%)", fontsize=FONT_SIZE)
    ax_strain.set_ylabel("tension needed (N)", fontsize=FONT_SIZE)
    ax_strain.legend(loc="best", fontsize=FONT_SIZE - 1)
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
    return _save(plt, fig, (ax_strain, ax_reach), path)


def plot_shape_design(found: ShapeDesign, path: str | Path) -> Path:
    """Write two panels to ``path``: the achieved midline at each load with the target tip
    poses and curves, and each notch's bend (deg) at each load with a notch-angle target's
    mean or angles."""
    import numpy as np

    plt = load_pyplot("--out", path)
    fig, (ax_shape, ax_notch) = plt.subplots(1, 2, figsize=(11, 4.8))
    results = found.evaluation.results
    loads = list(results)
    width = 0.8 / max(1, len(loads))
    for k, load in enumerate(loads):
        result = results[load]
        ax_shape.plot(result.positions[:, 0] * 1e3, result.positions[:, 2] * 1e3, lw=2,
                      color=f"C{k}", label=f"achieved at {load.label}")
        phi = np.degrees(result.notch_angles_rad)
        ax_notch.bar(np.arange(phi.size) + 1 + (k - (len(loads) - 1) / 2) * width, phi, width,
                     color=f"C{k}", label=f"achieved at {load.label}")
    for goal in found.problem.goals:
        colour = f"C{loads.index(goal.load)}"
        target = goal.target
        if isinstance(target, CurveTarget):
            ax_shape.plot(target.points[:, 0] * 1e3, target.points[:, 1] * 1e3, "x", ms=6,
                          color="k", label=f"target curve at {goal.load.label}")
        elif isinstance(target, TipTarget):
            result = results[goal.load]
            x = result.tip_position[0] if target.x is None else target.x
            z = result.tip_position[2] if target.z is None else target.z
            angle = result.tip_angle_rad if target.angle is None else target.angle
            reach = 0.15 * float(result.s[-1]) * 1e3  # a tangent 15 % of the body long (mm)
            ax_shape.plot([x * 1e3, x * 1e3 + reach * np.sin(angle)],
                          [z * 1e3, z * 1e3 + reach * np.cos(angle)], "k--", lw=1)
            ax_shape.plot([x * 1e3], [z * 1e3], "ko", mfc="none", ms=8,
                          label=f"target tip (and its tangent) at {goal.load.label}")
        elif isinstance(target, NotchAngleTarget):
            phi = np.degrees(results[goal.load].notch_angles_rad)
            if target.kind == "angles":
                ax_notch.plot(np.arange(phi.size) + 1, np.degrees(target.angles), "k_", ms=18,
                              mew=2, label="target angles")
            elif target.kind == "equal":
                ax_notch.axhline(phi.mean(), color=colour, ls="--", lw=0.8,
                                 label=f"mean; target within {target.tol:.0%}")
            else:
                ax_notch.axhline(phi[0] * target.ratio, color=colour, ls="--", lw=0.8,
                                 label=f"{target.ratio:g} x the first notch")
    ax_shape.set_aspect("equal", adjustable="datalim")
    ax_shape.set_xlabel("x (mm, toward the tendon)", fontsize=FONT_SIZE)
    ax_shape.set_ylabel("z (mm, along the unbent body)", fontsize=FONT_SIZE)
    ax_shape.legend(loc="best", fontsize=FONT_SIZE - 1)
    ax_notch.set_xlabel("notch (1 at the base)", fontsize=FONT_SIZE)
    ax_notch.xaxis.get_major_locator().set_params(integer=True)
    ax_notch.set_ylabel("bend across the notch (deg)", fontsize=FONT_SIZE)
    ax_notch.legend(loc="best", fontsize=FONT_SIZE - 1)
    verdict = "every target met" if found.evaluation.met else "closest design (not met)"
    fig.suptitle(f"shape design: {verdict}", fontsize=FONT_SIZE + 1)
    return _save(plt, fig, (ax_shape, ax_notch), path)


def _save(plt: Any, fig: Any, axes: tuple[Any, ...], path: str | Path) -> Path:
    """Label sizes, layout, and ``fig`` written to ``path`` (its folder made) and closed."""
    for ax in axes:
        ax.tick_params(labelsize=FONT_SIZE)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
