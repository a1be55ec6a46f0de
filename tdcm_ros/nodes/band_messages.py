"""The model node's uncertainty outputs: the tip with its covariance and the shape's band.

From a calibration's :class:`~tdcm_ros.model.ParameterCovariance` (a model file's
``uncertainty``), :func:`shape_spread` carries the parameters' covariance to the midline points
and the tip angle through the solver (:mod:`tdcm_ros.model.uncertainty`, forward differences:
one extra solve per fitted parameter) and adds the fit's residual variance to each point: the
*prediction* covariance, where a marker on the body would be measured. Then
:func:`uncertainty_messages` builds, in ``frame_id`` and turned by the roll:

- ``tip_pose_with_covariance`` (``geometry_msgs/msg/PoseWithCovarianceStamped``): the tip pose;
  covariance row-major 6 x 6 over (x, y, z, rotation about x, y, z): the position block the
  tip's prediction covariance (m^2), the rotation block the tip angle's variance (rad^2) about
  the bending plane's normal (the planar model's other rotations are exact: 0);
- ``shape_band`` (``visualization_msgs/msg/Marker``, a ``TRIANGLE_LIST`` in namespace
  ``tdcm_band``): the ``confidence`` band of the midline in the bending plane, each sample
  widened by its interval along the in-plane normal.

Both are written as CDR straight from the arrays (:class:`~tdcm_ros.bagio.CdrWriter`,
:func:`~tdcm_ros.nodes.shape_messages.marker_cdr`), the bytes rosbags would give.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import CdrWriter, cdr_header
from tdcm_ros.model import (
    Design,
    ParameterCovariance,
    SolveResult,
    band_half_widths,
    linearised_covariances,
    prediction_covariances,
    roll_points,
    roll_quaternions,
)
from tdcm_ros.nodes.shape_messages import TRIANGLE_LIST, MarkerStyle, marker_cdr

Array = NDArray[np.float64]
BAND_NAMESPACE = "tdcm_band"
#: RGBA of the band (translucent blue).
BAND_COLOR = (0.2, 0.5, 1.0, 0.35)
BAND_STYLE = MarkerStyle(BAND_NAMESPACE, 0, TRIANGLE_LIST, (1.0, 1.0, 1.0), BAND_COLOR)


@dataclass(frozen=True, eq=False)
class ShapeSpread:
    """The planar midline ``points`` (k, 3) m at arc lengths ``s`` with their prediction
    covariances (k, 3, 3) m^2, and the tip angle's variance (rad^2, parameters only)."""

    s: Array
    points: Array
    covariances: Array
    tip_angle_variance: float


def shape_spread(result: SolveResult, mu: float, uncertainty: ParameterCovariance, s: Array,
                 resolve: Callable[[Design, float], SolveResult]) -> ShapeSpread:
    """The spread of ``result`` (solved with friction ``mu``) at arc lengths ``s`` (m):
    ``resolve(design, mu)`` solves the same input for moved parameters."""
    def rows(solved: SolveResult) -> Array:
        # the midline points, and the tip angle (rad) carried as one more row's x
        angle = np.array([[solved.tip_angle_rad, 0.0, 0.0]])
        return np.vstack([solved.pose_at(s)[0], angle])

    def rows_at(design: Design, moved_mu: float) -> Array:
        return rows(resolve(design, moved_mu))

    centre = rows(result)
    spread = linearised_covariances(rows_at, result.design, mu, uncertainty, centre)
    return ShapeSpread(s, centre[:-1], prediction_covariances(spread[:-1], uncertainty.residual_m),
                       float(spread[-1, 0, 0]))


def uncertainty_messages(spread: ShapeSpread, result: SolveResult, *, stamp_ns: int,
                         frame_id: str, roll: float, confidence: float
                         ) -> Iterator[tuple[str, bytes]]:
    """``(topic, CDR bytes)`` for ``tip_pose_with_covariance`` and ``shape_band`` (see the
    module docstring), turned by ``roll`` (rad about +z)."""
    hdr = cdr_header(stamp_ns, frame_id)
    turn = roll_points(np.eye(3), roll).T  # R: a point p turns to R p
    tip = roll_points(result.tip_position, roll)
    quat = roll_quaternions(result.tip_quaternion, roll)
    covariance = np.zeros((6, 6))
    covariance[:3, :3] = turn @ spread.covariances[-1] @ turn.T
    normal_axis = turn @ np.array([0.0, 1.0, 0.0])  # the bending plane's normal: the tip bends about it
    covariance[3:, 3:] = spread.tip_angle_variance * np.outer(normal_axis, normal_axis)
    writer = CdrWriter()  # PoseWithCovarianceStamped: header, then float64s from the pose on
    writer.raw(hdr)
    writer.raw(np.concatenate([tip, quat, covariance.ravel()]).astype("<f8").tobytes(), 8)
    yield "tip_pose_with_covariance", writer.data()
    yield "shape_band", _band_marker(hdr, band_edges(spread, confidence), roll)


def band_edges(spread: ShapeSpread, confidence: float) -> tuple[Array, Array]:
    """The band's two edges (k, 3) m in the bending plane: each point moved by its
    ``confidence`` half-width along the in-plane normal (toward +x and away)."""
    tangent = np.gradient(spread.points, spread.s, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    normal = np.column_stack([tangent[:, 2], np.zeros(len(tangent)), -tangent[:, 0]])
    half = band_half_widths(spread.covariances, normal, confidence)[:, None]
    return spread.points + half * normal, spread.points - half * normal


def _band_marker(hdr: bytes, edges: tuple[Array, Array], roll: float) -> bytes:
    """The band as a ``TRIANGLE_LIST`` marker (CDR, header ``hdr``): two triangles per pair
    of samples."""
    outer, inner = (roll_points(edge, roll) for edge in edges)
    corners = np.stack([outer[:-1], inner[:-1], outer[1:], inner[:-1], inner[1:], outer[1:]],
                       axis=1).reshape(-1, 3)
    return marker_cdr(hdr, BAND_STYLE, corners)
