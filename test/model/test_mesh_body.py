"""Bodies read from a triangle mesh (:mod:`tdcm_ros.model.mesh_body`) against references
written here: each notch's section by integrating the chord length of the material the mesh
was built from along x (exact for polygons by 2-point Gauss-Legendre between vertex
abscissae: not the package's Green's theorem), the segments where the mesh was built to put
them, and the shape by the second solver of :mod:`test.support.second_solver` fed those
sections."""

from __future__ import annotations

import itertools
import logging
import re
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import LineString, Polygon, box

from tdcm_ros.model import solve
from tdcm_ros.model.body_file import read_body_file
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.mesh_body import _segments, _slices
from tdcm_ros.model.mesh_file import TriangleMesh
from tdcm_ros.model.profiles import SlicedProfile
from test.support.meshes import (
    annulus,
    as_shapely,
    body_mesh,
    cross_section,
    slanted_cut_mesh,
    write_mesh,
)
from test.support.second_solver import reference_tip

MM = 1e-3
R_OUTER, R_INNER = 3.92, 1.55  # mm
TEE = Polygon([(-3.5, -1.5), (-2.5, -1.5), (-2.5, -0.3), (0.5, -0.3), (0.5, 0.3), (-2.5, 0.3),
               (-2.5, 1.5), (-3.5, 1.5)])  # its web crosses the lumen (a printed body's)
WALL = annulus(R_OUTER, R_INNER, 256)
PAIR = box(-0.7, -5.0, 0.7, 5.0).intersection(WALL)  # the paper's pair of cuts: two pieces
CUT = box(-5.0, -5.0, 0.8, 5.0).intersection(WALL)   # a one-sided cut from +x to x = 0.8 mm
SEGMENTS = [("tube", 4.0), ("notch", 2.0, TEE), ("tube", 4.0), ("notch", 2.0, PAIR),
            ("tube", 3.0), ("notch", 1.5, CUT), ("tube", 4.0)]


def by_chords(material: object) -> tuple[float, float, float]:
    """Area (mm^2), centroid x (mm) and centroidal I (mm^4) of a (multi)polygon from its
    chord length L(x) along vertical lines: linear between vertex abscissae, so 2-point Gauss
    per interval integrates x^k L(x), k <= 2, exactly."""
    xs = np.unique(np.concatenate([np.asarray(p.exterior.coords)[:, 0] for p in
                                   getattr(material, "geoms", [material])]
                                  + [np.asarray(h.coords)[:, 0] for p in
                                     getattr(material, "geoms", [material]) for h in p.interiors]))
    nodes = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    moments = np.zeros(3)
    for a, b in itertools.pairwise(xs):
        for node in nodes:
            x = 0.5 * (a + b) + 0.5 * (b - a) * node
            chord = LineString([(x, -10.0), (x, 10.0)]).intersection(material).length
            moments += 0.5 * (b - a) * chord * np.array([1.0, x, x * x])
    area, first, second = moments
    x_bar = first / area
    return area, x_bar, second - area * x_bar**2


def references() -> list[tuple[float, float, float]]:
    """The notches' sections by chords, of the material as the mesh holds it (its builder
    rounds coordinates to 1e-8 mm)."""
    tube = annulus(R_OUTER, R_INNER, 256)
    return [by_chords(as_shapely(cross_section(s, tube))) for s in SEGMENTS if s[0] == "notch"]


def test_the_slices_give_each_segment_and_each_notch_section_to_1e9() -> None:
    mesh = body_mesh(SEGMENTS, R_OUTER, R_INNER)
    mesh.apply_scale(MM)
    triangles = TriangleMesh(np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64))
    body = _segments(_slices(triangles, "mesh.file"), "mesh.file", "mm")
    assert body.R_outer == pytest.approx(R_OUTER * MM, rel=1e-8)  # the builder's rounding
    assert body.r_inner == pytest.approx(R_INNER * MM, rel=1e-8)
    assert [s.length for s in body.segments] == pytest.approx([s[1] * MM for s in SEGMENTS],
                                                              abs=1e-12)
    notches = [s.section for s in body.segments if s.section is not None]
    assert len(notches) == 3
    for got, (area, x_bar, inertia) in zip(notches, references(), strict=True):
        assert got.area == pytest.approx(area * MM**2, rel=1e-9)
        assert got.centroid_x == pytest.approx(x_bar * MM, rel=1e-9, abs=1e-12 * MM)
        assert got.second_moment == pytest.approx(inertia * MM**4, rel=1e-9)


