"""Polygon notches (:class:`~tdcm_ros.model.profiles.PolygonProfile`: a prismatic section of
any simple polygon of material) against references written here: sections made of
axis-aligned rectangles in closed form (sums of each rectangle's area and moments, not the
package's Green's-theorem integrals), and the shape by the second solver of
:mod:`test.support.second_solver` fed those sections."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from tdcm_ros.model import PolygonProfile, search_designs, solve, sweep
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.design import preset
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.solver import DEFAULT_SETTINGS
from test.support.cli import tdcm
from test.support.second_solver import reference_tip

MM = 1e-3
Box = tuple[float, float, float, float]  # x0, x1, y0, y1 (m)


def rectangles(solid: list[Box], holes: list[Box] = ()) -> tuple[float, float, float, float]:
    """Area (m^2), centroid x (m), centroidal I (m^4) and farthest fibre from the centroid (m)
    of non-overlapping rectangles less the rectangular holes inside them, in closed form."""
    def moments(box: Box) -> np.ndarray:
        x0, x1, y0, y1 = box
        return np.array([(x1 - x0) * (y1 - y0), (y1 - y0) * (x1**2 - x0**2) / 2,
                         (y1 - y0) * (x1**3 - x0**3) / 3])

    area, first, second = sum(map(moments, solid)) - sum(map(moments, holes), np.zeros(3))
    x_bar = first / area
    low, high = min(b[0] for b in solid), max(b[1] for b in solid)
    return area, x_bar, second - area * x_bar**2, max(high - x_bar, x_bar - low)


#: A tee (flange on the far side, web toward the tendon), a box with a rectangular lumen, and
#: an angle: each as its rectangles and as the polygon a user would write.
TEE = ([(-3.5 * MM, -2.5 * MM, -1.5 * MM, 1.5 * MM), (-2.5 * MM, 0.5 * MM, -0.3 * MM, 0.3 * MM)],
       [], [(-3.5, -1.5), (-2.5, -1.5), (-2.5, -0.3), (0.5, -0.3), (0.5, 0.3), (-2.5, 0.3),
            (-2.5, 1.5), (-3.5, 1.5)], [])
BOX = ([(-3.0 * MM, -1.0 * MM, -1.0 * MM, 1.0 * MM)], [(-2.5 * MM, -1.5 * MM, -0.3 * MM, 0.3 * MM)],
       [(-3.0, -1.0), (-1.0, -1.0), (-1.0, 1.0), (-3.0, 1.0)],
       [[(-2.5, -0.3), (-2.5, 0.3), (-1.5, 0.3), (-1.5, -0.3)]])
ANGLE = ([(-3.0 * MM, 0.0, -0.5 * MM, 0.5 * MM), (-3.0 * MM, -2.0 * MM, 0.5 * MM, 2.0 * MM)], [],
         [(-3.0, -0.5), (0.0, -0.5), (0.0, 0.5), (-2.0, 0.5), (-2.0, 2.0), (-3.0, 2.0)], [])
SHAPES = {"tee": TEE, "box with lumen": BOX, "angle": ANGLE}


def profile(shape: tuple) -> PolygonProfile:
    _, _, shell, holes = shape
    scaled = [[(x * MM, y * MM) for x, y in ring] for ring in (shell, *holes)]
    return PolygonProfile(scaled[0], tuple(scaled[1:]))


def reference(shape: tuple) -> tuple[float, float, float, float]:
    return rectangles(shape[0], shape[1])


RECTANGULAR = preset("paper-experiment").with_overrides(profile="rectangular")


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_a_polygon_section_matches_its_rectangles_to_1e9(name: str) -> None:
    area, x_bar, inertia, fibre = reference(SHAPES[name])
    got = profile(SHAPES[name]).section(RECTANGULAR.R_outer)
    assert float(got.area) == pytest.approx(area, rel=1e-9)
    assert float(got.centroid_x) == pytest.approx(x_bar, rel=1e-9)
    assert float(got.second_moment) == pytest.approx(inertia, rel=1e-9)
    assert max(float(got.fibre_tendon_side), float(got.fibre_far_side)) == pytest.approx(
        fibre, rel=1e-9)


def mixed_body() -> tuple:
    """Eight notches: the three polygons, the paper's rectangular band between them."""
    order = ["tee", None, "box with lumen", "angle", None, "tee", "angle", None]
    profiles = [profile(SHAPES[n]) if n else RECTANGULAR.profile for n in order]
    given = {k: reference(SHAPES[n])[1:3] for k, n in enumerate(order) if n}
    return RECTANGULAR.with_overrides(profile=profiles), given


