"""Registration of the motion-capture frame to the robot frame (``mocap`` -> ``tdcm_base``).

A :class:`Registration` is the pose of ``tdcm_base`` in ``mocap`` (the static transform with
parent ``mocap`` and child ``tdcm_base``): ``p_mocap = R p_base + t``. :meth:`Registration.to_base`
maps marker positions (m) from ``mocap`` into ``tdcm_base``.

:func:`estimate_registration` builds it from markers alone (contract conventions: markers on
the body surface at known arc lengths, ``radius`` off the midline at ``side_rad`` around the
body z axis from the tendon side):

- a **zero-tension** frame gives the body axis (+z, a line fit of the markers against their arc
  lengths) and the origin (the fitted line at ``s = 0``, moved back by the marker offset);
- a **bent** frame (the largest deflection) gives the bending plane: +x is the direction the
  markers moved, perpendicular to the axis.

Limitation: at zero tension the markers are collinear, so they fix the axis and the origin but
not the roll about the axis. Without a bent frame the roll must come from ``x_hint`` (a
``mocap`` direction whose component perpendicular to the axis is +x), otherwise
:class:`RegistrationError` is raised.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import InputError, out_of_range

Array = NDArray[np.float64]

MIN_BEND_M = 1e-3
"""Default smallest perpendicular marker motion (m) accepted to fix the bending plane."""


class RegistrationError(InputError):
    """The markers cannot determine the ``mocap`` -> ``tdcm_base`` transform."""


@dataclass(frozen=True)
class Registration:
    """Pose of ``tdcm_base`` in ``mocap``: ``translation`` (3,) m, ``quaternion`` (x, y, z, w).

    ``method`` says where it came from (``given``, ``tf_static``, ``estimated``);
    ``residual_m`` is the RMS distance of the zero-tension markers from the fitted axis
    (estimated only, else 0).
    """

    translation: tuple[float, ...]  # 3 entries, checked on construction
    quaternion: tuple[float, ...]  # 4 entries, checked on construction
    method: str = "given"
    residual_m: float = 0.0

    def __post_init__(self) -> None:
        t = np.asarray(self.translation, dtype=float)
        q = np.asarray(self.quaternion, dtype=float)
        if t.shape != (3,) or not np.all(np.isfinite(t)):
            raise out_of_range("translation", self.translation, "3 finite numbers", unit="m",
                               error=RegistrationError)
        norm = float(np.linalg.norm(q)) if q.shape == (4,) else 0.0
        if q.shape != (4,) or not np.all(np.isfinite(q)) or norm < 1e-9:
            raise out_of_range("quaternion", self.quaternion, "4 finite numbers, not all zero",
                               error=RegistrationError)
        object.__setattr__(self, "translation", tuple(float(v) for v in t))
        object.__setattr__(self, "quaternion", tuple(float(v) for v in q / norm))

    @classmethod
    def identity(cls, method: str = "given") -> Registration:
        """``tdcm_base`` coincides with ``mocap``."""
        return cls((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), method)

    @classmethod
    def from_matrix(cls, rotation: ArrayLike, translation: ArrayLike, *, method: str = "given",
                    residual_m: float = 0.0) -> Registration:
        """From a rotation matrix (3, 3) (columns: base axes in ``mocap``) and a translation (m)."""
        # scipy on use only: the mocap face imports this module
        from scipy.spatial.transform import Rotation

        quat = Rotation.from_matrix(np.asarray(rotation, dtype=float)).as_quat()
        return cls(tuple(np.asarray(translation, dtype=float)), tuple(quat), method, residual_m)

    @property
    def rotation(self) -> Array:
        """Rotation matrix (3, 3) whose columns are the ``tdcm_base`` axes in ``mocap``."""
        # scipy on use only: the mocap face imports this module
        from scipy.spatial.transform import Rotation

        return Rotation.from_quat(self.quaternion).as_matrix()

    def to_base(self, points_mocap: ArrayLike) -> Array:
        """Points (..., 3) m from ``mocap`` into ``tdcm_base`` (NaN rows stay NaN)."""
        p = np.asarray(points_mocap, dtype=float)
        return (p - np.asarray(self.translation)) @ self.rotation

    def to_mocap(self, points_base: ArrayLike) -> Array:
        """Points (..., 3) m from ``tdcm_base`` into ``mocap``."""
        p = np.asarray(points_base, dtype=float)
        return p @ self.rotation.T + np.asarray(self.translation)


def _visible(points: Array, name: str) -> NDArray[np.bool_]:
    if points.ndim != 2 or points.shape[1] != 3:
        raise out_of_range(name, points.shape, "an array of shape (k, 3)",
                           error=RegistrationError)
    return np.all(np.isfinite(points), axis=1)


def estimate_registration(zero_markers: ArrayLike, arc_lengths: ArrayLike, *,
                          radius: float, side_rad: float,
                          bent_markers: ArrayLike | None = None,
                          x_hint: ArrayLike | None = None,
                          min_bend_m: float = MIN_BEND_M) -> Registration:
    """Estimate ``mocap`` -> ``tdcm_base`` from marker positions in ``mocap`` (m).

    ``zero_markers`` (k, 3): markers at zero tension (NaN rows = not visible; at least two
    visible markers with distinct arc lengths). ``arc_lengths`` (k,) m of the markers, ``radius``
    (m) of their centres from the midline, ``side_rad`` their side around the body z axis from
    the tendon side. ``bent_markers`` (k, 3): the same markers at the largest deflection; they
    fix +x (the direction the markers moved across the axis, at least ``min_bend_m``). Without
    them, ``x_hint`` (3,) gives +x as its component across the axis.
    """
    zero = np.asarray(zero_markers, dtype=float)
    s = np.asarray(arc_lengths, dtype=float)
    seen = _visible(zero, "zero_markers")
    if s.shape != (zero.shape[0],):
        raise out_of_range("arc_lengths", list(s), f"{zero.shape[0]} arc lengths (m)",
                           error=RegistrationError)
    if not (np.isfinite(radius) and radius >= 0.0):
        raise out_of_range("radius", radius, "[0, inf)", unit="m", error=RegistrationError)
    if not (np.isfinite(min_bend_m) and min_bend_m > 0.0):
        raise out_of_range("min_bend_m", min_bend_m, "(0, inf)", unit="m",
                           error=RegistrationError)
    if seen.sum() < 2 or np.ptp(s[seen]) <= 0.0:
        raise RegistrationError(
            f"zero-tension markers: {int(seen.sum())} visible at distinct arc lengths; "
            "allowed: at least 2 to fix the body axis", parameter="zero_markers",
            value=int(seen.sum()), allowed=">= 2 visible markers")
    # Line fit p_i = a + s_i z (least squares in s): z is the slope, a the point at s = 0.
    s_seen, p_seen = s[seen], zero[seen]
    s_mean, p_mean = s_seen.mean(), p_seen.mean(axis=0)
    slope = ((s_seen - s_mean) @ (p_seen - p_mean)) / np.sum((s_seen - s_mean) ** 2)
    z_axis = slope / np.linalg.norm(slope)
    # Re-fit the intercept with a unit slope (arc length is distance along the straight body).
    line_point = np.mean(p_seen - s_seen[:, None] * z_axis, axis=0)
    fitted = line_point + s_seen[:, None] * z_axis
    residual = float(np.sqrt(np.mean(np.sum((p_seen - fitted) ** 2, axis=1))))
    x_axis = _plane_direction(zero, seen, z_axis, bent_markers, x_hint, min_bend_m)
    y_axis = np.cross(z_axis, x_axis)
    rotation = np.column_stack([x_axis, y_axis, z_axis])
    offset = radius * (np.cos(side_rad) * x_axis + np.sin(side_rad) * y_axis)
    origin = line_point - offset
    return Registration.from_matrix(rotation, origin, method="estimated", residual_m=residual)


def _plane_direction(zero: Array, seen: NDArray[np.bool_], z_axis: Array,
                     bent_markers: ArrayLike | None, x_hint: ArrayLike | None,
                     min_bend_m: float) -> Array:
    """+x: the markers' motion across the axis between the zero and the bent frame, or x_hint."""
    if bent_markers is not None:
        bent = np.asarray(bent_markers, dtype=float)
        both = _visible(bent, "bent_markers") & seen if bent.shape == zero.shape else None
        if both is None:
            raise out_of_range("bent_markers", bent.shape, f"shape {zero.shape}",
                               error=RegistrationError)
        motion = (bent[both] - zero[both]).sum(axis=0) if both.any() else np.zeros(3)
        across = motion - (motion @ z_axis) * z_axis
        moved = float(np.linalg.norm(across)) / max(int(both.sum()), 1)
        if moved < min_bend_m:
            raise RegistrationError(
                f"bent_markers moved {moved:.3g} m across the body axis; allowed: at least "
                f"min_bend_m = {min_bend_m:g} m to fix the bending plane", parameter="bent_markers",
                value=moved, allowed=f">= {min_bend_m:g} m")
        return across / np.linalg.norm(across)
    if x_hint is not None:
        hint = np.asarray(x_hint, dtype=float)
        across = hint - (hint @ z_axis) * z_axis if hint.shape == (3,) else np.zeros(3)
        if not np.all(np.isfinite(across)) or np.linalg.norm(across) < 1e-9:
            raise out_of_range("x_hint", x_hint, "a finite 3-vector not parallel to the body axis",
                               error=RegistrationError)
        return across / np.linalg.norm(across)
    raise RegistrationError(
        "zero-tension markers are collinear and cannot fix the roll about the body axis; "
        "allowed: give bent_markers (a deflected frame) or x_hint", parameter="bent_markers",
        value=None, allowed="a bent frame or x_hint")
