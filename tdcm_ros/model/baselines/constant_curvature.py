"""Constant-curvature baseline: the whole body as one circular arc.

The arc's curvature is the mean over ``s`` of ``m / (E I(s))`` with the tendon moment
``m = R_c T`` (N m), i.e. ``kappa = R_c T / L * int_0^L ds / (E I)`` (1/m). The tip angle is
therefore the model's small-deflection tip angle; the shape ignores where the compliance
sits (notches vs tubes). ``cell_moments`` holds the assumed ``R_c T`` everywhere; the result's
``curvature_profile`` (which uses the grid's compliance) does not describe the arc.
"""

from __future__ import annotations

from time import perf_counter

import numpy as np

from tdcm_ros.model.baselines.common import (
    node_result,
    require_centred,
    uniform_moments,
)
from tdcm_ros.model.design import Design
from tdcm_ros.model.grid import build_grid
from tdcm_ros.model.limits import check_tension
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS

NAME = "constant-curvature"


def solve_constant_curvature(design: Design, tension: float, *,
                             settings: SolverSettings = DEFAULT_SETTINGS) -> SolveResult:
    """One arc of length ``L`` (m) with the mean curvature under ``R_c T``; nodes on the grid."""
    started = perf_counter()
    t = check_tension(tension)
    require_centred(design, "constant-curvature")
    grid = build_grid(design, settings)
    moment = design.R_c * t
    kappa = moment * float(np.sum(grid.C0 + grid.C1)) / design.length
    s = grid.s_nodes
    theta = kappa * s
    if kappa == 0.0:
        x, z = np.zeros_like(s), s.copy()
    else:
        x, z = (1.0 - np.cos(theta)) / kappa, np.sin(theta) / kappa
    return node_result(grid, settings, t, x=x, z=z, theta=theta,
                       cell_moments=uniform_moments(grid, moment), iterations=1,
                       residual_history=(0.0,), converged=True, strategy=NAME,
                       solve_time_s=perf_counter() - started)