@pytest.mark.parametrize("tension", [2.0, 5.0])
@pytest.mark.parametrize("grid", ["uniform", "adaptive"])
def test_polygon_notches_match_the_second_solver_to_a_tenth_of_a_micron(grid: str,
                                                                        tension: float) -> None:
    design, given = mixed_body()
    result = solve(design, tension, settings=DEFAULT_SETTINGS.with_overrides(grid=grid))
    tip, bends = reference_tip(design, tension, given)
    assert abs(complex(result.positions[-1, 2], result.positions[-1, 0]) - tip) <= 0.1e-6
    assert result.notch_angles_rad == pytest.approx(bends, abs=1e-9)
    # the published midline and the batch solver read the same body
    assert float(np.max(np.abs(result.pose_at([design.length])[0][0] - result.positions[-1]))
                 ) <= 1e-9
    batch = solve_batch([design], [tension], settings=DEFAULT_SETTINGS.with_overrides(grid=grid))
    assert batch.tip_position[0] == pytest.approx(result.positions[-1], abs=1e-12)
    assert float(batch.max_bending_strain[0]) == pytest.approx(
        float(np.max(result.notch_peak_strains)), rel=1e-9)


def test_a_polygon_cut_closes_where_its_faces_meet_and_strains_at_its_farthest_fibre() -> None:
    """Every notch the tee, cut open at +x: the hard stop is w / (R_outer - x_bar); under paper
    routing the moment about the centroid is (R_c - x_bar) T, so the peak strain is that over
    E I times the farthest fibre."""
    design = RECTANGULAR.with_overrides(profile=profile(TEE))
    _, x_bar, inertia, fibre = reference(TEE)
    result = solve(design, 1.0)
    stops = result.notch_stop_margins_rad + result.notch_angles_rad
    assert stops == pytest.approx(np.full(design.N, 2 * MM / (design.R_outer - x_bar)), rel=1e-6)
    strain = (design.R_c - x_bar) * 1.0 / (design.E * inertia) * fibre
    assert result.notch_peak_strains == pytest.approx(np.full(design.N, strain), rel=1e-9)


def test_a_polygon_that_keeps_the_wall_on_the_tendon_side_has_no_hard_stop_there() -> None:
    """Material up to the outer surface at +x (a cut from -x only): bending toward the
    tendon compresses that wall, the faces never meet; a cut opening there does stop."""
    kept = PolygonProfile([(-1 * MM, -0.5 * MM), (3.8 * MM, -0.5 * MM), (3.92 * MM, 0.0),
                           (3.8 * MM, 0.5 * MM), (-1 * MM, 0.5 * MM)])
    design = RECTANGULAR.with_overrides(profile=[kept] + [RECTANGULAR.profile] * 7)
    assert design.open_faces()[:, 0].tolist() == [False, True]
    result = solve(design, 1.0)
    margins = result.notch_stop_margins_rad
    assert math.isinf(margins[0]) and np.all(np.isfinite(margins[1:]))
    # strict JSON (tdcm solve --json): no stop is null, not Infinity
    summary = json.loads(json.dumps(result.summary(), allow_nan=False))
    assert summary["notch_stop_margins_rad"][0] is None


@pytest.mark.parametrize(("shell", "message"), [
    ([(-3.5 * MM, -2 * MM), (0.5 * MM, -2 * MM), (0.5 * MM, 2 * MM)],
     r"profile\[0\] \(polygon\) = 0\.00403.*within R_outer = 0\.00392 m"),
    ([(0.0, 0.0), (MM, MM), (MM, 0.0), (0.0, MM)], r"profile\[0\]: polygon is not a simple"),
])
def test_a_bad_polygon_is_refused_naming_the_notch(shell: list, message: str) -> None:
    with pytest.raises(InvalidDesignError, match=message):
        RECTANGULAR.with_overrides(profile=[PolygonProfile(shell)] + [RECTANGULAR.profile] * 7)


def test_the_fields_a_polygon_body_derives_are_not_set_swept_or_searched() -> None:
    """w_d and w_o of a polygon notch are its extent: --set, sweeps and searches refuse them by
    name rather than ignore them; the fields the body takes still vary."""
    design = RECTANGULAR.with_overrides(profile=profile(TEE))
    assert design.derived_fields() == {"profile", "w_d", "w_o"}
    with pytest.raises(InvalidDesignError, match="swept fields: w_d is derived"):
        sweep(design, {"w_d": [1e-3, 2e-3]}, [1.0])
    with pytest.raises(InvalidDesignError, match="free fields: w_d is derived"):
        search_designs(design, free={"w_d": (1e-3, 2e-3)}, tip_deflection=1e-3)
    assert sweep(design, {"w_n": [1e-3, 2e-3]}, [1.0]).tip_deflection_m.shape == (2, 1)
    with pytest.raises(InvalidDesignError, match="with_overrides: w_d is derived"):
        design.with_overrides(w_d=1e-3)  # in Python too: refused, not silently replaced
    assert design.with_overrides(w_n=2e-3).w_n == 2e-3
    assert design.with_overrides(profile=RECTANGULAR.profile, w_d=1.5e-3).w_d == 1.5e-3
    body = Path(__file__).resolve().parents[2] / "config" / "bodies" / "tee_notches.yaml"
    refused = tdcm("solve", "--design", str(body), "--set", "w_o=0", "--tension", "1")
    assert refused.returncode == 2 and "--set: w_o is derived" in refused.stderr
