"""``sensor_msgs/msg/JointState`` of the bench's joints: the roll (rad), as the device nodes
publish it (``tension_driver``: ``joint_states``; ``device_twin``: ``sim/joint_states_true``), and
the tendons as prismatic joints, as model_node predicts them (``tendon_states``), and the
tendons' tensions as efforts, as model_node and metrics_node take them
(:func:`tendon_efforts`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from tdcm_ros.bagio import from_dict, joint_state_cdr
from tdcm_ros.nodes.shape_messages import header

JOINT_STATE = "sensor_msgs/msg/JointState"
ROLL_JOINT = "roll"  #: joint name of the roll servo (rotation about the base +z axis)
#: joint name of the driven tendon on the tension driver's ``joint_states`` and ``joint_commands``
#: (effort = tension, N), as ros2_control's topic-based hardware interfaces name joints
TENDON_JOINT = "tendon"


def joint_state(stamp_ns: int, position: float, velocity: float | None = None) -> Any:
    """The roll joint at ``position`` rad (``velocity`` rad/s, or empty if unknown), stamped
    ``stamp_ns`` (ns since the epoch), no frame."""
    return from_dict(JOINT_STATE, {"header": header(stamp_ns, ""), "name": [ROLL_JOINT],
                                   "position": [position],
                                   "velocity": [] if velocity is None else [velocity],
                                   "effort": []})


def tendon_effort(stamp_ns: int, tension_n: float) -> Any:
    """The driven tendon as a joint whose effort is its measured tension (N), stamped
    ``stamp_ns``, no frame, no position (the driver measures no stroke)."""
    return from_dict(JOINT_STATE, {"header": header(stamp_ns, ""), "name": [TENDON_JOINT],
                                   "position": [], "velocity": [], "effort": [tension_n]})


def commanded(message: Any) -> dict[str, tuple[float | None, float | None]]:
    """``{joint: (position or None, effort or None)}`` of a JointState command, by index in
    ``name``: a missing entry (a shorter array) or NaN is ``None``, no command (ros2_control
    leaves what it does not command empty or NaN); an infinity stays, to be refused."""
    def field(values: Any, i: int) -> float | None:
        array = np.asarray(values, dtype=float)
        return None if i >= array.size or math.isnan(array[i]) else float(array[i])
    return {str(name): (field(message.position, i), field(message.effort, i))
            for i, name in enumerate(message.name)}


def body_joint_states(stamp_ns: int, names: Sequence[str], positions: Sequence[float]
                      ) -> bytes:
    """CDR of the body's URDF joints (:func:`~tdcm_ros.model.urdf.joint_names`, the roll left
    to the driver) at ``positions`` (rad, m), stamped ``stamp_ns``, no frame."""
    return joint_state_cdr(stamp_ns, names, positions, (), ())


def tendon_states(stamp_ns: int, names: Sequence[str], strokes_m: Sequence[float],
                  tensions_n: Sequence[float]) -> bytes:
    """CDR of each tendon as a prismatic joint named as in the body (``tendon_<k>`` by
    default): position its actuator's stroke (m, pulled in against the straight body), effort
    its tension (N), stamped ``stamp_ns``, no frame. Written directly: model_node sends one per
    input (through rosbags' objects it cost ~100 µs)."""
    return joint_state_cdr(stamp_ns, names, strokes_m, (), tensions_n)


def tendon_efforts(message: Any, tendons: Sequence[str]
                   ) -> tuple[tuple[float, ...], tuple[str, ...]]:
    """Each tendon's tension (N) in the order of ``tendons`` (names) from the efforts of a
    JointState, matched by joint name (NaN where missing; not validated otherwise), and the
    tendons it has no effort for."""
    efforts = dict(zip(message.name, np.asarray(message.effort, dtype=float).tolist(),
                       strict=False))
    return (tuple(efforts.get(name, math.nan) for name in tendons),
            tuple(name for name in tendons if name not in efforts))
