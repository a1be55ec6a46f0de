"""Plot of an inverse-design search: the designs that meet the target and their Pareto set."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tdcm_ros.errors import InputError
from tdcm_ros.model.inverse_design import DesignSearch

FONT_SIZE = 10
"""Smallest font of the plot (pt)."""
MAX_SHOWN = 20_000
"""Most ``meets`` designs drawn (an even subsample beyond; the Pareto set is always drawn)."""


def plot_search(search: DesignSearch, path: str | Path) -> Path:
    """Write two panels to ``path`` (.png, .pdf or .svg): tension needed against peak strain at
    the target, and reach against tension needed; every design that meets the target in grey,
    the Pareto set coloured by reach."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise InputError("--out needs matplotlib for the plot: pip install 'tdcm_ros[plot]'",
                         parameter="out", value=str(path), allowed="matplotlib installed") from exc
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
