"""A small TF buffer: the latest transform of each ``parent -> child`` edge (from ``/tf`` and
``/tf_static``), looked up between any two connected frames.

No time interpolation: a lookup uses the newest transform of each edge (the controller resolves
a target once, when it arrives). A frame name's leading ``/`` is ignored. The result is a
:class:`~tdcm_ros.mocap.Registration` (the pose of the target frame in the source frame), so
``lookup(target, source).to_base(points_in_source)`` gives the points in ``target``: the same
transform the metrics use for ``mocap -> tdcm_base``.
"""

from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from tdcm_ros.control.errors import TargetRefusedError
from tdcm_ros.errors import InputError
from tdcm_ros.mocap import Registration

Array = NDArray[np.float64]


def _frame(name: str) -> str:
    return name.lstrip("/")


class TransformBuffer:
    """Edges ``parent -> child`` as 4x4 poses of the child in the parent (m)."""

    def __init__(self) -> None:
        self._poses: dict[tuple[str, str], Array] = {}

    def add_message(self, message: Any) -> list[str]:
        """Take every transform of a ``tf2_msgs/msg/TFMessage``; returns why any was skipped."""
        problems = []
        for tf in message.transforms:
            t, q = tf.transform.translation, tf.transform.rotation
            try:
                self.add(tf.header.frame_id, tf.child_frame_id, (t.x, t.y, t.z),
                         (q.x, q.y, q.z, q.w))
            except InputError as error:
                problems.append(f"{tf.header.frame_id} -> {tf.child_frame_id}: {error}")
        return problems

    def add(self, parent: str, child: str, translation: tuple[float, float, float],
            quaternion: tuple[float, float, float, float]) -> None:
        """Set the pose of ``child`` in ``parent``: translation (m), quaternion (x, y, z, w)."""
        pose = Registration(translation, quaternion)  # checks finite, normalises
        matrix = np.eye(4)
        matrix[:3, :3], matrix[:3, 3] = pose.rotation, pose.translation
        self._poses[(_frame(parent), _frame(child))] = matrix

    def frames(self) -> set[str]:
        """Every frame named by an edge."""
        return {name for edge in self._poses for name in edge}

    def lookup(self, target: str, source: str) -> Registration:
        """The pose of ``target`` in ``source``; :class:`TargetRefusedError` if they are not
        connected."""
        target, source = _frame(target), _frame(source)
        matrix = self._chain(source, target)
        if matrix is None:
            known = ", ".join(sorted(self.frames())) or "none yet"
            raise TargetRefusedError(
                f"frame {source!r} has no transform to {target!r}; known frames: {known}",
                parameter="frame_id", value=source, allowed=known)
        quaternion = Rotation.from_matrix(matrix[:3, :3]).as_quat()
        return Registration(tuple(matrix[:3, 3]), tuple(quaternion), method="tf")

    def _chain(self, source: str, target: str) -> Array | None:
        """Pose of ``target`` in ``source`` along the tree, breadth first."""
        if source == target:
            return np.eye(4)
        steps: dict[str, list[tuple[str, Array]]] = {}
        for (parent, child), pose in self._poses.items():
            steps.setdefault(parent, []).append((child, pose))
            steps.setdefault(child, []).append((parent, np.linalg.inv(pose).astype(np.float64)))
        seen, queue = {source}, deque([(source, np.eye(4))])
        while queue:
            frame, pose = queue.popleft()
            for neighbour, step in steps.get(frame, []):
                if neighbour in seen:
                    continue
                if neighbour == target:
                    return pose @ step
                seen.add(neighbour)
                queue.append((neighbour, pose @ step))
        return None
