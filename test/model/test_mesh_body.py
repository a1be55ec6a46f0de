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
from test.support.meshes import (
    annulus,
    as_shapely,
    body_mesh,
    cross_section,
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
    for name in "zxpfg":
        (tmp_path / name).mkdir()
    cases = {
        "starts at z = 0.001 m": body_file(tmp_path / "z", z=1.0),
        "centred at (x, y) = (0.0005": body_file(tmp_path / "x", x=0.5),
        "notch 1 changes its section along the body": body_file(
            tmp_path / "p", [("tube", 4.0), ("notch", 1.0, TEE), ("notch", 1.0, CUT),
                             ("tube", 4.0)]),
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
