"""Axial compression (``SolverSettings.axial = "compressible"``): the body shortens by
``T / (E A)`` per metre under the tendons' resultant, against quadrature of ``1/A(s)`` and an
ODE of the extensible rod written here; the rigid midline stays the paper's."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from tdcm_ros.model import (
    SolverSettings,
    Tendon,
    preset,
    solve,
)
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.design import Design
from tdcm_ros.model.section import notched_moment
from test.model.test_result import tendon_path_length

PAPER = preset("paper-experiment")
SOFT = SolverSettings(axial="compressible")


def half_width(design: Design, sigma: float) -> float:
    """Eq. 13: the circular notch's half-width (m) at ``sigma`` (m) into it."""
    w_n, w_d = design.w_n, design.w_d
    return (w_n + w_d) / 2.0 - math.sqrt(max(sigma * (w_n - sigma), 0.0))


def strip_area(h: float, radius: float) -> float:
    """Area (m^2) of the disc of ``radius`` where ``|x| <= h``: ``4 int_0^h sqrt(R^2 - y^2)``."""
    h = min(h, radius)
    return 2.0 * (h * math.sqrt(radius**2 - h**2) + radius**2 * math.asin(h / radius))


def area(design: Design, sigma: float) -> float:
    """The paper's band section's area (m^2) in a notch, ``sigma`` (m) into it."""
    h1 = half_width(design, sigma)
    return strip_area(h1, design.R_outer) - strip_area(min(h1, design.r_inner), design.r_inner)


def shortening_per_newton(design: Design) -> tuple[float, float]:
    """``int ds / (E A)`` (m/N) over the notches and over the tubes of ``design``."""
    notch = quad(lambda sigma: 1.0 / (design.E * area(design, sigma)), 0.0, design.w_n,
                 epsabs=0.0, epsrel=1e-12, limit=200)[0] * design.N
    tube = (design.length - design.N * design.w_n) / (
        design.E * math.pi * (design.R_outer**2 - design.r_inner**2))
    return notch, tube


@pytest.mark.parametrize("modulus", [1.85e9, 0.774e9])
def test_equal_antagonistic_tensions_shorten_the_straight_body_by_the_quadrature(
        modulus: float) -> None:
    """Issue 28: the paper's body shortens by 0.03 mm (1.85 GPa) to 0.07 mm (0.774 GPa) at
    20 N, about two thirds of it in the notches. At 64 cells a notch (the default 4 is 3.6e-8
    off: its Gauss points near the notch ends, where ``1/A`` is steep)."""
    design = PAPER.with_overrides(E=modulus)
    pair = dataclasses.replace(design, tendons=(Tendon(design.R_c), Tendon(-design.R_c)))
    result = solve(pair, [10.0, 10.0], settings=dataclasses.replace(SOFT, cells_per_notch=64))
    notch, tube = shortening_per_newton(design)
    assert np.all(result.positions[:, 0] == 0.0)
    assert design.length - result.tip_position[2] == pytest.approx(20.0 * (notch + tube),
                                                                   rel=1e-9)
    assert 0.6 < notch / (notch + tube) < 0.75
    assert 2.5e-5 < 20.0 * (notch + tube) < 8e-5


def test_a_bent_compressible_body_matches_an_ode_of_the_extensible_rod() -> None:
    """A body of notches only, its tendon following the body everywhere (moment exactly
    ``R_c T``): scipy's DOP853 of ``x' = (1 - T/(E A)) sin theta``, ``z' = (1 - T/(E A))
    cos theta``, ``theta' = R_c T / (E I)``."""
    design = PAPER.with_overrides(w_base=0.0, w_t=0.0, w_tip=0.0, E=0.774e9)
    tension = 12.0
    result = solve(design, tension, settings=SolverSettings(axial="compressible",
                                                            cells_per_notch=64))

    def rhs(s: float, y: np.ndarray, left: float) -> list[float]:
        sigma = s - left
        inertia = float(notched_moment(half_width(design, sigma), design.R_outer,
                                       design.r_inner))
        squeeze = 1.0 - tension / (design.E * area(design, sigma))
        return [squeeze * math.sin(y[2]), squeeze * math.cos(y[2]),
                design.R_c * tension / (design.E * inertia)]

    y = np.zeros(3)
    for left, right in zip(*design.notch_bounds(), strict=True):
        y = solve_ivp(rhs, (left, right), y, method="DOP853", args=(left,), rtol=1e-12,
                      atol=1e-15).y[:, -1]
    rigid = solve(design, tension, settings=SolverSettings(cells_per_notch=64))
    assert abs(rigid.tip_position[2] - y[1]) > 1e-5  # the effect is not below the check
    assert result.tip_position[0] == pytest.approx(y[0], abs=2e-11)
    assert result.tip_position[2] == pytest.approx(y[1], abs=2e-11)
    assert result.tip_angle_rad == pytest.approx(rigid.tip_angle_rad, abs=1e-15)


@pytest.mark.parametrize("routing", ["paper", "free"])
def test_poses_and_the_tendon_length_follow_the_shortened_body(routing: str) -> None:
    """``pose_at`` at the nodes is the solve's node (the shortening integrated by the same
    weights) and the tendon's length is its path drawn from ``pose_at`` (Richardson-
    extrapolated polylines, as for the rigid body) to a nanometre."""
    result = solve(PAPER, 15.0, settings=dataclasses.replace(SOFT, routing=routing))
    positions, _ = result.pose_at(result.s)
    assert np.max(np.abs(positions - result.positions)) <= 2e-9
    coarse, fine = tendon_path_length(result, 64), tendon_path_length(result, 128)
    assert result.tendon_lengths_m[0] == pytest.approx((4.0 * fine - coarse) / 3.0, abs=1e-9)
    rigid = solve(PAPER, 15.0, settings=SolverSettings(routing=routing))
    assert result.tendon_strokes_m[0] > rigid.tendon_strokes_m[0] + 1e-5


def test_the_rigid_midline_is_the_default_and_the_batch_solves_compression_as_solve() -> None:
    assert SolverSettings().axial == "rigid"
    assert not solve(PAPER, 20.0).grid.compressible
    batch = solve_batch([PAPER], [1.0], settings=SOFT)
    assert batch.fallback[0]
    assert np.array_equal(batch.tip_position[0], solve(PAPER, 1.0, settings=SOFT).tip_position)
