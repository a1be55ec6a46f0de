"""Plot of one solution: midline in the x-z plane and curvature along s (needs matplotlib)."""

from __future__ import annotations

from pathlib import Path

from tdcm_ros.errors import InputError
from tdcm_ros.model import SolveResult


def plot_solution(result: SolveResult, path: str | Path) -> Path:
    """Write a two-panel PNG (midline, curvature) of ``result`` to ``path``."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise InputError("--plot needs matplotlib: pip install 'tdcm_ros[plot]'",
                         parameter="plot", value=str(path), allowed="matplotlib installed") from exc
    out = Path(path)
    import numpy as np

    fig, (ax_shape, ax_k) = plt.subplots(1, 2, figsize=(10, 4.5),
                                         gridspec_kw={"width_ratios": [1, 2]})
    positions, _ = result.pose_at(np.linspace(0.0, result.design.length, 400))
    ax_shape.plot(positions[:, 0] * 1e3, positions[:, 2] * 1e3, "-", lw=2, label="midline")
    left, right = result.design.notch_bounds()
    notch_pts, _ = result.pose_at(0.5 * (left + right))
    ax_shape.plot(notch_pts[:, 0] * 1e3, notch_pts[:, 2] * 1e3, "o", ms=4, label="notch centres")
    ax_shape.plot([0, 0], [0, result.design.length * 1e3], "k--", lw=0.8, label="unloaded")
    ax_shape.set_aspect("equal")
    ax_shape.set_xlabel("x (mm)")
    ax_shape.set_ylabel("z (mm)")
    ax_shape.set_title(f"midline at T = {result.tension_n:g} N")
    ax_shape.legend(loc="best", fontsize=8)
    s, kappa = result.curvature_profile
    ax_k.plot(s * 1e3, kappa, "-", lw=1.2)
    ax_k.set_xlabel("s (mm)")
    ax_k.set_ylabel("curvature (1/m)")
    ax_k.set_title("curvature along the midline")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
