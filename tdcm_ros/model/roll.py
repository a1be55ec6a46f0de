"""Roll: the whole manipulator, and so its bending plane, turned about the base +z axis.

Frame ``tdcm_base`` (REP 103, SI units): the planar model bends in the x-z plane toward +x. A
roll ``phi`` (rad, right-handed about +z) turns every point of the solved shape rigidly, so a
planar point ``(x, 0, z)`` becomes ``(x cos phi, x sin phi, z)`` and every body frame ``q``
becomes ``q_z(phi) q``. ``phi = 0`` returns the inputs unchanged, bit for bit.

Loads fixed in ``tdcm_base`` (a scene's gravity, a tip load) do not roll with the body: the
planar model takes their component in the rolled bending plane (:func:`roll_loading`); the
component normal to it would bend the body out of the plane, which the planar model cannot
represent, and is left out.
"""

from __future__ import annotations

import math
import numbers
from bisect import bisect_right
from collections import deque
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.model.errors import ModelError
from tdcm_ros.model.loading import Loading

Array = NDArray[np.float64]


class InvalidRollError(ModelError, InputError):
    """The roll angle is not a finite real number."""

    kind = "invalid_roll"


def check_roll(roll: Any, parameter: str = "roll") -> float:
    """``roll`` (rad) as a float, or :class:`InvalidRollError` naming ``parameter``: any finite
    real number (``bool``, strings and arrays are refused)."""
    if isinstance(roll, (bool, np.bool_)) or not isinstance(roll, numbers.Real) \
            or not math.isfinite(float(roll)):
        raise out_of_range(parameter, roll, "a finite real number (-inf, inf)", unit="rad",
                           error=InvalidRollError)
    return float(roll)


def roll_points(points: ArrayLike, roll: float) -> Array:
    """Points (..., 3) m turned by ``roll`` (rad) about +z; unchanged at ``roll = 0``."""
    phi = check_roll(roll)
    p = np.asarray(points, dtype=float)
    if phi == 0.0:
        return p
    c, s = math.cos(phi), math.sin(phi)
    return p @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # rows: p R_z^T


def roll_quaternions(quaternions: ArrayLike, roll: float) -> Array:
    """Orientations (..., 4) ``(x, y, z, w)`` turned by ``roll`` (rad) about +z: the product
    ``q_z(roll) q``; unchanged at ``roll = 0``."""
    phi = check_roll(roll)
    q = np.asarray(quaternions, dtype=float)
    if phi == 0.0:
        return q
    c, s = math.cos(0.5 * phi), math.sin(0.5 * phi)
    # (x, y, z, w) -> (c x - s y, c y + s x, c z + s w, c w - s z), as rows: q M^T
    return q @ np.array([[c, s, 0.0, 0.0], [-s, c, 0.0, 0.0], [0.0, 0.0, c, -s],
                         [0.0, 0.0, s, c]])


def roll_poses(positions: ArrayLike, quaternions: ArrayLike, roll: float
               ) -> tuple[Array, Array]:
    """Poses (positions (k, 3) m, quaternions (k, 4) xyzw) turned by ``roll`` (rad) about +z."""
    return roll_points(positions, roll), roll_quaternions(quaternions, roll)


def depends_on_roll(loading: Loading | None) -> bool:
    """True when ``loading`` has a base-frame load whose in-plane part changes with the roll
    (a tip force or body force with an x component, or a tip moment)."""
    return loading is not None and (loading.tip_force[0] != 0.0 or loading.tip_moment != 0.0
                                    or loading.body_force_density[0] != 0.0)


def roll_loading(loading: Loading | None, roll: float) -> Loading | None:
    """The planar loading of a body rolled by ``roll`` (rad) under ``loading``'s base-frame
    loads: their part in the rolled bending plane. A force ``(F_x, F_z)`` keeps
    ``(F_x cos roll, F_z)``, a moment about +y keeps ``M cos roll``; the rest acts out of the
    plane and is dropped. ``loading`` itself when nothing depends on the roll."""
    phi = check_roll(roll)
    if phi == 0.0 or loading is None or not depends_on_roll(loading):
        return loading
    c = math.cos(phi)
    force_x, force_z = loading.tip_force
    density_x, density_z = loading.body_force_density
    return replace(loading, tip_force=(force_x * c, force_z), tip_moment=loading.tip_moment * c,
                   body_force_density=(density_x * c, density_z))


class StampedHistory:
    """Recent values by stamp, to pair each sample of another stream with this one's value at
    its time: the latest value stamped at or before it, else the oldest kept (all are newer),
    else ``empty`` (none yet). Stamps in any one unit (ns, s), fed in order; an out-of-order
    value replaces nothing and is ignored. Keeps the last ``size``."""

    def __init__(self, size: int = 2048, empty: float = 0.0) -> None:
        if isinstance(size, bool) or not isinstance(size, int) or size < 1:
            raise out_of_range("size", size, "an integer >= 1")
        self._stamps: deque[float] = deque(maxlen=size)
        self._values: deque[float] = deque(maxlen=size)
        self._empty = empty

    def __len__(self) -> int:
        return len(self._values)

    @property
    def newest_stamp(self) -> float | None:
        """Stamp of the newest value kept; ``None`` before any."""
        return self._stamps[-1] if self._stamps else None

    def samples(self) -> tuple[list[float], list[float]]:
        """The stamps and values kept, oldest first."""
        return list(self._stamps), list(self._values)

    def add(self, stamp: float, value: float) -> bool:
        """Keep ``value`` at ``stamp``; False (not kept) when ``stamp`` is older than the latest
        kept one."""
        if self._stamps and stamp < self._stamps[-1]:
            return False
        self._stamps.append(stamp)
        self._values.append(value)
        return True

    def at(self, stamp: float) -> float:
        """The value at ``stamp`` (see the class docstring)."""
        if not self._values:
            return self._empty
        index = bisect_right(self._stamps, stamp)
        return self._values[index - 1] if index else self._values[0]


class RollHistory(StampedHistory):
    """Recent rolls (rad) by stamp (:class:`StampedHistory`, 0 before any), to pair each sample
    of another stream (a tension, a marker frame) with the roll at its time."""

    def add(self, stamp: float, value: float, parameter: str = "roll") -> bool:
        """Keep the roll ``value`` (rad; :class:`InvalidRollError` naming ``parameter`` unless
        finite) at ``stamp``; False (not kept) when ``stamp`` is older than the latest."""
        return super().add(stamp, check_roll(value, parameter))
