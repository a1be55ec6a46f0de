"""``sensor_msgs/msg/JointState`` of the bench's one joint, ``roll`` (rad), as the device nodes
publish it (``tension_driver``: ``joint_states``; ``device_twin``: ``sim/joint_states_true``)."""

from __future__ import annotations

from typing import Any

from tdcm_ros.bagio import from_dict
from tdcm_ros.nodes.shape_messages import header

JOINT_STATE = "sensor_msgs/msg/JointState"
ROLL_JOINT = "roll"  #: joint name of the roll servo (rotation about the base +z axis)


def joint_state(stamp_ns: int, position: float, velocity: float | None = None) -> Any:
    """The roll joint at ``position`` rad (``velocity`` rad/s, or empty if unknown), stamped
    ``stamp_ns`` (ns since the epoch), no frame."""
    return from_dict(JOINT_STATE, {"header": header(stamp_ns, ""), "name": [ROLL_JOINT],
                                   "position": [position],
                                   "velocity": [] if velocity is None else [velocity],
                                   "effort": []})
