"""Pseudo-rigid-body baseline: one revolute joint per notch, rigid links between.

Joint ``i`` sits at the notch centre ``c_i = (l_i + r_i)/2`` (m) with torsional stiffness
``k_i = 1 / int_notch ds/(E I)`` (N m/rad). It carries the tendon moment ``R_c T`` (N m),
exact for the paper's routing inside a notch, so it turns by ``R_c T / k_i`` (rad). Tube
compliance is **neglected** (links are rigid): the tubes' share of the bend is the error
this baseline makes by construction, besides lumping each notch's rotation at its centre.
"""

from __future__ import annotations

from time import perf_counter

import numpy as np

from tdcm_ros.model.baselines.common import (
    node_result,
    notch_compliance,
    require_centred,
    uniform_moments,
)
from tdcm_ros.model.design import Design
from tdcm_ros.model.grid import build_grid
from tdcm_ros.model.limits import check_tension
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS

NAME = "pseudo-rigid-body"


def solve_pseudo_rigid_body(design: Design, tension: float, *,
                            settings: SolverSettings = DEFAULT_SETTINGS) -> SolveResult:
    """Joint angles ``R_c T int_notch ds/(E I)`` at notch centres; node poses on the grid."""
    started = perf_counter()
    t = check_tension(tension)
    require_centred(design, "pseudo-rigid-body")
    grid = build_grid(design, settings)
    moment = design.R_c * t
    joint_angle = moment * notch_compliance(grid)
    left, right = design.notch_bounds()
    joints = 0.5 * (left + right)
    s = grid.s_nodes
    # Breakpoints: every node and every joint; the link angle is constant between them.
    marks = np.union1d(s, joints)
    turned = np.concatenate([[0.0], np.cumsum(joint_angle)])
    angle = turned[np.searchsorted(joints, marks[:-1], side="right")]
    step = np.diff(marks)
    x = np.concatenate([[0.0], np.cumsum(step * np.sin(angle))])
    z = np.concatenate([[0.0], np.cumsum(step * np.cos(angle))])
    at_nodes = np.searchsorted(marks, s)
    theta = turned[np.searchsorted(joints, s, side="right")]
    return node_result(grid, settings, t, x=x[at_nodes], z=z[at_nodes], theta=theta,
                       cell_moments=uniform_moments(grid, moment), iterations=1,
                       residual_history=(0.0,), converged=True, strategy=NAME,
                       solve_time_s=perf_counter() - started)
