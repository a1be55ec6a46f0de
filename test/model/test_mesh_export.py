"""Designs exported as meshes (:mod:`tdcm_ros.model.mesh_export`) and read back by the
package's mesh path (a body file naming the STL, in mm): the tip against the design's own
solve; the STL closed, its volume against one summed here (shapely areas of the faceted
sections times their lengths, and the design's own sections); each circular slab's
compliance against the solver's eq. 12 and 13 (not the exporter's formulas), over the faceted
section by the polygon moment formulas; and the typed errors."""

from __future__ import annotations

import itertools
import logging
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon, box

from tdcm_ros.errors import InputError
from tdcm_ros.model import Design, named_design, preset, solve
from tdcm_ros.model.body_file import read_body_file
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.grid_kernel import (
    CIRCULAR,
    geometry,
    notched_inertia,
    offset_section,
)
from tdcm_ros.model.material import Material
from tdcm_ros.model.mesh_export import (
    DEFAULT_SIDES,
    InvalidExportError,
    band_slabs,
    design_mesh,
    mesh_body_file_text,
    write_body_stl,
)
from tdcm_ros.model.profiles import CircularProfile, PolygonProfile, RectangularProfile
from tdcm_ros.model.sections import PolygonSection
from test.model.test_mesh_body import by_shoelace
from test.support.meshes import annulus

MM = 1e-3
BODIES = Path(__file__).resolve().parents[2] / "config" / "bodies"
#: The round trip's bound on the tip's error, of the tip's displacement (measured at the
#: default sides and slabs: 9e-7 paper, 9e-6 tip-first wrist, 7e-7 bands, 3e-7 polygon wrist).
TIP_TOL = 1e-4


def per_notch_bands() -> Design:
    """Bands of four backbones, circular and rectangular, of three widths and gaps."""
    return Design(w_base=4 * MM, w_tip=3 * MM, w_n=(1.5 * MM, 2 * MM, 2.5 * MM, 2 * MM),
                  w_t=(3 * MM, 4 * MM, 3 * MM), w_d=(1.2 * MM, 1.4 * MM, 1.6 * MM, 1.8 * MM),
                  N=4, R_outer=3.92 * MM, r_inner=1.55 * MM, R_c=2.75 * MM,
                  profile=("circular", "rectangular", "circular", "rectangular"))


def polygon_wrist() -> Design:
    """The I-beam wire wrist of polygon notches, its material linear (the mesh path's)."""
    return named_design(str(BODIES / "nitinol_polygon_wrist.yaml")).with_overrides(
        material=Material())


CASES = {  # name: (design, tension N)
    "paper-experiment": (lambda: preset("paper-experiment"), 20.0),
    "tip_first_wrist": (lambda: named_design(str(BODIES / "tip_first_wrist.yaml")), 2.0),
    "per-notch bands": (per_notch_bands, 20.0),
    "polygon wrist": (polygon_wrist, 3.0),
}


@dataclass(frozen=True)
class Exported:
    """A case's design and tension (N), its STL and the design read back from it."""

    design: Design
    tension: float
    stl: Path
    read_back: Design


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Exported]:
    """Each case written as an STL in mm and read back through a body file naming it."""
    folder = tmp_path_factory.mktemp("exported")
    out = {}
    for k, (name, (make, tension)) in enumerate(CASES.items()):
        design = make()
        stl = write_body_stl(design, folder / f"body{k}.stl")
        body = folder / f"body{k}.yaml"
        body.write_text(mesh_body_file_text(design, stl.name))
        out[name] = Exported(design, tension, stl, read_body_file(body).design())
    return out


@pytest.mark.parametrize("name", CASES)
def test_the_read_back_body_bends_as_the_design(exported: dict[str, Exported], name: str) -> None:
    case = exported[name]
    design, back = case.design, case.read_back
    assert back.R_outer == pytest.approx(design.R_outer, rel=1e-7)  # the circles' radii
    assert back.r_inner == pytest.approx(design.r_inner, rel=1e-6)
    assert back.N == design.N
    assert back.E == design.E and back.R_c == design.R_c
    for field in ("w_n", "w_t"):
        assert back.per_notch(field) == pytest.approx(design.per_notch(field), abs=1e-8)
    assert (back.w_base, back.w_tip) == pytest.approx((design.w_base, design.w_tip), abs=1e-8)
    want, got = solve(design, case.tension), solve(back, case.tension)
    error = np.linalg.norm(got.tip_position - want.tip_position)
    assert error <= TIP_TOL * want.tip_displacement_m, (name, error / want.tip_displacement_m)


def faceted_volume(design: Design) -> float:
    """The exported body's volume (m^3) from its sections, by shapely: the faceted annulus
    along the tubes, each band slab of it (bounds from :func:`band_slabs`), each polygon."""
    wall = annulus(design.R_outer, design.r_inner, DEFAULT_SIDES)
    w_n = design.per_notch("w_n")
    volume = wall.area * (design.length - w_n.sum())
    for i, profile in enumerate(design.notch_profiles()):
        if isinstance(profile, PolygonProfile):
            volume += Polygon(profile.shell, profile.holes).area * w_n[i]
            continue
        bounds, low, high = band_slabs(design, i)
        for width, x_low, x_high in zip(np.diff(bounds), low, high, strict=True):
            volume += wall.intersection(box(max(x_low, -1.0), -1.0, min(x_high, 1.0), 1.0)
                                        ).area * width
    return float(volume)


