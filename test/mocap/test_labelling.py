"""Labelling by name (NameMap) and by arc length along a body axis, and occlusion."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tdcm_ros.mocap import (
    ArcLengthLabeller,
    LabelError,
    NameLabeller,
    NameMap,
    project_on_polyline,
    straight_axis,
    visible,
)
from tdcm_ros.mocap.registration import Registration
from tdcm_ros.model import preset, solve, surface_points

LABELS = ("m1", "m2", "m3")
ARCS = (0.015, 0.033, 0.053)
DESIGN = preset("paper-experiment")
RADIUS = DESIGN.R_outer + 0.001


def test_visible_drops_zeros_nan_and_inf_rows_only():
    p = np.array([[0, 0, 0], [np.nan, 1, 2], [1, np.inf, 0], [0, 0, 1e-6], [0.1, -0.2, 0.3]])
    assert visible(p).tolist() == [False, False, False, True, True]


def test_name_map_matches_full_names_and_marker_parts():
    names = NameMap.parse(["TDCM:M1=m1", "M2=m2", "Tip=m3"], LABELS)
    assert names.label_of("TDCM:M1") == "m1"
    assert names.label_of("Other:M1") is None          # a subject in the key must match
    assert names.label_of("M1") == "m1"                # a driver that sends no subject
    assert names.label_of("TDCM:M2") == "m2" and names.label_of("M2") == "m2"
    assert names.label_of("X:Tip") == "m3" and names.label_of("M4") is None


@pytest.mark.parametrize("entries", [["M1"], ["M1=m9"], ["M1=m1", "M1=m2"], ["M1=m1", "M2=m1"],
                                     ["=m1"]])
def test_bad_name_maps_are_rejected(entries):
    with pytest.raises(LabelError) as caught:
        NameMap.parse(entries, LABELS)
    assert caught.value.parameter == "labelling.map"


def test_require_names_the_missing_or_ambiguous_marker():
    names = NameMap.parse(["M1=m1", "M2=m2", "M3=m3"], LABELS)
    names.require(["A:M1", "A:M2", "A:M3", "*4"], "f.csv")
    with pytest.raises(LabelError, match="'m3'.*matches 0 markers"):
        names.require(["A:M1", "A:M2"], "f.csv")
    with pytest.raises(LabelError, match="'m1'.*matches 2 markers"):
        names.require(["A:M1", "B:M1", "A:M2", "A:M3"], "f.csv")


def test_name_labeller_orders_drops_occluded_and_counts_unlabelled():
    labeller = NameLabeller(NameMap.parse(["S:M1=m1", "S:M2=m2", "S:M3=m3"], LABELS))
    names = ["S:M3", "S:Extra", "S:M1", "S:M2", "S:M1"]
    p = np.array([[3.0, 0, 0], [9, 9, 9], [1, 0, 0], [0, 0, 0], [5, 5, 5]])
    frame = labeller(names, p)
    assert frame.labels == ("m1", "m3")
    assert np.array_equal(frame.positions, [[1, 0, 0], [3, 0, 0]])
    assert frame.occluded == 1 and frame.unlabelled == 2   # S:Extra and the second S:M1
    nan_frame = labeller(["S:M1"], [[math.nan, 0, 0]])
    assert nan_frame.labels == () and nan_frame.positions.shape == (0, 3)
    assert nan_frame.occluded == 1


def test_projection_on_a_polyline_by_hand():
    line = np.array([[0, 0, 0], [0, 0, 1.0], [1.0, 0, 1.0]])
    s, d = project_on_polyline([[0.2, 0, 0.5], [0.5, 0.3, 1.1], [0, 0, -2.0]], line)
    assert np.allclose(s, [0.5, 1.5, 0.0]) and np.allclose(d, [0.2, math.hypot(0.3, 0.1), 2.0])


def markers_in_mocap(tension: float, registration: Registration) -> tuple[np.ndarray, object]:
    result = solve(DESIGN, tension)
    points, _ = surface_points(result, np.array(ARCS), RADIUS, math.pi)
    return registration.to_mocap(points), result


registrations = st.builds(
    lambda q, t: Registration(tuple(t), tuple(q)),
    st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda q: np.linalg.norm(q) > 0.1),
    st.lists(st.floats(-2, 2), min_size=3, max_size=3))


@settings(max_examples=60)
@given(st.floats(0.0, 45.0), st.permutations(range(3)), registrations,
       st.sampled_from(["straight", "predicted"]), st.booleans(), st.integers(0, 2**31))
def test_arc_length_labelling_recovers_labels_for_any_order(tension, order, registration, axis,
                                                            with_stray, seed):
    truth, result = markers_in_mocap(tension, registration)
    rng = np.random.default_rng(seed)
    noisy = truth + rng.normal(0.0, 2e-4, truth.shape)          # 0.2 mm mocap noise
    shuffled = noisy[list(order)]
    if with_stray:   # a reflection 0.2 m away from the body: never labelled
        stray = registration.to_mocap(np.array([[0.2, 0.0, 0.03]]))
        shuffled = np.vstack([shuffled, stray, [[0.0, 0.0, 0.0]]])
    line = (straight_axis(DESIGN.length) if axis == "straight"
            else result.pose_at(np.linspace(0, DESIGN.length, 30))[0])
    labeller = ArcLengthLabeller(LABELS, ARCS, registration, line, max_distance=0.03)
    frame = labeller(None, shuffled)
    assert frame.labels == LABELS
    assert np.allclose(frame.positions, noisy, atol=1e-12)
    assert frame.unlabelled == int(with_stray) and frame.occluded == int(with_stray)


def test_arc_length_labelling_with_a_hidden_marker_and_a_tight_gate():
    registration = Registration((0.1, 0.2, 0.3), tuple(Rotation.from_euler("x", 2.0).as_quat()))
    truth, result = markers_in_mocap(40.0, registration)
    line = result.pose_at(np.linspace(0, DESIGN.length, 30))[0]
    labeller = ArcLengthLabeller(LABELS, ARCS, registration, line, max_distance=0.006)
    frame = labeller(None, truth[[2, 0]])            # m2 not seen
    assert frame.labels == ("m1", "m3") and np.allclose(frame.positions, truth[[0, 2]])
    # Markers sit 4.9 mm off the midline. On the straight axis the bent tip marker is about
    # 8.6 mm from the label point, beyond a 6 mm gate: unlabelled.
    labeller.set_axis(straight_axis(DESIGN.length))
    frame = labeller(None, truth)
    assert frame.labels == ("m1", "m2") and frame.unlabelled == 1


@pytest.mark.parametrize(("arcs", "distance"), [((0.01, 0.02), 0.01), ((0.01, 0.02, -1), 0.01),
                                                (ARCS, 0.0), (ARCS, math.nan)])
def test_arc_length_labeller_rejects_bad_settings(arcs, distance):
    with pytest.raises(LabelError):
        ArcLengthLabeller(LABELS, arcs, Registration.identity(), straight_axis(0.05), distance)
