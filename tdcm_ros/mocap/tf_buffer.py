"""A buffer of TF edges and lookups between two frames at a stamp, as tf2's ``BufferCore``
reads ``/tf`` and ``/tf_static``, without ROS.

A frame has at most one parent. A **static** edge (``/tf_static``) holds at every time; a
**dynamic** edge (``/tf``) is a time series of samples kept for ``cache_s`` behind its newest
one and read between two samples by linear interpolation of the translation and spherical
interpolation of the rotation (tf2's rule; between samples with different parents the earlier
sample holds). A stamp outside a dynamic edge's samples is an extrapolation and raises
:class:`TransformLookupError`, as do an unknown frame, two frames in unconnected trees and a
loop. The last edge given into a frame decides whether it is static or dynamic.

A pose is a :class:`~tdcm_ros.mocap.Registration`: the pose of the source frame in the target
frame, ``p_target = R p_source + t`` (m).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.mocap.errors import MocapError
from tdcm_ros.mocap.registration import Registration, RegistrationError

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

Array = NDArray[np.float64]

MAX_DEPTH = 1000
"""Most edges walked from a frame toward its root before the walk counts as a loop (tf2's)."""


class TransformLookupError(MocapError, InputError):
    """Two frames cannot be related at a stamp: unknown frame, no common root, extrapolation."""


class ExtrapolationError(TransformLookupError):
    """A stamp outside a dynamic edge's samples; ``future``: after the newest one (the edge
    may still arrive), else before the oldest kept."""

    def __init__(self, message: str, *, future: bool, value: float, allowed: str) -> None:
        super().__init__(message, parameter="stamp_s", value=value, allowed=allowed)
        self.future = future


@dataclass(frozen=True)
class _Edge:
    """One edge sample: the child's pose in ``parent``."""

    parent: str
    rotation: Rotation
    translation: Array


@dataclass(frozen=True)
class _Pose:
    """A frame's pose in another: ``p_other = rotation p + translation`` (m)."""

    rotation: Rotation
    translation: Array

    @classmethod
    def identity(cls) -> _Pose:
        # scipy on use only: the mocap face imports this module
        from scipy.spatial.transform import Rotation

        return cls(Rotation.identity(), np.zeros(3))


@dataclass
class _Series:
    """A dynamic edge's samples, in stamp order (s)."""

    stamps: list[float] = field(default_factory=list)
    edges: list[_Edge] = field(default_factory=list)


def _frame(name: str, role: str) -> str:
    text = str(name).lstrip("/")
    if not text:
        raise out_of_range(role, name, "a frame name (not empty, a leading '/' is dropped)",
                           error=TransformLookupError)
    return text


class TransformBuffer:
    """Static and dynamic TF edges, and :meth:`lookup` between two frames at a stamp."""

    def __init__(self, cache_s: float = 10.0) -> None:
        if not (math.isfinite(cache_s) and cache_s > 0.0):
            raise out_of_range("cache_s", cache_s, "(0, inf) s", error=TransformLookupError)
        self.cache_s = float(cache_s)
        self._static: dict[str, _Edge] = {}
        self._dynamic: dict[str, _Series] = {}

    def set_transform(self, parent: str, child: str, stamp_s: float,
                      translation: Sequence[float], quaternion: Sequence[float], *,
                      static: bool) -> None:
        """Add the edge ``parent -> child``: the child's pose in ``parent`` at ``stamp_s`` (s),
        ``translation`` (m), ``quaternion`` (x, y, z, w; normalised). A bad edge raises an
        error naming it; a dynamic sample older than the cache, or at a stamp already held,
        replaces nothing and is dropped."""
        parent, child = _frame(parent, "parent frame"), _frame(child, "child frame")
        edge_name = f"TF edge {parent!r} -> {child!r}"
        if parent == child:
            raise out_of_range(edge_name, parent, "a child frame other than its parent",
                               error=TransformLookupError)
        if not math.isfinite(stamp_s):
            raise out_of_range(f"{edge_name} stamp", stamp_s, "a finite time", unit="s",
                               error=TransformLookupError)
        try:
            pose = Registration(tuple(translation), tuple(quaternion))
        except RegistrationError as error:
            raise TransformLookupError(f"{edge_name}: {error}", parameter=edge_name,
                                       value=error.value, allowed=error.allowed) from error
        # scipy on use only: the mocap face imports this module
        from scipy.spatial.transform import Rotation

        edge = _Edge(parent, Rotation.from_quat(pose.quaternion), np.asarray(pose.translation))
        if static:
            self._dynamic.pop(child, None)
            self._static[child] = edge
            return
        self._static.pop(child, None)
        series = self._dynamic.setdefault(child, _Series())
        if series.stamps and stamp_s < series.stamps[-1] - self.cache_s:
            return
        i = bisect.bisect_left(series.stamps, stamp_s)
        if i < len(series.stamps) and series.stamps[i] == stamp_s:
            return
        series.stamps.insert(i, float(stamp_s))
        series.edges.insert(i, edge)
        old = bisect.bisect_left(series.stamps, series.stamps[-1] - self.cache_s)
        del series.stamps[:old], series.edges[:old]

    def add_message(self, message: Any, *, static: bool) -> list[str]:
        """Take every transform of a ``tf2_msgs/msg/TFMessage`` (``static``: from
        ``/tf_static``); returns why any was skipped, one line each."""
        problems = []
        for tf in message.transforms:
            t, q, stamp = tf.transform.translation, tf.transform.rotation, tf.header.stamp
            try:
                self.set_transform(tf.header.frame_id, tf.child_frame_id,
                                   int(stamp.sec) + int(stamp.nanosec) * 1e-9, (t.x, t.y, t.z),
                                   (q.x, q.y, q.z, q.w), static=static)
            except TransformLookupError as error:
                problems.append(str(error))
        return problems

    def frames(self) -> list[str]:
        """Every frame named by an edge (children and parents), sorted."""
        names = set(self._static) | set(self._dynamic)
        names |= {e.parent for e in self._static.values()}
        names |= {e.parent for s in self._dynamic.values() for e in s.edges}
        return sorted(names)

    def _edge(self, child: str, stamp_s: float | None) -> _Edge | None:
        """The edge into ``child`` at ``stamp_s`` (s; ``None``: its newest sample); ``None`` at
        a root."""
        if child in self._static:
            return self._static[child]
        series = self._dynamic.get(child)
        if series is None:
            return None
        if stamp_s is None:
            return series.edges[-1]
        stamps = series.stamps
        i = bisect.bisect_left(stamps, stamp_s)
        if i < len(stamps) and stamps[i] == stamp_s:
            return series.edges[i]
        if i == 0 or i == len(stamps):
            side = "before the first" if i == 0 else "after the last"
            raise ExtrapolationError(
                f"TF edge {series.edges[0].parent!r} -> {child!r}: stamp {stamp_s:.9f} s is "
                f"{side} sample (samples from {stamps[0]:.9f} to {stamps[-1]:.9f} s); a "
                "dynamic edge is not extrapolated", future=i > 0, value=stamp_s,
                allowed=f"[{stamps[0]:.9f}, {stamps[-1]:.9f}] s")
        before, after = series.edges[i - 1], series.edges[i]
        if before.parent != after.parent:
            return before
        f = (stamp_s - stamps[i - 1]) / (stamps[i] - stamps[i - 1])
        turn = (before.rotation.inv() * after.rotation).as_rotvec()
        # scipy on use only: the mocap face imports this module
        from scipy.spatial.transform import Rotation

        return _Edge(before.parent, before.rotation * Rotation.from_rotvec(f * turn),
                     before.translation + f * (after.translation - before.translation))

    def _require_known(self, frame: str) -> None:
        names = self.frames()
        if frame not in names:
            shown = ", ".join(names[:12]) or "none"
            raise TransformLookupError(
                f"frame {frame!r} is in no TF edge (frames known: {shown})",
                parameter="frame", value=frame, allowed="a frame of /tf or /tf_static")

    def _walk(self, frame: str, stamp_s: float | None, stop: dict[str, _Pose] | None
              ) -> tuple[dict[str, _Pose], TransformLookupError | None]:
        """The pose of ``frame`` in itself and in each ancestor at ``stamp_s``, walking up until
        the root or a frame in ``stop``; an edge that cannot be read ends the walk, and its
        error is returned with the poses found below it."""
        poses = {frame: _Pose.identity()}
        name, pose = frame, poses[frame]
        while stop is None or name not in stop:
            try:
                edge = self._edge(name, stamp_s)
            except TransformLookupError as error:
                return poses, error
            if edge is None:
                break
            pose = _Pose(edge.rotation * pose.rotation,
                         edge.translation + edge.rotation.apply(pose.translation))
            name = edge.parent
            if name in poses or len(poses) > MAX_DEPTH:
                raise TransformLookupError(
                    f"TF frames above {frame!r} form a loop (at {name!r})",
                    parameter="frame", value=frame, allowed="a tree")
            poses[name] = pose
        return poses, None

    def lookup(self, target: str, source: str, stamp_s: float | None) -> Registration:
        """The pose of ``source`` in ``target`` at ``stamp_s`` (s; ``None``: each dynamic
        edge's newest sample): ``to_base`` of it maps points in ``target`` into ``source``
        (``method`` ``tf``). Only the edges up to the frames' nearest common ancestor are read. Raises :class:`TransformLookupError` when the two cannot be
        related at that stamp."""
        target, source = _frame(target, "target frame"), _frame(source, "source frame")
        if target == source:
            return Registration.identity("tf")
        of_source, source_error = self._walk(source, stamp_s, {target: _Pose.identity()})
        of_target, target_error = self._walk(target, stamp_s, of_source)
        common = next((name for name in of_target if name in of_source), None)
        if common is None:  # the frames are checked here, off the path of a found pose
            self._require_known(target)
            self._require_known(source)
            error = source_error or target_error
            if error is not None:
                raise error
            raise TransformLookupError(
                f"frames {target!r} and {source!r} are in two unconnected TF trees (roots "
                f"{list(of_source)[-1]!r} and {list(of_target)[-1]!r})", parameter="frames",
                value=(target, source), allowed="frames joined by /tf or /tf_static edges")
        s, t = of_source[common], of_target[common]
        inverse = t.rotation.inv()
        return Registration(tuple(inverse.apply(s.translation - t.translation).tolist()),
                            tuple((inverse * s.rotation).as_quat().tolist()), method="tf")

    def is_static(self, target: str, source: str) -> bool:
        """Whether every edge between ``target`` and ``source`` (up to their nearest common
        ancestor, by each dynamic edge's newest parent) is static: the pose holds at every
        time. False when they are not related."""
        up_source, up_target = self._ancestors(source), self._ancestors(target)
        common = next((name for name in up_target if name in up_source), None)
        if common is None:
            return False
        return all(up_source[n] for n in list(up_source)[:list(up_source).index(common)]) and \
            all(up_target[n] for n in list(up_target)[:list(up_target).index(common)])

    def _ancestors(self, frame: str) -> dict[str, bool]:
        """``frame`` and its ancestors (by each dynamic edge's newest parent), each mapped to
        whether the edge into it is static (a root: True)."""
        frame = frame.lstrip("/")
        found: dict[str, bool] = {}
        while frame not in found and len(found) <= MAX_DEPTH:
            if frame in self._static:
                found[frame], frame = True, self._static[frame].parent
            elif frame in self._dynamic:
                found[frame], frame = False, self._dynamic[frame].edges[-1].parent
            else:
                found[frame] = True
                break
        return found