def design_volume(design: Design) -> float:
    """The design's own volume (m^3): the circles' annulus along the tubes, each notch's
    section area (the solver's formulas) over its width, eq. 13's by Gauss-Legendre in u."""
    w_n, w_d, w_o = (design.per_notch(name) for name in ("w_n", "w_d", "w_o"))
    volume = math.pi * (design.R_outer**2 - design.r_inner**2) * (design.length - w_n.sum())
    nodes, weights = np.polynomial.legendre.leggauss(200)
    u, weights = 0.5 * (nodes + 1.0), 0.5 * weights
    for i, profile in enumerate(design.notch_profiles()):
        if isinstance(profile, PolygonProfile):
            section = PolygonSection(profile.shell, design.R_outer, profile.holes)
            volume += float(section.properties().area) * w_n[i]
        elif isinstance(profile, RectangularProfile):
            volume += offset_section(0.5 * w_d[i], w_o[i], design.R_outer, design.r_inner
                                     )[0] * w_n[i]
        else:
            h1 = profile.h1(u, w_n[i], w_d[i])
            areas = [offset_section(h, w_o[i], design.R_outer, design.r_inner)[0] for h in h1]
            volume += float(np.sum(weights * 0.5 * np.pi * w_n[i] * np.sin(np.pi * u) * areas))
    return volume


@pytest.mark.parametrize("name", CASES)
def test_the_stl_is_closed_and_holds_the_sections_volume(exported: dict[str, Exported],
                                                         name: str) -> None:
    """To float32's rounding, the volume of the faceted sections; to the faceting (prismatic
    notches) or the staircase (circular ones: slabs matched in compliance, not area), the
    design's."""
    design = exported[name].design
    mesh = trimesh.load(str(exported[name].stl), force="mesh")
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0.0
    volume = mesh.volume * MM**3
    assert volume == pytest.approx(faceted_volume(design), rel=1e-6)
    faceting = (2.0 * math.pi / DEFAULT_SIDES) ** 2 / 6.0  # an inscribed polygon's area deficit
    circular = any(isinstance(p, CircularProfile) for p in design.notch_profiles())
    assert volume == pytest.approx(design_volume(design), rel=1e-3 if circular else 2 * faceting)


def shoelace_moment(material: object) -> float:
    """Second moment (m^4) about its centroid of a shapely (multi)polygon in m (the mesh-body
    tests' polygon moment formulas: scale-free)."""
    return by_shoelace(material)[2]


def test_each_circular_slab_has_the_profile_s_compliance_over_its_faceted_section() -> None:
    """The slabs' int ds / I (faceted, as the mesh reader slices them) equal eq. 13's over
    them with eq. 12's I (the solver's formulas, :func:`grid_kernel.geometry` and
    :func:`grid_kernel.notched_inertia`, by scipy's adaptive quadrature in u), to 1e-9; the
    rectangular bands' second moments equal eq. 12's at w_d / 2."""
    from scipy.integrate import quad

    design = per_notch_bands()
    wall = annulus(design.R_outer, design.r_inner, DEFAULT_SIDES)
    for i, profile in enumerate(design.notch_profiles()):
        w_n, w_d = (float(design.per_notch(name)[i]) for name in ("w_n", "w_d"))
        bounds, low, high = band_slabs(design, i)
        faceted = np.array([shoelace_moment(wall.intersection(box(a, -1.0, b, 1.0)))
                            for a, b in zip(low, high, strict=True)])
        if isinstance(profile, RectangularProfile):
            assert faceted[0] == pytest.approx(notched_inertia(0.5 * w_d, design.R_outer,
                                                               design.r_inner), rel=1e-9)
            continue

        def compliance(u: float, w_n: float = w_n, w_d: float = w_d) -> float:
            _, rate, h1 = geometry(CIRCULAR, w_n, w_d, u, 0.0)  # d sigma / d u, h1
            return rate / notched_inertia(h1, design.R_outer, design.r_inner)

        assert len(bounds) == 17 and np.diff(bounds) == pytest.approx(w_n / 16, rel=1e-12)
        ends = np.arccos(1.0 - 2.0 * bounds / w_n) / np.pi  # sigma = (w_n/2)(1 - cos(pi u))
        for k, (a, b) in enumerate(itertools.pairwise(ends)):
            reference = quad(compliance, a, b, epsabs=0.0, epsrel=1e-11, limit=200)[0]
            assert (bounds[k + 1] - bounds[k]) / faceted[k] == pytest.approx(reference,
                                                                             rel=1e-9)


