"""The inverse model (:func:`tdcm_ros.model.solve_inverse`): round trips through ``solve``,
unreachable targets naming their range, physical limits bounding it, and bad input."""

import functools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from tdcm_ros.errors import InputError, PhysicsError
from tdcm_ros.model import (
    DEFAULT_TENSION_MAX_N,
    PRESETS,
    InvalidTargetError,
    UnreachableTargetError,
    preset,
    solve,
    solve_inverse,
)

ROUND_TRIP_M = 1e-9
PAPER = preset("paper-experiment")


def target_of(kind, result):
    """The target of ``kind`` that ``result`` reaches."""
    if kind == "tip_point":
        return (float(result.tip_position[0]), float(result.tip_position[2]))
    if kind == "tendon_stroke":
        return float(result.tendon_strokes_m[0])
    return result.tip_deflection_m if kind == "tip_deflection" else result.tip_angle_rad


@settings(max_examples=60, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(sorted(PRESETS)),
       tension=st.floats(0.0, DEFAULT_TENSION_MAX_N),
       kind=st.sampled_from(["tip_deflection", "tip_angle", "tip_point", "tendon_stroke"]))
def test_round_trip_reaches_targets_drawn_from_solves(name, tension, kind):
    design = preset(name)
    target = target_of(kind, solve(design, tension))
    if kind == "tendon_stroke":  # a straight body's is 0 to rounding, of either sign
        target = max(target, 0.0)
    found = solve_inverse(design, **{kind: target})
    assert 0.0 <= found.tension_n <= DEFAULT_TENSION_MAX_N
    assert found.residual <= 1e-9  # m or rad: the default tolerance
    achieved = target_of(kind, found.result)
    assert np.max(np.abs(np.subtract(achieved, target))) <= 1e-9
    cold = solve(design, found.tension_n)  # the round trip: no warm start, nothing shared
    assert np.max(np.abs(cold.tip_position - found.result.tip_position)) <= ROUND_TRIP_M
    assert abs(cold.tendon_strokes_m[0] - found.result.tendon_strokes_m[0]) <= ROUND_TRIP_M
    assert found.tension_n == pytest.approx(tension, abs=1e-4)
    assert found.forward_solves <= 10


@pytest.mark.parametrize("kind", ["tip_deflection", "tip_angle", "tip_point"])
def test_sensitivity_matches_a_finite_difference_of_solves(kind):
    reference = solve(PAPER, 17.0)
    found = solve_inverse(PAPER, **{kind: target_of(kind, reference)})
    step = 0.2
    low, high = solve(PAPER, found.tension_n - step), solve(PAPER, found.tension_n + step)
    sens = found.sensitivity
    assert sens.method == "central"
    assert sens.tip_angle_rad_per_n == pytest.approx(
        (high.tip_angle_rad - low.tip_angle_rad) / (2 * step), rel=1e-6)
    assert sens.tip_deflection_m_per_n == pytest.approx(
        (high.tip_deflection_m - low.tip_deflection_m) / (2 * step), rel=1e-6)
    expected = (high.tip_position - low.tip_position)[[0, 2]] / (2 * step)
    assert sens.tip_point_m_per_n == pytest.approx(tuple(expected), rel=1e-5)
    assert sens.tip_point_m_per_n[0] > 0.0 > sens.tip_point_m_per_n[1]  # bends toward +x


def test_sensitivity_is_one_sided_at_a_bound():
    found = solve_inverse(PAPER, tip_angle=0.0)
    assert found.tension_n == 0.0 and found.sensitivity.method == "forward"
    assert found.sensitivity.tip_angle_rad_per_n > 0.0


