"""Shared helpers of the baselines: the result object on the design's grid, and limit checks."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.grid import Grid
from tdcm_ros.model.kinematics import PlanarShape
from tdcm_ros.model.limits import check_closure
from tdcm_ros.model.profiles import GIVEN_SECTION_PROFILES
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.tendons import require_paper_tendon

Array = NDArray[np.float64]


def require_centred(design: Design, method: str) -> None:
    """Raise :class:`InvalidDesignError` naming ``w_o`` unless every notch's backbone is on the
    tube axis, or ``profile`` where a notch's section is given whole (a polygon, a section's
    numbers, a mesh's slices): the baselines model the paper's symmetric notch only (the
    off-axis centroid's and given sections' mechanics are :func:`tdcm_ros.model.solve`'s),
    and its one tendon."""
    require_paper_tendon(design.tendons, f"the {method} baseline")
    given = [k for k, p in enumerate(design.notch_profiles())
             if isinstance(p, GIVEN_SECTION_PROFILES)]
    if given:
        name = design.notch_profiles()[given[0]].name
        raise InvalidDesignError(
            f"profile[{given[0]}] = {name!r}: the {method} baseline takes the paper's band "
            "notches (circular, rectangular or custom h1); allowed: those (solve a body of "
            "given sections with algorithm1)", parameter=f"profile[{given[0]}]", value=name,
            allowed="circular | rectangular | custom")
    offsets = design.per_notch("w_o")
    if offsets.any():
        raise InvalidDesignError(
            f"w_o = {design.to_dict()['w_o']!r}: the {method} baseline takes notches centred on "
            "the tube axis; allowed: 0 (solve such a body with algorithm1)", parameter="w_o",
            value=design.to_dict()["w_o"], allowed="0 m")


def node_result(grid: Grid, settings: SolverSettings, tension: float, *, x: Array, z: Array,
                theta: Array, cell_moments: Array, iterations: int,
                residual_history: tuple[float, ...], converged: bool, strategy: str,
                solve_time_s: float, check_limits: bool = True) -> SolveResult:
    """A :class:`SolveResult` from node arrays on ``grid`` (m, rad, N m).

    With ``check_limits`` the notch-closure check of the core model runs on the shape first,
    so a baseline raises the same :class:`NotchClosureError` the model would.
    """
    if check_limits:
        p = z + 1j * x
        check_closure(grid, PlanarShape(p=p, theta=theta, tangent=np.exp(1j * theta)), tension)
    positions = np.zeros((grid.s_nodes.size, 3))
    positions[:, 0] = x
    positions[:, 2] = z
    return SolveResult(design=grid.design, settings=settings, tension_n=tension,
                       s=grid.s_nodes, positions=positions, theta=theta,
                       cell_moments=cell_moments, iterations=iterations,
                       residual_history=residual_history, converged=converged,
                       strategy=strategy, solve_time_s=solve_time_s, grid=grid)


def uniform_moments(grid: Grid, moment: float) -> Array:
    """Cell end moments (cells, 2) all equal to ``moment`` (N m)."""
    return np.full((grid.n_cells, 2), moment)


def notch_compliance(grid: Grid) -> Array:
    """``int_notch ds/(E I)`` (1/(N m)) of every notch, from the grid's quadrature."""
    per_cell = grid.C0 + grid.C1
    out = np.zeros(grid.design.N)
    np.add.at(out, grid.notch_index[grid.is_notch], per_cell[grid.is_notch])
    return out
