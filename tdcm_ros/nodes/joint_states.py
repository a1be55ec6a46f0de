"""Reading one joint out of a ``sensor_msgs/msg/JointState`` (the roll joint, issue 18)."""

from __future__ import annotations

from typing import Any


def joint_position(message: Any, joint: str) -> float | None:
    """Position of ``joint`` in ``message`` (rad for a revolute joint such as the roll), or
    None when the message does not name the joint or carries no position for it (JointState
    may leave ``position`` empty). Not validated: the caller checks finiteness."""
    names = list(message.name)
    if joint not in names:
        return None
    index = names.index(joint)
    positions = message.position
    return float(positions[index]) if index < len(positions) else None