@pytest.mark.parametrize(("kind", "target"), [
    ("tip_deflection", 0.05), ("tip_angle", 1.5), ("tip_angle", -0.1),
    ("tip_point", (0.05, 0.02)), ("tip_point", (-0.01, 0.053)), ("tendon_stroke", 0.01),
])
def test_unreachable_target_names_the_range_at_the_bounds(kind, target):
    with pytest.raises(UnreachableTargetError) as caught:
        solve_inverse(PAPER, **{kind: target})
    error = caught.value
    assert isinstance(error, PhysicsError) and error.exit_code == 3
    assert error.tension_range == (0.0, DEFAULT_TENSION_MAX_N) and error.limit is None
    low, high = (target_of(kind, solve(PAPER, t)) for t in error.tension_range)
    assert error.reachable == (low, high)
    shown = (f"{high:.9g}" if kind != "tip_point" else f"{high[0]:.9g}")
    assert shown in str(error) and "unreachable" in str(error)


def test_a_raised_lower_bound_moves_the_range():
    found = solve_inverse(PAPER, tip_angle=0.3, tension_min=10.0, tension_max=30.0)
    assert 10.0 < found.tension_n < 30.0
    with pytest.raises(UnreachableTargetError) as caught:
        solve_inverse(PAPER, tip_angle=0.05, tension_min=10.0, tension_max=30.0)
    assert caught.value.reachable[0] == solve(PAPER, 10.0).tip_angle_rad


def test_a_physical_limit_inside_the_bounds_ends_the_reachable_range():
    with pytest.raises(UnreachableTargetError) as caught:
        solve_inverse(PAPER, tip_angle=4.0, tension_max=400.0)
    error = caught.value
    assert error.limit == "tendon_singularity" and "tendon singularity" in str(error)
    top = error.tension_range[1]
    assert 100.0 < top < 400.0
    solve(PAPER, top)  # the top of the range solves ...
    with pytest.raises(PhysicsError):
        solve(PAPER, top * (1.0 + 1e-6))  # ... and just above it the limit is met
    reached = solve_inverse(PAPER, tip_angle=2.0, tension_max=400.0)
    assert abs(reached.result.tip_angle_rad - 2.0) <= 1e-9


def test_a_point_off_the_path_is_met_in_least_squares():
    base = solve(PAPER, 20.0)
    along = (solve(PAPER, 20.01).tip_position - solve(PAPER, 19.99).tip_position)[[0, 2]]
    normal = np.array([along[1], -along[0]]) / np.hypot(*along)  # across the tip's path (x, z)
    offset = 2e-4
    aim = base.tip_position[[0, 2]] + offset * normal
    found = solve_inverse(PAPER, tip_point=(float(aim[0]), float(aim[1])))
    assert found.tension_n == pytest.approx(20.0, abs=1e-5)
    assert found.residual == pytest.approx(offset, rel=1e-3)


@functools.cache
def tip_path(name):
    """Tensions (N) every 25 mN over the default bounds and the tip ``(x, z)`` (m) at each."""
    tensions = np.linspace(0.0, DEFAULT_TENSION_MAX_N, 2001)
    design = preset(name)
    return tensions, np.array([solve(design, t).tip_position[[0, 2]] for t in tensions])


@settings(max_examples=80, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(["paper-experiment", "fig3-wd-1.2", "fig2-wn-1"]),
       x=st.floats(-0.01, 0.04), z=st.floats(0.02, 0.06))
def test_any_point_gets_the_closest_tip_on_the_path_or_is_beyond_its_ends(name, x, z):
    tensions, tips = tip_path(name)
    distance = np.hypot(tips[:, 0] - x, tips[:, 1] - z)
    closest = int(np.argmin(distance))
    try:
        found = solve_inverse(preset(name), tip_point=(x, z))
    except UnreachableTargetError as error:
        assert closest in (0, tensions.size - 1)  # the scan's closest tip is at an end too
        assert error.reachable == (tuple(tips[0]), tuple(tips[-1]))
        return
    assert found.residual <= distance[closest] + 1e-12  # no worse than a 25 mN scan
    assert abs(found.tension_n - tensions[closest]) <= 0.025 + 1e-9
    assert found.forward_solves <= 16


