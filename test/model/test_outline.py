"""The cut body's outline against eq. 13 written in s, and its geometry on a bent shape."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tdcm_ros.model import preset, solve
from tdcm_ros.model.outline import body_outline


def eq13_half_width(w_n: float, w_d: float, sigma: float) -> float:
    """The circular notch's backbone half-width (m) at ``sigma`` (m) into it."""
    return (w_n + w_d) / 2.0 - math.sqrt(max(sigma * (w_n - sigma), 0.0))


def test_unloaded_edges_are_the_tube_and_the_notch_profile() -> None:
    design = preset("paper-experiment")
    outline = body_outline(solve(design, 0.0))
    left, right = design.notch_bounds()
    inside = np.zeros(outline.s.size, dtype=bool)
    for l_i, r_i in zip(left, right, strict=True):
        inside |= (outline.s > l_i) & (outline.s < r_i)
    want = np.full(outline.s.size, design.R_outer)
    for k in np.flatnonzero(inside):
        l_i = left[np.searchsorted(left, outline.s[k]) - 1]
        want[k] = min(eq13_half_width(design.w_n, design.w_d, outline.s[k] - l_i), design.R_outer)
    np.testing.assert_allclose(outline.half_width_tendon_side[inside], want[inside], rtol=1e-12)
    np.testing.assert_allclose(outline.tendon_side[:, 0], outline.half_width_tendon_side,
                               atol=1e-15)
    np.testing.assert_allclose(outline.far_side[:, 0], -outline.half_width_far_side, atol=1e-15)
    np.testing.assert_allclose(outline.tendon_side[:, 1], outline.s, atol=1e-15)
    # every boundary appears twice: the tube's surface, then the notch's edge (or the reverse)
    for boundary in (*left, *right):
        widths = outline.half_width_tendon_side[np.isclose(outline.s, boundary, rtol=0,
                                                           atol=1e-15)]
        assert sorted(widths) == pytest.approx(sorted([design.R_outer,
                                                       (design.w_n + design.w_d) / 2.0]))


def test_bent_edges_are_their_half_width_off_the_midline_along_its_normal() -> None:
    design = preset("paper-experiment")
    result = solve(design, 20.0)
    outline = body_outline(result)
    positions, quaternions = result.pose_at(outline.s)
    theta = 2.0 * np.arctan2(quaternions[:, 1], quaternions[:, 3])
    tangent = np.stack([np.sin(theta), np.cos(theta)], axis=1)
    for edge, width in ((outline.tendon_side, outline.half_width_tendon_side),
                        (outline.far_side, -outline.half_width_far_side)):
        offset = edge - positions[:, [0, 2]]
        np.testing.assert_allclose(np.sum(offset * tangent, axis=1), 0.0, atol=1e-15)
        across = offset[:, 0] * tangent[:, 1] - offset[:, 1] * tangent[:, 0]  # + toward body +x
        np.testing.assert_allclose(across, width, rtol=1e-12)
    odd = body_outline(result, stations=25)  # a station at each notch's centre
    assert np.min(odd.half_width_tendon_side) == pytest.approx(design.w_d / 2, rel=1e-12)


def test_a_one_sided_cut_leaves_the_far_side_whole_and_the_tendon_side_cut_to_its_depth(
        ) -> None:
    """A rectangular cut 6.4 mm deep from +x (w_d = 2 R - 6.4 mm at w_o = -3.2 mm): inside the
    notch the material reaches R_outer - 6.4 mm on the tendon's side (past the axis) and the
    tube's surface on the other."""
    base = preset("paper-experiment").with_overrides(profile="rectangular")
    design = base.with_overrides(w_d=2 * base.R_outer - 6.4e-3, w_o=-3.2e-3)
    outline = body_outline(solve(design, 0.0))
    left, right = design.notch_bounds()
    inside = np.zeros(outline.s.size, dtype=bool)
    for l_i, r_i in zip(left, right, strict=True):
        inside |= (outline.s > l_i) & (outline.s < r_i)
    np.testing.assert_allclose(outline.half_width_tendon_side[inside], design.R_outer - 6.4e-3,
                               rtol=1e-12)
    np.testing.assert_allclose(outline.half_width_far_side, design.R_outer, rtol=1e-12)
    for boundary in (*left, *right):  # the tube's surface and the cut's floor, both drawn
        widths = outline.half_width_tendon_side[np.isclose(outline.s, boundary, rtol=0,
                                                           atol=1e-15)]
        assert sorted(widths) == pytest.approx([design.R_outer - 6.4e-3, design.R_outer])