def test_a_mesh_in_metres_is_the_mesh_in_millimetres_scaled() -> None:
    design = named_design(str(BODIES / "tip_first_wrist.yaml"))
    metres, millimetres = design_mesh(design), design_mesh(design, unit="mm")
    assert np.asarray(metres.vertices) * 1e3 == pytest.approx(np.asarray(millimetres.vertices),
                                                              rel=1e-12, abs=1e-15)
    corners = [-design.R_outer, -design.R_outer, 0.0, design.R_outer, design.R_outer,
               design.length]
    assert np.ravel(metres.bounds) == pytest.approx(corners, abs=1e-12)


def test_a_body_of_more_notch_than_tube_draws_a_warning(
        caplog: pytest.LogCaptureFixture) -> None:
    """Three 2 mm notches 1 mm apart from the base: more of the body is notch than tube, and
    the mesh reader takes the section most of the length has as the tube."""
    dense = Design(w_base=0.0, w_tip=2 * MM, w_n=2 * MM, w_t=1 * MM, w_d=1.4 * MM, N=3,
                   R_outer=3.92 * MM, r_inner=1.55 * MM, R_c=2.75 * MM, profile="rectangular")
    with caplog.at_level(logging.WARNING, logger="tdcm_ros.model.mesh_export"):
        design_mesh(dense, sides=128)
    assert "takes the section most of the body's length has as the tube" in caplog.text
    assert "more plain tube" in caplog.text


def test_bad_arguments_are_typed_errors_naming_the_parameter_value_and_range(
        tmp_path: Path) -> None:
    design = named_design(str(BODIES / "tip_first_wrist.yaml"))
    cases: list[tuple[dict[str, object], str, str]] = [
        ({"sides": 127}, "sides",
         r"sides = 127 is out of range; allowed: an even integer in \[128, 8192\]"),
        ({"sides": 513}, "sides", "sides = 513"),
        ({"sides": 512.0}, "sides", "sides = 512.0"),
        ({"sides": True}, "sides", "sides = True"),
        ({"slabs": 0}, "slabs", r"slabs = 0 is out of range; allowed: an integer in \[1, 512\]"),
        ({"unit": "inch"}, "unit", r"unit = 'inch' is out of range; allowed: m \| mm"),
    ]
    for kwargs, parameter, message in cases:
        with pytest.raises(InvalidExportError, match=message) as caught:
            design_mesh(design, **kwargs)
        assert isinstance(caught.value, InputError) and caught.value.parameter == parameter
    narrow = preset("paper-experiment").with_overrides(w_n=5e-6)  # circular, 5 um wide
    with pytest.raises(InvalidExportError, match=r"slabs = 16 .*\[1, 5\] \(slabs of the "
                                                  r"narrowest circular or custom notch, 5e-06 m"):
        design_mesh(narrow)
    for path, message in [(tmp_path / "body.obj", "body.obj"),
                          (tmp_path / "missing" / "body.stl", "missing")]:
        with pytest.raises(InvalidExportError, match=f"path = .*{message}.* a file name ending "
                                                      "in .stl in an existing folder"):
            write_body_stl(design, path)
    with pytest.raises(InvalidExportError, match="unit = 'cm'"):
        mesh_body_file_text(design, "body.stl", unit="cm")


def test_sections_without_a_shape_and_a_material_law_are_refused(
        exported: dict[str, Exported]) -> None:
    """A section given by its numbers and a mesh's slices have no shape to export (named by
    the notch); a body file naming a mesh takes a linear material only (the STL itself is
    geometry: written whatever the law)."""
    given = named_design(str(BODIES / "disk_routed.yaml"))
    with pytest.raises(InvalidDesignError, match=r"profile = 'section' \(notch 0\): a section "
                                                 "given by its numbers .* has no shape"):
        design_mesh(given)
    sliced = exported["paper-experiment"].read_back
    with pytest.raises(InvalidDesignError, match=r"profile(\[0\])? = 'sliced' \(notch 0\): a "
                                                 "mesh's slices"):
        design_mesh(sliced)
    with pytest.raises(InvalidDesignError, match=r"notch 1\): a polygon notch is extruded "
                                                 "whole"):
        band_slabs(polygon_wrist(), 1)
    bilinear = named_design(str(BODIES / "nitinol_polygon_wrist.yaml"))
    with pytest.raises(InvalidExportError, match="material.law = 'bilinear' .* allowed: linear"):
        mesh_body_file_text(bilinear, "body.stl")
    linear = trimesh.load(str(exported["polygon wrist"].stl), force="mesh")
    assert design_mesh(bilinear, unit="mm").volume == pytest.approx(linear.volume, rel=1e-6)


def test_without_manifold3d_the_error_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "manifold3d", None)  # import manifold3d raises ImportError
    with pytest.raises(InvalidExportError, match=r"needs manifold3d: pip install "
                                                 r"'tdcm_ros\[export\]'"):
        design_mesh(preset("paper-experiment"))


def test_the_body_file_names_the_mesh_and_carries_material_and_tendons() -> None:
    design = named_design(str(BODIES / "antagonistic_pair.yaml"))
    text = mesh_body_file_text(design, "my body.stl", unit="m")
    assert text.endswith('mesh: {file: "my body.stl", unit: m}\n')
    assert "segments" not in text and "tube:" not in text
    assert text.startswith("material: {E: ") and "tendons:\n  - {offset: " in text