def test_warm_start_gives_the_same_answer():
    first = solve_inverse(PAPER, tip_angle=0.3)
    again = solve_inverse(PAPER, tip_angle=0.31, warm_start=first.result)
    cold = solve_inverse(PAPER, tip_angle=0.31)
    assert again.tension_n == pytest.approx(cold.tension_n, abs=1e-7)


@pytest.mark.parametrize(("kwargs", "parameter"), [
    ({}, "target"),
    ({"tip_angle": 0.1, "tip_deflection": 0.001}, "target"),
    ({"tip_deflection": -0.001}, "tip_deflection"),
    ({"tip_deflection": math.nan}, "tip_deflection"),
    ({"tip_angle": math.inf}, "tip_angle"),
    ({"tip_angle": "0.1"}, "tip_angle"),
    ({"tip_angle": True}, "tip_angle"),
    ({"tip_point": (0.01,)}, "tip_point"),
    ({"tip_point": (0.01, math.nan)}, "tip_point"),
    ({"tip_point": "0.01,0.05"}, "tip_point"),
    ({"tendon_stroke": -1e-4}, "tendon_stroke"),
    ({"tendon_stroke": math.nan}, "tendon_stroke"),
    ({"tip_angle": 0.1, "tension_min": -1.0}, "tension_min"),
    ({"tip_angle": 0.1, "tension_max": 0.0}, "tension_max"),
    ({"tip_angle": 0.1, "tension_max": math.inf}, "tension_max"),
    ({"tip_angle": 0.1, "tol": 0.0}, "tol"),
    ({"tip_angle": 0.1, "tol": True}, "tol"),
])
def test_bad_targets_and_bounds_are_input_errors_naming_the_parameter(kwargs, parameter):
    with pytest.raises(InvalidTargetError) as caught:
        solve_inverse(PAPER, **kwargs)
    assert isinstance(caught.value, InputError) and caught.value.exit_code == 2
    assert caught.value.parameter == parameter and parameter in str(caught.value)


def test_summary_is_json_ready():
    import json

    found = solve_inverse(PAPER, tip_point=(0.005, 0.0527))
    data = json.loads(json.dumps(found.summary()))
    assert data["tension_n"] == found.tension_n
    assert data["tip_point_m"] == list(found.tip_point_m)
    assert data["residual"] == found.residual and data["residual_unit"] == "m"
    assert data["sensitivity"]["method"] == "central"
    assert data["target"] == {"kind": "tip_point", "value": [0.005, 0.0527]}


@settings(max_examples=300)
@example(coefficients=[1.0, 0.0, -3.1657934812405806e-232, 2.2250738585e-313],
         scales=[-2, 0, 0, -9], ends=[2.0, -1.0])  # f(low) f(piece end) underflowed to -0.0
@given(coefficients=st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4),
       scales=st.lists(st.integers(-12, 0), min_size=4, max_size=4),
       ends=st.lists(st.floats(-5.0, 5.0), min_size=2, max_size=2, unique=True))
def test_the_point_steps_cubic_roots_match_numpy(coefficients, scales, ends):
    from tdcm_ros.model.inverse import _cubic_roots

    cubic = tuple(c * 10.0**e for c, e in zip(coefficients, scales, strict=True))
    low, high = sorted(ends)
    found = _cubic_roots(cubic, low, high)
    for root in found:  # each is a root: the cubic changes sign within rounding around it
        assert low < root < high
        value = np.polyval(cubic, root)
        size = sum(abs(c) * max(1.0, abs(root)) ** (3 - k) for k, c in enumerate(cubic))
        assert abs(value) <= 1e-12 * size
    grid = np.linspace(low, high, 20001)
    values = np.polyval(cubic, grid)
    for k in np.flatnonzero(values[:-1] * values[1:] < 0.0):  # every sign change has its root
        assert any(grid[k] - 1e-12 <= f <= grid[k + 1] + 1e-12 for f in found)
