"""``tf2_msgs/msg/TFMessage`` builders (CDR bytes, :class:`~tdcm_ros.bagio.CdrWriter`) for the
model node's TF tree.

The tree under ``base`` (``tdcm_base`` by default, REP 103, SI units; see doc/explanation/frames.md):

- ``base -> tendon`` (static): where the tendon leaves the base, ``R_c`` (m) from the midline on
  +x, its z axis along the tendon toward the actuator (``-z`` of the base), x kept: a rotation by
  pi about x. ``tension`` (``wrench.force.z``) is stamped in this frame.
- ``base -> tip`` (dynamic): the midline's tip pose of the latest solve, z along the tangent,
  turned by the roll about the base +z axis (:mod:`tdcm_ros.model.roll`).
- ``base -> <station_prefix><k>`` (dynamic, optional): midline poses at ``s = k L / n``,
  ``k = 1 .. n``, rolled alike.

The tendon frame stays where it is at roll 0: it is static, and the tension's direction in it
(along the base's -z) does not change with the roll; only its origin would turn with the body.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import CdrWriter, cdr_header, cdr_string
from tdcm_ros.model import Design, SolveResult, roll_poses

Array = NDArray[np.float64]
TF_TYPE = "tf2_msgs/msg/TFMessage"
#: Rotation of the tendon frame in the base frame, (x, y, z, w): pi about x.
TENDON_ROTATION = (1.0, 0.0, 0.0, 0.0)


def _transforms(stamp_ns: int, parent: str, children: list[str], positions: Array,
                quaternions: Array) -> bytes:
    """CDR of a ``TFMessage`` of ``parent -> children[i]`` at positions (k, 3) m and
    quaternions (k, 4) ``(x, y, z, w)``, all stamped ``stamp_ns`` (ns since the epoch)."""
    hdr = cdr_header(stamp_ns, parent)
    hdr += bytes((-len(hdr)) % 4)  # child_frame_id is a string: 4-aligned
    writer = CdrWriter()
    writer.uint32(len(children))
    # TransformStamped: header, child_frame_id, then translation and rotation as in a Pose
    writer.records([hdr + cdr_string(child) for child in children],
                   np.hstack([positions, quaternions]))
    return writer.data()


def tendon_tf(design: Design, *, stamp_ns: int, parent: str, child: str) -> bytes:
    """The static ``parent -> child`` transform of the tendon frame (see the module docstring)."""
    return _transforms(stamp_ns, parent, [child], np.array([[design.R_c, 0.0, 0.0]]),
                       np.array([TENDON_ROTATION]))


def station_lengths(length: float, stations: int) -> Array:
    """Arc lengths (m) ``k L / n`` of ``n = stations`` frames along a body of ``length`` m."""
    return np.linspace(length / max(stations, 1), length, stations)  # last one exactly L


def body_tf(result: SolveResult, *, stamp_ns: int, parent: str, tip: str,
            station_prefix: str, stations: int, roll: float = 0.0) -> bytes:
    """``parent -> tip`` and, for ``stations > 0``, ``parent -> <station_prefix><k>``, the
    shape rolled by ``roll`` (rad) about the base +z axis."""
    children = [tip]
    positions, quaternions = result.tip_position[None, :], result.tip_quaternion[None, :]
    if stations > 0:
        at, turn = result.pose_at(station_lengths(result.design.length, stations))
        children += [f"{station_prefix}{k}" for k in range(1, stations + 1)]
        positions, quaternions = np.vstack([positions, at]), np.vstack([quaternions, turn])
    return _transforms(stamp_ns, parent, children, *roll_poses(positions, quaternions, roll))
