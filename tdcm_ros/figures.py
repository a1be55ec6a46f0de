"""The paper's simulation figures (Figs. 2, 3) and a feasibility map, as PNG (needs matplotlib).

- ``fig2.png``: notch widths ``w_n = 1, 1.9, 2.5 mm`` (``w_d = 1.5 mm``): (a) midlines at
  20 N, (b) curvature along ``s`` at 20 N, (c) design space ``w_n x T`` (fixed-pitch coupling,
  ``L = 53 mm``) with the three design curves on it.
- ``fig3.png``: backbone widths ``w_d = 1.2, 1.52, 2 mm`` (``w_n = 1.5 mm``), same panels.
- ``feasibility.png``: status of every point of wider ``w_n x T`` and ``w_d x T`` sweeps
  (bending strain above the allowable, notch closure, tendon-offset singularity).

Surfaces show feasible points only; infeasible ones are left out, never extrapolated.

Also the checks of every plot output option (``--plot FILE``, ``--out DIR``):
:func:`plot_file` and :func:`output_folder`. Nothing creates a parent folder it was not asked for.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tdcm_ros.errors import InputError
from tdcm_ros.model import (
    DEFAULT_ALLOWABLE_STRAIN,
    STATUSES,
    DesignSpace,
    Progress,
    design_curves,
    preset,
    report_progress,
    solve,
    sweep,
    within,
)
from tdcm_ros.plot_backend import load_pyplot

MM = 1e-3
PLOT_FORMATS = ("png", "pdf", "svg")
"""File extensions a plot may have: formats matplotlib writes with its default backends."""
T_BASE = 20.0
STATUS_COLOURS = {"ok": "#4c9a5b", "strain": "#e5b53c", "closure": "#c8553d",
                  "singularity": "#5b3c88", "non_convergence": "#555555", "invalid": "#bbbbbb"}


class PlotPathError(InputError):
    """A plot output path has an extension matplotlib cannot write or a missing parent."""


def _parent(option: str, path: Path) -> Path:
    """``path`` if its parent folder exists, else a :class:`PlotPathError` naming the parent."""
    parent = path.parent
    if not parent.is_dir():
        raise PlotPathError(f"{option} = {str(path)!r}: the folder {str(parent)!r} does not "
                            "exist; allowed: a path in an existing folder (it is not created)",
                            parameter=option, value=str(path), allowed="an existing parent folder")
    return path


def plot_file(option: str, path: str | Path) -> Path:
    """Check the plot file ``path`` given as ``option``: an extension of :data:`PLOT_FORMATS`
    and an existing parent folder."""
    out = Path(path)
    extension = out.suffix.lower().lstrip(".")
    if extension not in PLOT_FORMATS:
        allowed = ", ".join(f".{e}" for e in PLOT_FORMATS)
        raise PlotPathError(f"{option} = {str(out)!r} has extension {out.suffix or '(none)'!r};"
                            f" allowed: {allowed}", parameter=option, value=str(out),
                            allowed=allowed)
    return _parent(option, out)


def output_folder(option: str, path: str | Path) -> Path:
    """Create the output folder ``path`` given as ``option`` if needed; its parent must exist."""
    out = _parent(option, Path(path))
    try:
        out.mkdir(exist_ok=True)
    except OSError as error:
        raise PlotPathError(f"{option} = {str(out)!r}: cannot create the folder ({error})",
                            parameter=option, value=str(out), allowed="a writable folder"
                            ) from error
    return out


def save_figures(directory: str | Path, option: str,
                 figures: Sequence[tuple[str, Callable[[Any], Any]]]) -> list[Path]:
    """Each ``(name, make)`` of ``figures``: ``make(pyplot)`` saved as ``directory/name`` at 120
    dpi and closed; the folder created if missing (:func:`output_folder`, ``option`` names it in
    errors). Returns the files written."""
    plt = load_pyplot(option, Path(directory))
    out = output_folder(option, directory)
    for name, make in figures:
        fig = make(plt)
        fig.savefig(out / name, dpi=120)
        plt.close(fig)
    return [out / name for name, _ in figures]


@dataclass(frozen=True)
class FigureSpec:
    """One paper figure: the swept field, its range (m) and the three labelled presets."""

    name: str
    field: str
    symbol: str
    presets: tuple[str, ...]
    values_m: tuple[float, ...]
    sweep_m: tuple[float, float]
    coupling: str


FIGURES = (
    FigureSpec("fig2", "w_n", "w_n", ("fig2-wn-1", "fig2-wn-1.9", "fig2-wn-2.5"),
               (1.0 * MM, 1.9 * MM, 2.5 * MM), (0.5 * MM, 3.0 * MM), "fixed-pitch"),
    FigureSpec("fig3", "w_d", "w_d", ("fig3-wd-1.2", "fig3-wd-1.52", "fig3-wd-2"),
               (1.2 * MM, 1.52 * MM, 2.0 * MM), (0.8 * MM, 2.5 * MM), "none"),
)


def write_figures(out_dir: str | Path, *, points: int = 41, dpi: int = 130,
                  progress: Progress | None = None) -> list[Path]:
    """Write ``fig2.png``, ``fig3.png`` and ``feasibility.png`` to ``out_dir``; return paths.

    ``points`` is the grid size per sweep axis (field and tension). ``progress`` gets one stage
    per file: its sweep's designs, then one unit for drawing it.
    """
    if isinstance(points, bool) or not isinstance(points, int) or not 3 <= points <= 400:
        raise InputError(f"points = {points!r} is out of range; allowed: integer in [3, 400]",
                         parameter="points", value=points, allowed="integer in [3, 400]")
    plt = load_pyplot("matplotlib", None, subject="figures need")
    out = output_folder("--out", out_dir)
    tensions = np.linspace(0.0, T_BASE, points)
    paths = [_paper_figure(plt, spec, tensions, points, out / f"{spec.name}.png", dpi, progress)
             for spec in FIGURES]
    paths.append(_feasibility_figure(plt, points, out / "feasibility.png", dpi, progress))
    return paths


def _paper_figure(plt: Any, spec: FigureSpec, tensions: np.ndarray, points: int, path: Path,
                  dpi: int, progress: Progress | None) -> Path:
    designs = {f"${spec.symbol}$ = {v / MM:g} mm": preset(name)
               for name, v in zip(spec.presets, spec.values_m)}
    base = preset(spec.presets[1])
    values = np.union1d(np.linspace(*spec.sweep_m, points), spec.values_m)
    units = values.size + 1  # the sweep's designs, then drawing
    space = sweep(base, {spec.field: values}, tensions, coupling=spec.coupling,
                  progress=within(progress, path.name, 0, units))
    curves = design_curves(designs, tensions)

    fig = plt.figure(figsize=(15, 5.2))
    ax_a = fig.add_subplot(1, 3, 1)
    ax_b = fig.add_subplot(1, 3, 2)
    ax_c = fig.add_subplot(1, 3, 3, projection="3d")
    colours = ["#1f77b4", "#d62728", "#2ca02c"]
    for (label, design), colour in zip(designs.items(), colours):
        result = solve(design, T_BASE)
        positions, _ = result.pose_at(np.linspace(0.0, design.length, 300))
        ax_a.plot(positions[:, 0] / MM, positions[:, 2] / MM, color=colour, lw=2, label=label)
        s, kappa = result.curvature_profile
        ax_b.plot(s / MM, kappa, color=colour, lw=1.2, label=label)
    ax_a.plot([0.0, 0.0], [0.0, base.length / MM], "k--", lw=0.8, label="unloaded")
    ax_a.set_aspect("equal")
    ax_a.set_xlim(-4.0, max(ax_a.get_xlim()[1], 0.5 * base.length / MM))
    ax_a.set_xlabel("x (mm)")
    ax_a.set_ylabel("z (mm)")
    ax_a.set_title(f"(a) midlines at T = {T_BASE:g} N")
    ax_a.legend(fontsize=9, loc="lower right")
    ax_b.set_xlabel("arc length s (mm)")
    ax_b.set_ylabel("curvature κ (1/m)")
    ax_b.set_title(f"(b) curvature along s at T = {T_BASE:g} N")
    ax_b.set_ylim(top=1.3 * ax_b.get_ylim()[1])  # room above the peaks for the legend
    ax_b.legend(fontsize=9, loc="upper center", ncol=len(curves))
    _surface(ax_c, space, spec, curves, colours)
    fig.suptitle(f"{spec.name}: {spec.symbol} varied, E = {base.E / 1e9:g} GPa, "
                 f"L = {base.length / MM:g} mm", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    report_progress(progress, path.name, units, units)
    return path


def _surface(ax: Any, space: DesignSpace, spec: FigureSpec, curves: dict[str, Any],
             colours: list[str]) -> None:
    grid_w, grid_t = np.meshgrid(space.values[0] / MM, space.tensions, indexing="ij")
    deflection = np.where(space.feasible, space.tip_deflection_m, np.nan) / MM
    ax.plot_surface(grid_w, grid_t, deflection, cmap="viridis", alpha=0.75, linewidth=0,
                    antialiased=True)
    for (label, curve), colour, value in zip(curves.items(), colours, spec.values_m):
        shown = np.where(curve.status == "ok", curve.tip_deflection_m, np.nan) / MM
        ax.plot(np.full_like(curve.tensions, value / MM), curve.tensions, shown, color=colour,
                lw=2.5, label=f"design curve {label}")
    ax.set_xlabel(f"{spec.symbol} (mm)")
    ax.set_ylabel("tension T (N)")
    ax.set_zlabel("tip deflection d (mm)")
    ax.set_title("(c) design space and design curves")
    ax.view_init(elev=24, azim=-130)
    ax.legend(fontsize=8, loc="upper left")


def _feasibility_figure(plt: Any, points: int, path: Path, dpi: int,
                        progress: Progress | None) -> Path:
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    units = points * points + points + 1  # both sweeps' designs, then drawing
    by_width = sweep(preset("fig2-wn-1.9"),
                     {"w_n": np.geomspace(0.02 * MM, 5.5 * MM, points),
                      "w_d": np.linspace(0.3 * MM, 2.5 * MM, points)}, [T_BASE],
                     coupling="fixed-pitch", progress=within(progress, path.name, 0, units))
    by_tension = sweep(preset("fig3-wd-1.52"), {"w_d": np.linspace(0.3 * MM, 2.5 * MM, points)},
                       np.linspace(0.0, 2.0 * T_BASE, points),
                       progress=within(progress, path.name, points * points, units))
    panels = [
        (by_width, by_width.values[1] / MM, "w_d (mm)", by_width.status[..., 0],
         by_width.max_bending_strain[..., 0],
         f"w_n x w_d at T = {T_BASE:g} N (fixed-pitch, L = 53 mm)"),
        (by_tension, by_tension.tensions, "tension T (N)", by_tension.status,
         by_tension.max_bending_strain, "w_d x T (w_n = 1.5 mm)"),
    ]
    cmap = ListedColormap([STATUS_COLOURS[s] for s in STATUSES])
    norm = BoundaryNorm(np.arange(len(STATUSES) + 1) - 0.5, cmap.N)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    for ax, (space, y, y_label, status, strain, title) in zip(axes, panels):
        x = space.values[0] / MM
        codes = np.vectorize(STATUSES.index)(status)
        ax.pcolormesh(x, y, codes.T, cmap=cmap, norm=norm, shading="nearest")
        valid = np.where(np.isin(status, ("ok", "strain")), strain, np.nan)
        contour = ax.contour(x, y, valid.T * 100.0, levels=[1, 2, 4, 6, 8], colors="k",
                             linewidths=0.6)
        ax.clabel(contour, fmt="%g %%", fontsize=8)
        ax.set_xlabel(f"{space.fields[0]} (mm)")
        ax.set_ylabel(y_label)
        ax.set_title(f"feasibility over {title}", fontsize=9)
    axes[0].set_xscale("log")
    handles = [Patch(color=STATUS_COLOURS[s], label=s.replace("_", " ")) for s in STATUSES]
    fig.legend(handles=handles, loc="lower center", ncol=len(STATUSES), fontsize=9)
    fig.suptitle("Feasibility: notch bending strain |κ|·min(h1, R_outer) (contours, %) against "
                 f"the allowable {DEFAULT_ALLOWABLE_STRAIN * 100:g} % (Nylon 12 elongation at "
                 "break, Z), notch closure, tendon-offset singularity", fontsize=9)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    report_progress(progress, path.name, units, units)
    return path