def body_file(tmp_path: Path, segments: list = SEGMENTS, sides: int = 256, **moved: float
              ) -> Path:
    mesh = body_mesh(segments, R_OUTER, R_INNER, sides)
    if moved:
        mesh.apply_translation([moved.get("x", 0.0), 0.0, moved.get("z", 0.0)])
    write_mesh(mesh, tmp_path / "body.stl")
    path = tmp_path / "body.yaml"
    path.write_text("material: {E: 1.85e9}\ntendons:\n  - {offset: 2.75e-3}\n"
                    "mesh: {file: body.stl, unit: mm}\n")
    return path


@pytest.mark.parametrize("tension", [2.0, 5.0])
def test_an_stl_body_solves_as_the_second_solver_with_the_reference_sections(
        tmp_path: Path, tension: float) -> None:
    """Through the body file (float32 STL coordinates: sections to ~1e-7), every command's
    path: the tip within 0.1 um of the second solver fed the sections by chords."""
    design = read_body_file(body_file(tmp_path)).design()
    assert design.N == 3 and design.R_outer == pytest.approx(R_OUTER * MM, rel=1e-7)
    given = {k: (x_bar * MM, inertia * MM**4) for k, (_, x_bar, inertia) in enumerate(references())}
    result = solve(design, tension)
    tip, bends = reference_tip(design, tension, given)
    assert abs(complex(result.positions[-1, 2], result.positions[-1, 0]) - tip) <= 0.1e-6
    assert result.notch_angles_rad == pytest.approx(bends, rel=1e-6)


def test_a_coarse_mesh_is_read_with_a_warning_saying_how_far_its_tube_is_off(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.WARNING, logger="tdcm_ros.model.mesh_body"):
        read_body_file(body_file(tmp_path, sides=24)).design()
    assert "faceted tube's second moment is -" in caplog.text and "coarse" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="tdcm_ros.model.mesh_body"):
        read_body_file(body_file(tmp_path, sides=256)).design()
    assert caplog.text == ""


def test_bad_meshes_are_refused_naming_what_is_wrong(tmp_path: Path) -> None:
    for name in "zxfg":
        (tmp_path / name).mkdir()
    cases = {
        "starts at z = 0.001 m": body_file(tmp_path / "z", z=1.0),
        "centred at (x, y) = (0.0005": body_file(tmp_path / "x", x=0.5),
        "z = 0..1 mm has more material than the tube": body_file(
            tmp_path / "f", [("solid", 1.0, annulus(6.0, R_INNER, 256)), ("tube", 4.0),
                             ("notch", 1.0, TEE), ("tube", 4.0)]),  # a mounting flange
        "no material at z = 0.0045 m": body_file(
            tmp_path / "g", [("tube", 4.0), ("notch", 1.0, box(10.0, 10.0, 11.0, 11.0)),
                             ("tube", 4.0)]),
    }
    for message, path in cases.items():
        with pytest.raises(InvalidDesignError, match=r"body\.yaml: mesh\.file.*" + re.escape(message)):
            read_body_file(path).design()


def test_an_open_or_inside_out_mesh_and_bad_keys_are_refused(tmp_path: Path) -> None:
    mesh = body_mesh(SEGMENTS, R_OUTER, R_INNER)
    open_mesh = mesh.copy()
    open_mesh.update_faces(np.arange(1, len(mesh.faces)))
    write_mesh(open_mesh, tmp_path / "open.stl")
    inside_out = mesh.copy()
    inside_out.invert()
    write_mesh(inside_out, tmp_path / "inverted.stl")
    (tmp_path / "junk.stl").write_text("not a mesh")
    head = "material: {E: 1.85e9}\ntendons:\n  - {offset: 2.75e-3}\n"
    for mesh_key, message in [("{file: open.stl, unit: mm}", "is not watertight"),
                              ("{file: inverted.stl, unit: mm}", "inward or inconsistent normals"),
                              ("{file: junk.stl, unit: mm}", "cannot be read as a mesh|holds no"),
                              ("{file: open.stl, unit: inch}", r"mesh\.unit = 'inch'.*m \| mm"),
                              ("{file: open.stl, scale: 2}", "unknown mesh key")]:
        path = tmp_path / "body.yaml"
        path.write_text(head + f"mesh: {mesh_key}\n")
        with pytest.raises(InvalidDesignError, match=message):
            read_body_file(path).design()
    path.write_text(head + "mesh: {file: open.stl}\ntube: {R_outer: 3.92e-3}\n")
    with pytest.raises(InvalidDesignError, match="tube goes with segments, not with mesh"):
        read_body_file(path).design()


