"""Targets in ``tdcm_base`` resolved to a roll and an in-plane target for the inverse model.

A 3D tip point ``(x, y, z)`` (m) is a roll ``phi = atan2(y, x)`` (rad, about the base +z axis,
REP 103) plus the in-plane point ``(hypot(x, y), z)`` of the bending plane (``x`` toward the
tendon); a point on the z axis (``hypot < AXIS_EPS_M``) keeps the current roll. A tip angle
(rad, in the bending plane) keeps the current roll. Roll outside ``[-roll_max, roll_max]`` is
refused (the body bends toward +x only, so a point behind it is not reachable by a smaller
roll).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tdcm_ros.control.errors import TargetRefusedError
from tdcm_ros.errors import out_of_range
from tdcm_ros.model import roll_points

#: Distance from the z axis (m) below which a point target keeps the current roll.
AXIS_EPS_M = 1e-12


@dataclass(frozen=True)
class PlaneTarget:
    """A target resolved: the roll (rad) and exactly one of ``tip_point`` (in-plane ``(r, z)``,
    m) or ``tip_angle`` (rad)."""

    roll_rad: float
    tip_point: tuple[float, float] | None = None
    tip_angle: float | None = None


def _finite(name: str, value: float, allowed: str, unit: str) -> float:
    number = float(value)
    if not math.isfinite(number):
        raise out_of_range(name, value, allowed, unit=unit, error=TargetRefusedError)
    return number


def check_roll(roll_rad: float, roll_max: float) -> float:
    """``roll_rad`` if within ``[-roll_max, roll_max]`` rad, else :class:`TargetRefusedError`."""
    roll = _finite("target roll", roll_rad, f"[{-roll_max:.6g}, {roll_max:.6g}] rad", "rad")
    if abs(roll) > roll_max:
        raise out_of_range("target roll", roll, f"[{-roll_max:.6g}, {roll_max:.6g}] rad "
                           "(atan2(y, x) of the point; the body bends toward +x only)",
                           unit="rad", error=TargetRefusedError)
    return roll


def point_target(point: tuple[float, float, float], current_roll: float,
                 roll_max: float) -> PlaneTarget:
    """The roll and in-plane point of a tip point ``(x, y, z)`` (m, ``tdcm_base``)."""
    x, y, z = (_finite(f"target {axis}", v, "a finite number (m)", "m")
               for axis, v in zip("xyz", point, strict=True))
    radial = math.hypot(x, y)
    roll = current_roll if radial < AXIS_EPS_M else math.atan2(y, x)
    return PlaneTarget(check_roll(roll, roll_max), tip_point=(radial, z))


def angle_target(angle: float, current_roll: float) -> PlaneTarget:
    """An in-plane tip angle (rad) at the current roll (rad)."""
    return PlaneTarget(current_roll, tip_angle=_finite("target angle", angle,
                                                       "a finite number (rad)", "rad"))


def rotate_z(point: tuple[float, float, float], roll_rad: float) -> tuple[float, float, float]:
    """``point`` (m) rotated by ``roll_rad`` about the base +z axis: the model's
    :func:`~tdcm_ros.model.roll_points` for one point, as a tuple of floats."""
    x, y, z = (float(value) for value in roll_points(point, roll_rad))
    return (x, y, z)


def in_plane(point: tuple[float, float, float], roll_rad: float) -> tuple[float, float]:
    """``(u, z)`` of a base point in the bending plane at ``roll_rad``: ``u`` along the rolled
    +x axis (m), the off-plane component dropped."""
    x, _, z = rotate_z(point, -roll_rad)
    return (x, z)
