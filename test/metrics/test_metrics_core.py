"""Metrics on hand-computable cases: alignment, Table I, deflection, midline, shape error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.metrics.align import nearest_within
from tdcm_ros.metrics.evaluation import evaluate_series
from tdcm_ros.metrics.geometry import (
    MarkerLayout,
    deflection,
    measured_midline,
    station_distance,
)
from tdcm_ros.metrics.lookup import MarkerTable
from tdcm_ros.metrics.options import EvaluateOptions, options_from_sets
from tdcm_ros.metrics.synthetic import simulate
from tdcm_ros.metrics.table import table_metrics
from tdcm_ros.model import preset, solve, surface_points

DESIGN = preset("paper-experiment")
LAYOUT = MarkerLayout()
RADIUS = LAYOUT.radius(DESIGN.R_outer)


def test_nearest_within_tolerance() -> None:
    ref = np.array([0.0, 1.0, 2.0, 3.0])
    got = nearest_within([-0.05, 0.4, 0.5, 1.6, 2.95, 3.2, 10.0], ref, 0.5)
    assert got.tolist() == [0, 0, 0, 2, 3, 3, -1]
    assert nearest_within([0.5], ref, 0.49).tolist() == [-1]
    assert nearest_within([0.5], [], 1.0).tolist() == [-1]
    with pytest.raises(InputError, match="tolerance_s"):
        nearest_within([0.0], ref, -1.0)


def test_table_metrics_hand_computed() -> None:
    # trial 1: 0, 4, 8 N; trial 2: 0, 4, 8 N; deflections in m
    trials = [1, 1, 1, 2, 2, 2]
    tension = [0.0, 4.0, 8.0, 0.0, 4.0, 8.0]
    measured = [0.0002, 0.004, 0.010, 0.0001, 0.005, 0.012]
    predicted = [0.0000, 0.005, 0.008, 0.0001, 0.005, 0.015]
    m = table_metrics(trials, tension, measured, predicted, [0.001] * 6, mape_threshold_m=1e-3)
    errors = np.array([-0.0002, 0.001, -0.002, 0.0, 0.0, 0.003])
    assert m.mae_m == pytest.approx(np.mean(np.abs(errors)))
    assert m.rmse_m == pytest.approx(math.sqrt(np.mean(errors**2)))
    assert m.mape_pct == pytest.approx(100 * np.mean([0.25, 0.2, 0.0, 0.25]))
    assert m.mape_excluded == 2
    assert m.deflection_mean_m == pytest.approx((0.010 + 0.012) / 2)
    assert m.predicted_deflection_mean_m == pytest.approx((0.008 + 0.015) / 2)
    assert (m.n_trials, m.n_steps, m.n_flagged) == (2, 6, 0)
    assert m.shape_error_m == pytest.approx(0.001)


def test_table_metrics_flagged_steps_and_no_mape() -> None:
    m = table_metrics([1, 1], [0.0, 4.0], [0.0001, np.nan], [0.0, 0.004], [np.nan, np.nan])
    assert (m.n_steps, m.n_flagged, m.mape_excluded) == (1, 1, 1)
    assert m.mape_pct is None and m.shape_error_m is None
    assert m.mae_m == pytest.approx(0.0001)
    assert m.deflection_mean_m == pytest.approx(0.0001)


def test_deflection_from_marker_rest_line_and_body_axis() -> None:
    offset = LAYOUT.rest_offset(DESIGN.R_outer)  # (-r, 0, 0): opposite the tendon
    assert offset[0] == pytest.approx(-RADIUS) and abs(offset[1]) < 1e-15
    point = np.array([offset[0] + 0.003, 0.004, 0.05])
    assert deflection(point, offset) == pytest.approx(0.005)
    assert deflection(point, offset, "body") == pytest.approx(math.hypot(point[0], point[1]))
    with pytest.raises(InputError, match="deflection_axis"):
        deflection(point, offset, "tip")


def _markers(tension: float) -> tuple[np.ndarray, object]:
    result = solve(DESIGN, tension)
    return surface_points(result, LAYOUT.s, RADIUS, LAYOUT.side_rad)[0], result


def test_straight_shape_has_zero_shape_error() -> None:
    markers, result = _markers(0.0)
    stations = np.linspace(0.0, 0.053, 40)
    midline = measured_midline(markers, LAYOUT, RADIUS, stations)
    assert midline is not None
    np.testing.assert_allclose(midline, result.pose_at(stations)[0], atol=1e-12)
    assert station_distance(midline, result.pose_at(stations)[0]) < 1e-12


def test_bent_midline_is_recovered_from_surface_markers() -> None:
    markers, result = _markers(20.0)
    stations = np.linspace(0.0, 0.053, 40)
    midline = measured_midline(markers, LAYOUT, RADIUS, stations)
    assert midline is not None
    error = station_distance(midline, result.pose_at(stations)[0])
    # a cubic through 3 markers on the 6.5 mm deflection: within 0.1 mm, not exact
    assert 0.0 < error < 1e-4
    # without the offset correction the midline would be a marker radius away
    raw = measured_midline(markers, LAYOUT, 0.0, stations)
    assert station_distance(raw, result.pose_at(stations)[0]) > 2e-3


def test_shifted_midline_has_the_shift_as_shape_error() -> None:
    a = np.column_stack([np.zeros(30), np.zeros(30), np.linspace(0, 0.05, 30)])
    assert station_distance(a + [0.0003, 0.0004, 0.0], a) == pytest.approx(0.0005)


def test_missing_tip_marker_gives_no_midline() -> None:
    markers, _ = _markers(8.0)
    markers[-1] = np.nan
    assert measured_midline(markers, LAYOUT, RADIUS, np.linspace(0, 0.053, 5)) is None
    markers, _ = _markers(8.0)
    markers[1] = np.nan  # a middle marker missing: the spline uses the others
    assert measured_midline(markers, LAYOUT, RADIUS, np.linspace(0, 0.053, 5)) is not None


def test_marker_table_interpolates_the_solver() -> None:
    table = MarkerTable(DESIGN, LAYOUT, max_n=5.0, step_n=0.1)
    for tension in (0.0, 2.37, 4.99, 12.3):  # 12.3 N extends the grid
        exact = surface_points(solve(DESIGN, tension), LAYOUT.s, RADIUS, LAYOUT.side_rad)[0]
        np.testing.assert_allclose(table.markers(tension), exact, atol=1e-7)
    assert table.max_n >= 12.3
    with pytest.raises(InputError, match="tension"):
        table.markers(-1.0)


def test_layout_validation() -> None:
    with pytest.raises(InputError, match="arc_lengths"):
        MarkerLayout(arc_lengths=(0.03, 0.02, 0.05))
    with pytest.raises(InputError, match="labels"):
        MarkerLayout(labels=("a", "a", "b"))


def test_midline_markers_evaluate_with_a_zero_radial_offset() -> None:
    """Virtual markers on the midline: evaluated as such (``markers.radial_offset=0``) only the
    marker noise is left; evaluated as surface markers, the offset turning with the body shows
    as a tip error of a few tenths of a millimetre."""
    midline = MarkerLayout(radial_offset=0.0)
    rec = simulate(DESIGN, layout=midline, levels=(0.0, 10.0, 20.0), hold_s=2.0, trials=1,
                   tension_hz=250.0, mocap_hz=50.0, seed=3)
    right = evaluate_series(rec.tension, rec.markers, EvaluateOptions(design=DESIGN,
                                                                      layout=midline),
                            rec.registration)
    wrong = evaluate_series(rec.tension, rec.markers, EvaluateOptions(design=DESIGN),
                            rec.registration)
    assert right.metrics.rmse_m < 2e-5
    assert wrong.metrics.rmse_m > 1e-4
    assert options_from_sets(["markers.radial_offset=0"]).layout == midline


def test_hysteresis_pairs_an_unloading_step_with_the_loading_one_at_its_level() -> None:
    """Markers held 0.5 mm further off during the unloading 8 N hold (as friction would):
    that step's hysteresis is 0.5 mm; loading steps and the final 0 N (paired with the first)
    follow the data."""
    rec = simulate(DESIGN, levels=(0.0, 8.0, 16.0, 8.0), hold_s=2.0, trials=1,
                   tension_hz=250.0, mocap_hz=50.0, seed=4)
    opts = EvaluateOptions(design=DESIGN)
    plain = evaluate_series(rec.tension, rec.markers, opts, rec.registration)
    tip_x = plain.records[2].measured_markers[-1, 0]  # the 16 N hold: the side it bends to
    shift = np.array([0.5e-3 * np.sign(tip_x), 0.0, 0.0])
    unloading = (rec.markers.stamps_s >= 6.0) & (rec.markers.stamps_s < 8.0)
    positions = rec.markers.positions.copy()
    positions[unloading] += rec.registration.to_mocap(shift) - rec.registration.to_mocap(
        np.zeros(3))
    frames = type(rec.markers).of(rec.markers.stamps_s, rec.markers.labels, positions)
    ev = evaluate_series(rec.tension, frames, opts, rec.registration)
    assert [r.phase for r in ev.records] == ["loading"] * 3 + ["unloading"] * 2
    hysteresis = ev.hysteresis_m()
    assert hysteresis[:3] == [None, None, None]
    assert hysteresis[3] == pytest.approx(0.5e-3, abs=3e-5)
    assert hysteresis[4] == pytest.approx(0.0, abs=3e-5)  # back at 0 N: no offset left
    assert ev.unloading is not None and ev.unloading.n_steps == 2
    assert [s["hysteresis_m"] for s in ev.to_json()["steps"]] == hysteresis