SLANT_CUT, SLANT_DEPTH, SLANT_LENGTH = (5.0, 7.0), (2.0, -1.0), 12.0  # mm: the cut's z, its x


def slant_material(z: float) -> object:
    """What the slanted cut leaves at height ``z`` (mm): the faceted wall where ``x`` is at
    most the cut plane's."""
    (c0, c1), (d0, d1) = SLANT_CUT, SLANT_DEPTH
    return WALL.intersection(box(-10.0, -10.0, d0 + (d1 - d0) * (z - c0) / (c1 - c0), 10.0))


def slant_breaks() -> list[float]:
    """Where the cut plane passes a vertex height of the faceted rings (m from the cut's
    start): there the section's derivatives jump."""
    (c0, c1), (d0, d1) = SLANT_CUT, SLANT_DEPTH
    xs = np.concatenate([r * np.cos(2.0 * np.pi * np.arange(256) / 256)
                         for r in (R_OUTER, R_INNER)])
    inside = xs[(xs < d0) & (xs > d1)]
    return sorted(((inside - d0) / (d1 - d0) * (c1 - c0) * MM).tolist())


def by_shoelace(material: object) -> tuple[float, float, float]:
    """Area (mm^2), centroid x (mm) and centroidal I (mm^4) of a (multi)polygon by the polygon
    moment formulas over its oriented rings (fast enough for an ODE's every step)."""
    from shapely.geometry.polygon import orient

    area = first = second = 0.0
    for part in getattr(material, "geoms", [material]):
        part = orient(part, 1.0)  # exterior counter-clockwise, holes clockwise
        for ring in [part.exterior, *part.interiors]:
            x, y = np.asarray(ring.coords).T
            cross = x[:-1] * y[1:] - x[1:] * y[:-1]
            area += cross.sum() / 2.0
            first += ((x[:-1] + x[1:]) * cross).sum() / 6.0
            second += ((x[:-1] ** 2 + x[:-1] * x[1:] + x[1:] ** 2) * cross).sum() / 12.0
    x_bar = first / area
    return area, x_bar, second - area * x_bar**2


def test_a_slanted_cut_is_one_notch_whose_section_is_exact_all_along_it() -> None:
    mesh = slanted_cut_mesh(R_OUTER, R_INNER, SLANT_LENGTH, [(SLANT_CUT, SLANT_DEPTH)])
    mesh.apply_scale(MM)
    triangles = TriangleMesh(np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64))
    body = _segments(_slices(triangles, "mesh.file"), "mesh.file", "mm")
    assert [s.length for s in body.segments] == pytest.approx([5.0 * MM, 2.0 * MM, 5.0 * MM],
                                                              abs=1e-12)
    profile = body.segments[1].section
    assert isinstance(profile, SlicedProfile)
    inner = np.asarray(profile.bounds[1:-1])  # the rings' vertex heights, and the triangles'
    assert all(np.min(np.abs(inner - b)) <= 1e-11 for b in slant_breaks())  # diagonals' (to
    # the builder's rounding, 1e-8 mm)
    u = np.linspace(0.0, 1.0, 23)[1:-1]
    area, x_bar, inertia, low, high = profile.section_at(u)
    for k, z in enumerate(SLANT_CUT[0] + u * 2.0):
        ref_area, ref_x_bar, ref_inertia = by_chords(slant_material(z))
        assert by_shoelace(slant_material(z)) == pytest.approx((ref_area, ref_x_bar, ref_inertia),
                                                               rel=1e-12, abs=1e-13)
        assert area[k] == pytest.approx(ref_area * MM**2, rel=1e-9)
        assert x_bar[k] == pytest.approx(ref_x_bar * MM, rel=1e-9, abs=1e-12 * MM)
        assert inertia[k] == pytest.approx(ref_inertia * MM**4, rel=1e-9)
        bounds = slant_material(z).bounds
        assert (low[k], high[k]) == pytest.approx((bounds[0] * MM, bounds[2] * MM), abs=1e-11)


