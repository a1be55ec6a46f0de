"""Write a simulated :class:`~tdcm_ros.metrics.synthetic.Recording` as a rosbag2 MCAP bag with the
contract topics: ``/tension`` (WrenchStamped, force.z; for several tendons a JointState with an
effort per tendon, by name, or a WrenchStamped topic per tendon), ``/markers``
(mocap4r2_msgs/Markers in ``mocap``, occluded markers omitted), optionally ``/tf_static``
(``mocap`` -> ``tdcm_base``) and, for a recording with a roll, ``/joint_states`` (JointState:
the position of joint ``roll``, rad).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from tdcm_ros.bagio import joint_state_cdr, msg_class, serialize
from tdcm_ros.bagio.writer import BagWriter, OfferedQos
from tdcm_ros.metrics.synthetic import Recording

EPOCH_NS = 1_700_000_000 * 1_000_000_000
"""Stamp (ns) of ``t = 0`` of a recording."""
WRENCH, JOINT_STATE = "geometry_msgs/msg/WrenchStamped", "sensor_msgs/msg/JointState"


def _header(stamp_ns: int, frame_id: str) -> object:
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return msg_class("std_msgs/msg/Header")(
        stamp=msg_class("builtin_interfaces/msg/Time")(sec=sec, nanosec=nanosec),
        frame_id=frame_id)


def _wrenches(stamps_s: np.ndarray, tension_n: np.ndarray, topic: str
              ) -> list[tuple[int, str, bytes]]:
    """WrenchStamped messages (log time ns, topic, CDR) of tensions (N) at stamps (s)."""
    vector = msg_class("geometry_msgs/msg/Vector3")
    wrench, stamped = msg_class("geometry_msgs/msg/Wrench"), msg_class(WRENCH)
    zero = vector(x=0.0, y=0.0, z=0.0)
    messages = []
    for t, value in zip(stamps_s.tolist(), tension_n.tolist(), strict=True):
        ns = EPOCH_NS + round(t * 1e9)
        msg = stamped(header=_header(ns, "tdcm_tendon"),
                      wrench=wrench(force=vector(x=0.0, y=0.0, z=value), torque=zero))
        messages.append((ns, topic, serialize(msg)))
    return messages


def _joint_states(stamps_s: np.ndarray, tensions_n: np.ndarray, names: tuple[str, ...],
                  topic: str) -> list[tuple[int, str, bytes]]:
    """JointState messages (log time ns, topic, CDR): an effort (N) per tendon ``names``."""
    messages = []
    for t, row in zip(stamps_s.tolist(), tensions_n, strict=True):
        ns = EPOCH_NS + round(t * 1e9)
        messages.append((ns, topic, joint_state_cdr(ns, names, (), (), row)))
    return messages


def _rolls(recording: Recording, topic: str, joint: str) -> list[tuple[int, str, bytes]]:
    """JointState messages (log time ns, topic, CDR): the roll (rad) as ``joint``'s position;
    none for a recording without a roll."""
    if recording.roll is None:
        return []
    messages = []
    for t, phi in zip(recording.roll.stamps_s.tolist(), recording.roll.roll_rad.tolist(),
                      strict=True):
        ns = EPOCH_NS + round(t * 1e9)
        messages.append((ns, topic, joint_state_cdr(ns, (joint,), (phi,), (), ())))
    return messages


def write_recording(recording: Recording, path: str | Path, *, tf_static: bool = True,
                    tension_topic: str = "tension", markers_topic: str = "markers",
                    tendon_topics: Mapping[str, str] | None = None,
                    joint_states_topic: str = "joint_states", roll_joint: str = "roll") -> Path:
    """Write ``recording`` to the new bag folder ``path``; returns ``path``. A recording of
    several tendons goes to ``tension_topic`` as one JointState, or with ``tendon_topics``
    (tendon name -> topic) to a WrenchStamped topic per tendon; its roll, if any, to
    ``joint_states_topic`` as the position of ``roll_joint``."""
    marker, markers = msg_class("mocap4r2_msgs/msg/Marker"), msg_class("mocap4r2_msgs/msg/Markers")
    point = msg_class("geometry_msgs/msg/Point")
    tension = recording.tension
    if tendon_topics is not None:
        columns = dict(zip(tension.names, tension.tension_n.T, strict=True))
        kind, series = WRENCH, {topic: _wrenches(tension.stamps_s, columns[name], topic)
                                for name, topic in tendon_topics.items()}
    elif tension.names:
        kind, series = JOINT_STATE, {tension_topic: _joint_states(
            tension.stamps_s, tension.tension_n, tension.names, tension_topic)}
    else:
        kind, series = WRENCH, {tension_topic: _wrenches(tension.stamps_s, tension.tension_n,
                                                         tension_topic)}
    with BagWriter(path) as bag:
        for topic in series:
            bag.add_topic(topic, kind)
        bag.add_topic(markers_topic, "mocap4r2_msgs/msg/Markers")
        messages: list[tuple[int, str, bytes]] = []
        if tf_static:
            bag.add_topic("/tf_static", "tf2_msgs/msg/TFMessage",
                          OfferedQos(depth=1, durability="transient_local"))
            messages.append((EPOCH_NS, "/tf_static", serialize(_tf(recording))))
        for part in series.values():
            messages.extend(part)
        if rolls := _rolls(recording, joint_states_topic, roll_joint):
            bag.add_topic(joint_states_topic, JOINT_STATE)
            messages.extend(rolls)
        frames = recording.markers
        labels = frames.labels
        for n, (t, rows) in enumerate(zip(frames.stamps_s.tolist(), frames.positions,
                                          strict=True)):
            ns = EPOCH_NS + round(t * 1e9)
            items = [marker(id_type=0, marker_index=i, marker_name=labels[i],
                            translation=point(x=row[0], y=row[1], z=row[2]))
                     for i, row in enumerate(rows.tolist()) if not np.isnan(row[0])]
            msg = markers(header=_header(ns, frames.frame_id), frame_number=n, markers=items)
            messages.append((ns, markers_topic, serialize(msg)))
        messages.sort(key=lambda m: m[0])
        for ns, topic, data in messages:
            bag.write(topic, ns, data)
    return Path(path)


def _tf(recording: Recording) -> object:
    reg = recording.registration
    tx, ty, tz = reg.translation
    qx, qy, qz, qw = reg.quaternion
    transform = msg_class("geometry_msgs/msg/TransformStamped")(
        header=_header(EPOCH_NS, "mocap"), child_frame_id="tdcm_base",
        transform=msg_class("geometry_msgs/msg/Transform")(
            translation=msg_class("geometry_msgs/msg/Vector3")(x=tx, y=ty, z=tz),
            rotation=msg_class("geometry_msgs/msg/Quaternion")(x=qx, y=qy, z=qz, w=qw)))
    return msg_class("tf2_msgs/msg/TFMessage")(transforms=[transform])
