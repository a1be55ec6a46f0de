"""The static ``mocap`` -> ``tdcm_base`` transform: given, or estimated from recordings.

The transform is a :class:`tdcm_ros.mocap.registration.Registration`: the pose of
``tdcm_base`` in ``mocap`` (``p_mocap = R p_base + t``), published by ``mocap_node`` on
``/tf_static`` with parent ``mocap`` and child ``tdcm_base``.

- **given**: translation (m) and a quaternion ``(x, y, z, w)`` or roll-pitch-yaw (rad, fixed
  axes x, y, z as ROS ``setRPY``);
- **estimated**: from a zero-tension Nexus CSV recording (mean marker positions fix the body
  axis and origin) plus a bent recording (its most deflected frame fixes the bending plane) or
  an ``x_hint``; see :func:`tdcm_ros.mocap.registration.estimate_registration`.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.mocap.errors import LabelError
from tdcm_ros.mocap.labelling import NameMap
from tdcm_ros.mocap.nexus_csv import Trajectories, read_nexus_csv
from tdcm_ros.mocap.occlusion import visible
from tdcm_ros.mocap.registration import (
    Registration,
    RegistrationError,
    estimate_registration,
)

Array = NDArray[np.float64]


def given_registration(translation: Sequence[float], *, quaternion: Sequence[float] | None = None,
                       rpy: Sequence[float] | None = None) -> Registration:
    """From a translation (3,) m and exactly one of ``quaternion`` (x, y, z, w) or ``rpy`` (rad)."""
    if (quaternion is None) == (rpy is None):
        raise RegistrationError("give exactly one of quaternion or rpy", parameter="registration",
                                value=None, allowed="quaternion or rpy")
    if quaternion is not None and (len(quaternion) != 4 or not np.all(np.isfinite(quaternion))
                                   or np.linalg.norm(quaternion) < 1e-9):
        raise out_of_range("registration.quaternion", list(quaternion),
                           "4 finite numbers (x, y, z, w), not all zero", error=RegistrationError)
    if rpy is not None:
        angles = np.asarray(rpy, dtype=float)
        if angles.shape != (3,) or not np.all(np.isfinite(angles)):
            raise out_of_range("registration.rpy", list(rpy), "3 finite angles", unit="rad",
                               error=RegistrationError)
        # scipy on use only: the mocap face imports this module
        from scipy.spatial.transform import Rotation

        quaternion = tuple(Rotation.from_euler("xyz", angles).as_quat())
    assert quaternion is not None  # given, or made from rpy: exactly one of them is (above)
    return Registration(tuple(translation), tuple(quaternion))


def labelled_positions(trajectories: Trajectories, name_map: NameMap) -> Array:
    """(n, L, 3) m positions per label of ``name_map`` (label order); NaN where not visible.

    Raises :class:`LabelError` when a label is not found exactly once among the file's markers.
    """
    name_map.require(trajectories.names, trajectories.path)
    columns = [next(i for i, name in enumerate(trajectories.names)
                    if name_map.label_of(name) == label) for label in name_map.labels]
    positions = trajectories.positions[:, columns, :].copy()
    hidden = ~visible(positions.reshape(-1, 3)).reshape(positions.shape[:2])
    positions[hidden] = np.nan
    return positions


def _mean_visible(positions: Array) -> Array:
    count = np.sum(np.all(np.isfinite(positions), axis=2), axis=0)
    total = np.nansum(positions, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count[:, None] > 0, total / np.maximum(count, 1)[:, None], np.nan)


def estimate_from_recordings(zero_csv: str | Path, name_map: NameMap, arc_lengths: Sequence[float],
                             *, radius: float, side_rad: float, bent_csv: str | Path | None = None,
                             x_hint: Sequence[float] | None = None) -> Registration:
    """Estimate the registration from Nexus CSV recordings (m, rad).

    ``zero_csv``: the body at zero tension; each label's mean visible position is used.
    ``bent_csv``: the body bent; its frame with the largest mean marker displacement from the
    zero-tension means is used. ``radius``/``side_rad``: marker centres off the midline.
    """
    if len(arc_lengths) != len(name_map.labels):
        raise LabelError(f"labelling.arc_lengths has {len(arc_lengths)} values for "
                         f"{len(name_map.labels)} labels", parameter="labelling.arc_lengths",
                         value=list(arc_lengths), allowed="one arc length per label")
    zero = _mean_visible(labelled_positions(read_nexus_csv(zero_csv), name_map))
    bent = None
    if bent_csv is not None:
        frames = labelled_positions(read_nexus_csv(bent_csv), name_map)
        distance = np.linalg.norm(frames - zero[None], axis=2)
        seen = np.isfinite(distance)
        count = seen.sum(axis=1)
        if not np.any(count):
            raise RegistrationError(f"{bent_csv}: no frame shows a marker also seen at zero "
                                    "tension", parameter="registration.bent_csv",
                                    value=str(bent_csv), allowed="a recording with the markers")
        shift = np.where(count > 0, np.where(seen, distance, 0.0).sum(axis=1)
                         / np.maximum(count, 1), -1.0)
        bent = frames[int(np.argmax(shift))]
    return estimate_registration(zero, list(arc_lengths), radius=radius, side_rad=side_rad,
                                 bent_markers=bent, x_hint=x_hint)