@pytest.mark.parametrize("tension", [2.0, 5.0])
def test_a_slanted_cut_solves_as_the_second_solver_with_its_sections(tmp_path: Path,
                                                                      tension: float) -> None:
    """Through an STL body file (float32 coordinates), the tip within 0.1 um of the second
    solver integrating the notch from break to break, its section by polygon moments of what
    the cut leaves at every step."""
    write_mesh(slanted_cut_mesh(R_OUTER, R_INNER, SLANT_LENGTH, [(SLANT_CUT, SLANT_DEPTH)]),
               tmp_path / "body.stl")
    path = tmp_path / "body.yaml"
    path.write_text("material: {E: 1.85e9}\ntendons:\n  - {offset: 2.75e-3}\n"
                    "mesh: {file: body.stl, unit: mm}\n")
    design = read_body_file(path).design()
    assert design.N == 1 and isinstance(design.notch_profiles()[0], SlicedProfile)

    def section(sigma: float) -> tuple[float, float]:
        _, x_bar, inertia = by_shoelace(slant_material(SLANT_CUT[0] + sigma / MM))
        return x_bar * MM, inertia * MM**4

    result = solve(design, tension)
    tip, bends = reference_tip(design, tension, varying={0: (section, slant_breaks())})
    assert abs(complex(result.positions[-1, 2], result.positions[-1, 0]) - tip) <= 0.1e-6
    assert result.notch_angles_rad == pytest.approx(bends, rel=1e-6)
    # the peak strain: the moment about the centroid, (R_c - x_bar) T (the tendon follows the
    # notch), over E I, times the farthest fibre, on a dense sampling of the cut
    strains = []
    for z in np.linspace(*SLANT_CUT, 801):
        material = slant_material(z)
        _, x_bar, inertia = by_shoelace(material)
        low, _, high, _ = material.bounds
        strains.append((design.R_c - x_bar * MM) * tension / (design.E * inertia * MM**4)
                       * max(high - x_bar, x_bar - low) * MM)
    assert result.notch_peak_strains[0] == pytest.approx(max(strains), rel=1e-6)


def test_two_slots_side_by_side_are_one_notch_of_two_sections(tmp_path: Path) -> None:
    """A notch of a tee slot then a one-sided slot (each prismatic): one notch, its section
    stepping between the two, solved as the second solver with the two sections by chords."""
    path = body_file(tmp_path, [("tube", 4.0), ("notch", 1.0, TEE), ("notch", 1.0, CUT),
                                ("tube", 4.0)])
    design = read_body_file(path).design()
    assert design.N == 1 and isinstance(design.notch_profiles()[0], SlicedProfile)
    tee, cut = (by_chords(as_shapely(cross_section(("notch", 1.0, m), WALL)))
                for m in (TEE, CUT))

    def section(sigma: float) -> tuple[float, float]:
        _, x_bar, inertia = tee if sigma < 1.0 * MM else cut
        return x_bar * MM, inertia * MM**4

    result = solve(design, 5.0)
    tip, bends = reference_tip(design, 5.0, varying={0: (section, [1.0 * MM])})
    assert abs(complex(result.positions[-1, 2], result.positions[-1, 0]) - tip) <= 0.1e-6
    assert result.notch_angles_rad == pytest.approx(bends, rel=1e-6)


def test_a_sliced_notch_in_a_batch_a_baseline_a_body_file_and_another_width(tmp_path: Path
                                                                            ) -> None:
    """The many-design build gives the single solve's tip bit for bit; the baselines, which
    model the paper's band notch only, and the body-file writer, which has no form for slices,
    refuse it naming the notch; a width other than the slices' is refused naming ``w_n``."""
    from dataclasses import replace

    from tdcm_ros.model.baselines import METHODS, solve_with
    from tdcm_ros.model.batch import solve_batch
    from tdcm_ros.model.body_file import body_file_text

    design = read_body_file(body_file(tmp_path, [("tube", 4.0), ("notch", 1.0, TEE),
                                                 ("notch", 1.0, CUT), ("tube", 4.0)])).design()
    single = solve(design, 5.0)
    batch = solve_batch([design, design], [5.0, 2.0])
    assert batch.tip_position[0].tolist() == single.tip_position.tolist()
    for method in sorted(set(METHODS) - {"algorithm1"}):
        with pytest.raises(InvalidDesignError, match=r"profile\[0\] = 'sliced'.*" + method):
            solve_with(method, design, 5.0)
    with pytest.raises(InvalidDesignError, match="no body-file form"):
        body_file_text(design)
    with pytest.raises(InvalidDesignError, match=r"w_n = 0\.003.*0\.002 m \(the width of the"):
        replace(design, w_n=3.0 * MM)
