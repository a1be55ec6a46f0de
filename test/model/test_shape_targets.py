"""Shape targets and limits: the arc against the circle it lies on, curve distances against
dense sampling, the notches' hard stop against ``N w_n / R_outer``, residual semantics."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from tdcm_ros.model import RectangularProfile, preset, solve
from tdcm_ros.model.inverse import InvalidTargetError
from tdcm_ros.model.shape_targets import (
    CurveTarget,
    Limits,
    NotchAngleTarget,
    StopAngleTarget,
    TipTarget,
    lower_bound,
)

PAPER = preset("paper-experiment")


def fake(**fields: Any) -> Any:
    """A stand-in of a solve's result holding only the fields a target reads."""
    return SimpleNamespace(**fields)


@pytest.mark.parametrize("angle", [0.3, 1.0472, -0.8, 2.5])
def test_an_arc_lies_on_its_circle_with_equal_steps_along_it(angle: float) -> None:
    length = 0.053
    target = CurveTarget.arc(length, angle, points=12)
    radius = length / angle
    centre = np.array([radius, 0.0])
    assert np.hypot(*(target.points - centre).T) == pytest.approx(abs(radius), rel=1e-12)
    chords = np.hypot(*np.diff(np.vstack([[0.0, 0.0], target.points]), axis=0).T)
    step = length / 12
    assert chords == pytest.approx(2 * abs(radius) * math.sin(step / (2 * abs(radius))))


def test_a_straight_arc_is_the_z_axis() -> None:
    target = CurveTarget.arc(0.05, 0.0, points=5)
    assert target.points[:, 0] == pytest.approx(0.0) and target.points[-1, 1] == pytest.approx(0.05)


def test_curve_distances_are_the_dense_polylines_nearest_points() -> None:
    result = solve(PAPER, 20.0)
    rng = np.random.default_rng(3)
    points = rng.uniform([-0.005, 0.0], [0.02, 0.06], (25, 2))
    target = CurveTarget(points, tol=1e-4)
    line = result.positions[:, [0, 2]]
    t = np.linspace(0.0, 1.0, 4001)[:, None]
    dense = np.concatenate([a + t * (b - a) for a, b in itertools.pairwise(line)])
    reference = np.min(np.hypot(*(points[:, None, :] - dense[None]).transpose(2, 0, 1)), axis=1)
    assert target.distances(result) == pytest.approx(reference, abs=2e-8)
    assert target.residuals(result) == pytest.approx(target.distances(result) / 1e-4)


def test_a_tip_target_scales_each_error_by_its_tolerance() -> None:
    result = fake(tip_position=np.array([0.010, 0.0, 0.050]), tip_angle_rad=0.5)
    target = TipTarget(x=0.011, angle=0.4, position_tol=1e-3, angle_tol=0.05)
    assert target.residuals(result) == pytest.approx([-1.0, 2.0])
    assert TipTarget(z=0.05).residuals(result) == pytest.approx([0.0])


def test_a_lower_bound_is_met_at_the_bound_and_zero_with_tol_to_spare() -> None:
    assert lower_bound(3.0, 3.0, 0.1) == pytest.approx(1.0)
    assert lower_bound(3.1, 3.0, 0.1) == pytest.approx(0.0)
    assert lower_bound(2.9, 3.0, 0.1) == pytest.approx(2.0)


def test_notch_angle_targets() -> None:
    even = fake(notch_angles_rad=np.array([0.1, 0.1, 0.1, 0.1]))
    graded = fake(notch_angles_rad=np.array([0.1, 0.15, 0.2, 0.33]))
    equal = NotchAngleTarget("equal", tol=0.02)
    assert equal.residuals(even) == pytest.approx(0.0)
    spread = equal.residuals(graded)
    assert np.max(np.abs(spread)) > 1.0  # far from equal
    first = NotchAngleTarget("tip_first", ratio=3.0, tol=0.02)
    assert np.all(first.residuals(graded) <= 1.0)  # ordered, 3.3 >= 3
    assert np.max(first.residuals(even)) > 1.0  # ratio 1
    reversed_ = fake(notch_angles_rad=graded.notch_angles_rad[::-1].copy())
    assert np.max(first.residuals(reversed_)) > 1.0
    given = NotchAngleTarget("angles", tol=0.01, angles=(0.1, 0.15, 0.2, 0.3))
    assert given.residuals(graded) == pytest.approx([0, 0, 0, 3.0])
    with pytest.raises(InvalidTargetError, match="4 angles"):
        NotchAngleTarget("angles", angles=(0.1,)).check_notches(4)


def test_the_hard_stop_of_rectangular_notches_is_n_wn_over_r_outer() -> None:
    """A prismatic notch under a uniform moment bends uniformly: it closes at ``w_n / R``."""
    design = replace(PAPER, profile=RectangularProfile())
    result = solve(design, 5.0)
    expected = design.N * design.uniform("w_n") / design.R_outer
    assert StopAngleTarget.stop_angle(result) == pytest.approx(expected, rel=1e-6)
    assert StopAngleTarget(expected, tol=0.01).residuals(result) == pytest.approx(0.0, abs=1e-3)


def test_limits_measure_each_shortfall() -> None:
    limits = Limits(max_strain=0.015, min_wall=3e-3, min_backbone=1.5e-3, min_web=5e-3)
    short = limits.fabrication(PAPER)
    assert short["min_wall"] == pytest.approx(3e-3 - (PAPER.R_outer - PAPER.r_inner))
    assert short["min_backbone"] == pytest.approx(1.5e-3 - 1.4e-3)
    assert short["min_web"] == pytest.approx(1e-3)
    result = solve(PAPER, 20.0)
    peak = float(np.max(result.notch_peak_strains))
    assert limits.shape(result) == {"max_strain": pytest.approx(peak / 0.015 - 1.0)}
    assert Limits(max_strain=0.05).shape(result) == {"max_strain": 0.0}
    margins = Limits(max_strain=1.0, stop_margin=0.5).shape(result)
    assert margins["stop_margin"] == pytest.approx(
        0.5 - float(np.min(result.notch_stop_margins_rad)))


@pytest.mark.parametrize(("build", "parameter"), [
    (lambda: TipTarget(), "targets.tip"),
    (lambda: TipTarget(angle=math.nan), "targets.tip.angle"),
    (lambda: TipTarget(angle=1.0, angle_tol=0.0), "targets.tip.angle_tol"),
    (lambda: CurveTarget(np.zeros((3, 3))), "targets.curve.points"),
    (lambda: CurveTarget.arc(-1.0, 1.0), "targets.curve.arc.length"),
    (lambda: NotchAngleTarget("even"), "targets.notch_angles.kind"),
    (lambda: NotchAngleTarget("tip_first", ratio=0.5), "targets.notch_angles.ratio"),
    (lambda: StopAngleTarget(-1.0), "targets.stop_angle.angle"),
    (lambda: Limits(max_strain=0.0), "limits.max_strain"),
    (lambda: Limits(max_strain=0.1, min_web=-1.0), "fabrication.min_web"),
])
def test_a_bad_target_names_its_key(build: Any, parameter: str) -> None:
    with pytest.raises(InvalidTargetError) as caught:
        build()
    assert caught.value.parameter == parameter
