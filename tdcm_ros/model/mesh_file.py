"""Triangle meshes read from a file and checked: an STL by NumPy, other formats by trimesh.

An STL (binary or ASCII, the format of a lab's CAD export or printer file) is read here:
NumPy reads its triangles in milliseconds, where importing trimesh (it pulls SciPy's spatial
and sparse packages) costs ~1.5 s, most of a first solve's 2 s budget
(``bench/bench_mesh.py``). Any other format trimesh reads (OBJ, PLY, OFF, 3MF, ...) goes
through trimesh's loader. Either way the triangles get the same treatment: vertices equal to
:data:`MERGE_DIGITS` decimals are one (as trimesh merges them), triangles without area are
dropped (an export's slivers), and the checks a body needs: closed (every edge shared by
exactly two triangles), consistently oriented (the two run it in opposite directions) and
outward (positive volume).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.errors import InvalidDesignError

Array = NDArray[np.float64]
Ints = NDArray[np.int64]

#: Decimals (in the file's unit) to which vertices are compared when merged; a triangle whose
#: smallest height is below ``10**-MERGE_DIGITS`` has no area. trimesh's ``tol.merge``.
MERGE_DIGITS = 8
_BINARY_HEADER = 84
_BINARY_RECORD = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                           ("attribute", "<u2")])
_ASCII_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)")


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    """A closed, outward-oriented triangle mesh: ``vertices`` (V, 3) in metres, ``faces``
    (F, 3) vertex indices, counter-clockwise seen from outside."""

    vertices: Array
    faces: Ints

    def corners(self) -> Array:
        """The triangles' corners (F, 3, 3), m."""
        return self.vertices[self.faces]

    def normals(self) -> Array:
        """Each triangle's outward normal (F, 3), its length twice its area (m^2)."""
        corners = self.corners()
        return np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])


def read_mesh(path: str | Path, scale: float, key: str) -> TriangleMesh:
    """The mesh in the file at ``path``, its lengths times ``scale`` (m per unit), checked;
    every problem is an :class:`InvalidDesignError` naming ``key``."""
    path = Path(path)
    if path.suffix.lower() == ".stl":
        triangles = _stl_triangles(path, key)
        vertices, faces = _merged(triangles.reshape(-1, 3))
    else:
        vertices, faces = _library_mesh(path, key)
        vertices, merged = _merged(vertices)
        faces = merged[faces]
    faces = _with_area(vertices, faces)
    if faces.shape[0] == 0:
        raise InvalidDesignError(f"{key} = {str(path)!r} holds no triangles", parameter=key,
                                 value=str(path), allowed="a triangle mesh of the body")
    _check_closed(faces, path, key)
    used, faces = np.unique(faces, return_inverse=True)
    mesh = TriangleMesh(vertices[used] * scale, faces.reshape(-1, 3).astype(np.int64))
    volume = float(np.einsum("ij,ij->", mesh.corners()[:, 0], mesh.normals())) / 6.0
    if volume <= 0.0:
        raise InvalidDesignError(
            f"{key} = {str(path)!r} has inward or inconsistent normals (volume {volume:.3g} "
            "m^3); allowed: outward normals", parameter=key, value=str(path),
            allowed="a mesh with consistent outward normals")
    return mesh


def _unreadable(path: Path, key: str, why: str) -> InvalidDesignError:
    return InvalidDesignError(f"{key} = {str(path)!r} cannot be read as a mesh: {why}",
                              parameter=key, value=str(path),
                              allowed="a mesh file: STL, or another format trimesh reads "
                                      "(OBJ, PLY, ...)")


def _stl_triangles(path: Path, key: str) -> Array:
    """The triangles of the binary or ASCII STL at ``path``, shape (F, 3, 3), file units."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise _unreadable(path, key, str(error)) from error
    if len(data) >= _BINARY_HEADER:
        count = int(np.frombuffer(data, "<u4", 1, 80)[0])
        if len(data) == _BINARY_HEADER + count * _BINARY_RECORD.itemsize:
            records = np.frombuffer(data, _BINARY_RECORD, count, _BINARY_HEADER)
            return records["corners"].astype(np.float64)
    if not data.lstrip().startswith(b"solid"):
        raise _unreadable(path, key, "neither a binary STL (its size does not match its "
                          "triangle count) nor an ASCII one (it does not start with 'solid')")
    try:
        corners = np.array(_ASCII_VERTEX.findall(data), dtype=np.float64)
    except ValueError as error:
        raise _unreadable(path, key, f"a vertex that is not three numbers ({error})") from error
    if corners.shape[0] % 3 != 0:
        raise _unreadable(path, key, f"{corners.shape[0]} vertices, not three per facet")
    return corners.reshape(-1, 3, 3)


def _library_mesh(path: Path, key: str) -> tuple[Array, Ints]:
    """Vertices and faces of a non-STL mesh file, by trimesh's loader."""
    import trimesh

    try:
        mesh = trimesh.load(str(path), force="mesh")
    except Exception as error:  # trimesh raises many types for unreadable files
        raise _unreadable(path, key, str(error)) from error
    if not isinstance(mesh, trimesh.Trimesh):
        raise _unreadable(path, key, f"it holds a {type(mesh).__name__}, not triangles")
    return (np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3),
            np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3))


def _merged(points: Array) -> tuple[Array, Ints]:
    """Distinct vertices of ``points`` (N, 3) to :data:`MERGE_DIGITS` decimals (each the first
    of its kind, unrounded) and each point's index among them."""
    rounded = np.round(points, MERGE_DIGITS)
    order = np.lexsort(rounded.T[::-1])  # stable: equal points keep their order
    ordered = rounded[order]
    first_of_kind = np.ones(order.size, dtype=bool)
    first_of_kind[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    index = np.empty(order.size, dtype=np.int64)
    index[order] = np.cumsum(first_of_kind) - 1
    return points[order[first_of_kind]], index


def _with_area(vertices: Array, faces: Ints) -> Ints:
    """``faces`` without those whose smallest height is below ``10**-MERGE_DIGITS``."""
    corners = vertices[faces.reshape(-1, 3)]
    doubled_area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                           corners[:, 2] - corners[:, 0]), axis=1)
    longest = np.max(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2), axis=1)
    keep = doubled_area > 10.0**-MERGE_DIGITS * longest
    return faces.reshape(-1, 3)[keep]


def _check_closed(faces: Ints, path: Path, key: str) -> None:
    """Refuse a mesh with an edge not shared by exactly two faces (not watertight) or run the
    same way by both (inconsistent orientation)."""
    directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    size = int(faces.max()) + 1
    forward = directed[:, 0] * size + directed[:, 1]
    undirected = np.minimum(directed[:, 0], directed[:, 1]) * size + np.maximum(
        directed[:, 0], directed[:, 1])
    _, shared = np.unique(undirected, return_counts=True)
    if np.any(shared != 2):
        raise InvalidDesignError(
            f"{key} = {str(path)!r} is not watertight ({int(np.sum(shared != 2))} edges not "
            "shared by exactly two triangles: its surface has holes or loose edges); allowed: "
            "a closed, watertight mesh", parameter=key, value=str(path),
            allowed="a watertight mesh")
    if np.unique(forward).size != forward.size:
        raise InvalidDesignError(
            f"{key} = {str(path)!r} has inward or inconsistent normals (neighbouring triangles "
            "run a shared edge the same way); allowed: outward normals", parameter=key,
            value=str(path), allowed="a mesh with consistent outward normals")
