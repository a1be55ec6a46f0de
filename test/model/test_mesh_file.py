"""Mesh files read and checked (:mod:`tdcm_ros.model.mesh_file`): binary and ASCII STL by
NumPy, other formats by trimesh, every one to the same triangles; broken files refused naming
what is wrong. References: the mesh the test builds (manifold3d), written by trimesh's
exporters, and its volume by trimesh."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
from shapely.geometry import box

from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.mesh_body import read_mesh_body
from tdcm_ros.model.mesh_file import read_mesh
from test.support.meshes import annulus, body_mesh, write_mesh

R_OUTER, R_INNER = 3.92, 1.55  # mm

def _mesh() -> Any:
    """A tube with a one-sided cut (mm), 64-gons."""
    cut = annulus(R_OUTER, R_INNER, 64).intersection(box(-5.0, -5.0, 0.8, 5.0))
    return body_mesh([("tube", 3.0), ("notch", 1.0, cut), ("tube", 3.0)], R_OUTER, R_INNER, 64)


def _sorted_triangles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The triangles as a canonical array: each rotated to start at its smallest corner, sorted."""
    corners = vertices[faces]
    keys = [tuple(map(tuple, np.roll(tri, -int(np.lexsort(tri.T[::-1])[0]), axis=0)))
            for tri in corners]
    return np.array(sorted(keys))


def test_binary_and_ascii_stl_and_other_formats_give_the_same_triangles(tmp_path: Path) -> None:
    binary = write_mesh(_mesh(), tmp_path / "body.stl")
    # the same triangles in other files: the binary STL's (float32) coordinates, as written
    mesh = trimesh.load(str(binary), force="mesh", process=False)
    ascii_stl = tmp_path / "ascii.STL"
    mesh.export(str(ascii_stl), file_type="stl_ascii")
    ply = write_mesh(mesh, tmp_path / "body.ply")
    by_trimesh = trimesh.load(str(binary), force="mesh")  # it merges corners on loading
    by_trimesh.update_faces(by_trimesh.nondegenerate_faces())
    by_trimesh.remove_unreferenced_vertices()
    expected = _sorted_triangles(np.asarray(by_trimesh.vertices) * 1e-3,
                                 np.asarray(by_trimesh.faces))
    for path in (binary, ascii_stl):
        got = read_mesh(path, 1e-3, "mesh.file")
        assert got.vertices.shape[0] == len(by_trimesh.vertices)
        np.testing.assert_array_equal(_sorted_triangles(got.vertices, got.faces), expected)
    from_ply = read_mesh(ply, 1e-3, "mesh.file")
    np.testing.assert_array_equal(_sorted_triangles(from_ply.vertices, from_ply.faces), expected)
    volume = np.einsum("ij,ij->", from_ply.corners()[:, 0], from_ply.normals()) / 6.0
    assert volume == pytest.approx(mesh.volume * 1e-9, rel=1e-12)
    bodies = [read_mesh_body(p, "mm") for p in (binary, ascii_stl, ply)]
    assert bodies[0].segments[1].section is not None
    assert bodies[0] == bodies[1] == bodies[2]


def test_a_sliver_triangle_of_coincident_corners_is_dropped(tmp_path: Path) -> None:
    mesh = _mesh()
    vertices = np.asarray(mesh.vertices)
    faces = np.asarray(mesh.faces)
    corner = faces[0, 0]
    sliver = np.array([[corner, corner, faces[0, 1]]])  # no area: dropped, the rest is closed
    path = write_mesh(trimesh.Trimesh(vertices, np.concatenate([faces, sliver]),
                                      process=False), tmp_path / "sliver.stl")
    without = write_mesh(mesh, tmp_path / "without.stl")
    np.testing.assert_array_equal(read_mesh(path, 1e-3, "mesh.file").faces,
                                  read_mesh(without, 1e-3, "mesh.file").faces)


def test_broken_files_are_refused_naming_what_is_wrong(tmp_path: Path) -> None:
    mesh = _mesh()
    binary = write_mesh(mesh, tmp_path / "body.stl").read_bytes()
    (tmp_path / "short.stl").write_bytes(binary[:-7])
    (tmp_path / "word.stl").write_text("solid x\nfacet normal 0 0 1\nouter loop\n"
                                       "vertex 0 0 0\nvertex 1 0 zero\nvertex 0 1 0\n"
                                       "endloop\nendfacet\nendsolid x\n")
    (tmp_path / "two.stl").write_text("solid x\nvertex 0 0 0\nvertex 1 0 0\nendsolid x\n")
    (tmp_path / "empty.stl").write_text("solid x\nendsolid x\n")
    (tmp_path / "junk.ply").write_text("not a mesh")
    faces = np.asarray(mesh.faces).copy()
    faces[0] = faces[0, ::-1]  # one triangle turned over: its edges run the same way twice
    write_mesh(trimesh.Trimesh(np.asarray(mesh.vertices), faces, process=False),
               tmp_path / "flipped.stl")
    write_mesh(trimesh.Trimesh(np.asarray(mesh.vertices), np.asarray(mesh.faces)[1:],
                               process=False), tmp_path / "open.stl")
    cases = {"short.stl": "neither a binary STL",
             "word.stl": "a vertex that is not three numbers",
             "two.stl": "2 vertices, not three per facet",
             "empty.stl": "holds no triangles",
             "junk.ply": "cannot be read as a mesh",
             "flipped.stl": "run a shared edge the same way",
             "open.stl": r"is not watertight \(3 edges not shared by exactly two"}
    for name, message in cases.items():
        with pytest.raises(InvalidDesignError, match=message) as caught:
            read_mesh(tmp_path / name, 1e-3, "mesh.file")
        assert caught.value.parameter == "mesh.file" and name in str(caught.value)
