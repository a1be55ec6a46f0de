"""The measured tip from the markers of a rolled body."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.control import measured_tip, rotate_z
from tdcm_ros.model import MarkerLayout, preset, solve, surface_points

DESIGN = preset("paper-experiment")


@settings(max_examples=20)
@given(st.floats(0.0, 20.0), st.floats(-1.5, 1.5), st.sampled_from([0.0, 90.0, 180.0]),
       st.sampled_from([(0.015, 0.033, 0.053), (0.01, 0.02, 0.045)]))
def test_the_tip_is_recovered_from_rolled_markers(tension: float, roll: float, side: float,
                                                  arcs: tuple[float, ...]) -> None:
    layout = MarkerLayout(arc_lengths=arcs, side_deg=side)
    result = solve(DESIGN, tension)
    planar = surface_points(result, layout.s, layout.radius(DESIGN.R_outer), layout.side_rad)[0]
    markers = np.array([rotate_z(tuple(p), roll) for p in planar])
    tip = measured_tip(markers, result, layout, roll)
    assert tip == pytest.approx(rotate_z(tuple(result.tip_position), roll), abs=1e-12)


def test_no_tip_without_a_visible_tip_marker() -> None:
    markers = np.zeros((3, 3))
    markers[-1, 0] = math.nan
    assert measured_tip(markers, solve(DESIGN, 5.0), MarkerLayout(), 0.0) is None
