"""Read the evaluation's inputs from a bag: tension, marker frames and the registration.

- tension: ``geometry_msgs/msg/WrenchStamped`` (``wrench.force.z``, N);
- markers: ``mocap4r2_msgs/msg/Markers`` (positions in the message's frame, matched to the
  layout's labels by ``marker_name``; unknown names are ignored and counted in a warning). A
  position that is NaN or exactly ``(0, 0, 0)`` is an occluded marker, as mocap_node treats it
  (:func:`tdcm_ros.mocap.occlusion.visible`): missing, counted, never a measurement;
- registration: the ``/tf_static`` transform whose child is ``tdcm_base`` and whose parent is the
  markers' frame, if the bag has one.

Stamps are the header stamps (s since the epoch); a topic whose header stamps are all zero uses
the bag's log times instead (said in a warning). Messages are left out, counted in a warning:

- duplicates: the same topic, stamp and payload bytes as an earlier message;
- implausible stamps: at or before 0 s, at or beyond 2^31 - 1 s (the int32 ``sec`` maximum), or more
  than :data:`FAR_S` from the median stamp of the topic's other messages. A topic with no
  plausible stamp at all is an error naming it, the count and a stamp.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tdcm_ros.bagio.reader import BagReader, open_bag, require_topic
from tdcm_ros.metrics.cdr import markers_frame, wrench_force_z
from tdcm_ros.metrics.errors import MetricsError
from tdcm_ros.metrics.registration import Registration
from tdcm_ros.metrics.series import MarkerSeries, TensionSeries
from tdcm_ros.mocap.occlusion import visible

TENSION_TYPE = "geometry_msgs/msg/WrenchStamped"
MARKERS_TYPE = "mocap4r2_msgs/msg/Markers"
TF_TYPE = "tf2_msgs/msg/TFMessage"
BASE_FRAME = "tdcm_base"
MAX_STAMP_S = 2.0**31 - 1.0
"""Stamps (s since the epoch) at or beyond this are implausible: the int32 ``sec`` maximum."""
FAR_S = 86_400.0
"""Stamps farther than this (s) from the median stamp of their topic are implausible."""


@dataclass(frozen=True, eq=False)
class BagSource:
    """One bag's inputs: series, the registration it carries (or None), reading warnings and
    the occluded marker positions (NaN or exactly zero) left out, per label."""

    path: Path
    tension: TensionSeries
    markers: MarkerSeries
    registration: Registration | None
    warnings: tuple[str, ...]
    occluded: dict[str, int] = field(default_factory=dict)


def _stamps_ns(header_ns: np.ndarray, log_ns: np.ndarray, topic: str, warnings: list[str]
               ) -> np.ndarray:
    """The stamps (ns since the epoch) of a topic: its header stamps, or its log times when
    the header stamps are all zero."""
    if np.all(header_ns == 0):
        warnings.append(f"{topic}: header stamps are all zero; using the bag's log times")
        return log_ns
    return header_ns


def _unique(stamps_ns: np.ndarray, payloads: Sequence[bytes], topic: str, warnings: list[str]
            ) -> np.ndarray:
    """Mask of the messages kept: each is dropped that repeats an earlier one's stamp (ns) and
    payload bytes."""
    keep = np.ones(len(payloads), dtype=bool)
    order = np.argsort(stamps_ns, kind="stable")
    equal = np.flatnonzero(np.diff(stamps_ns[order]) == 0)  # positions equal to the next
    seen: set[tuple[int, bytes]] = set()
    for n in order[np.union1d(equal, equal + 1)].tolist():  # only stamps shared, in order
        key = (int(stamps_ns[n]), payloads[n])
        keep[n] = key not in seen
        seen.add(key)
    if dropped := int((~keep).sum()):
        warnings.append(f"{topic}: {dropped} duplicated messages (same stamp and payload as an "
                        "earlier one) left out")
    return keep


def _plausible(stamps_ns: np.ndarray, path: Path, topic: str, warnings: list[str]
               ) -> np.ndarray:
    """Mask of the messages whose stamps are plausible (see the module docstring)."""
    t = stamps_ns * 1e-9
    keep = (t > 0.0) & (np.abs(t) < MAX_STAMP_S)
    if keep.any():
        keep &= np.abs(t - np.median(t[keep])) <= FAR_S
    allowed = f"(0, 2^31 - 1) s since the epoch, within {FAR_S:g} s of the topic's median stamp"
    bad = t[~keep]
    if keep.any() and bad.size:
        warnings.append(f"{topic}: {bad.size} messages with implausible stamps left out (e.g. "
                        f"{bad[0]:.9g} s; allowed: {allowed} {np.median(t[keep]):.9g} s)")
    elif not keep.any():
        raise MetricsError(f"{path}: {topic}: all {bad.size} stamps are implausible (e.g. "
                           f"{bad[0]:.9g} s); allowed: {allowed}", parameter=f"{topic} stamps",
                           value=float(bad[0]), allowed=allowed)
    return keep


def _usable(header_ns: np.ndarray, log_ns: np.ndarray, payloads: Sequence[bytes], path: Path,
            topic: str, warnings: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Stamps (s since the epoch) of a topic and the mask of its messages kept: neither
    duplicated nor implausibly stamped."""
    stamps_ns = _stamps_ns(header_ns, log_ns, topic, warnings)
    keep = _unique(stamps_ns, payloads, topic, warnings)
    keep[keep] = _plausible(stamps_ns[keep], path, topic, warnings)
    return stamps_ns * 1e-9, keep


def _payloads(reader: BagReader, name: str) -> tuple[np.ndarray, list[bytes]]:
    """Log times (ns) and CDR payloads of one topic, in log-time order."""
    log, data = [], []
    for _, log_ns, cdr in reader.raw_messages([name]):
        log.append(log_ns)
        data.append(cdr)
    return np.asarray(log, dtype=np.int64), data


def _tension(reader: BagReader, topic: str, warnings: list[str]) -> TensionSeries:
    name = require_topic(reader, topic, [TENSION_TYPE])
    log, data = _payloads(reader, name)
    header_ns, force_z = wrench_force_z(data)
    stamps, keep = _usable(header_ns, log, data, reader.path, name, warnings)
    return TensionSeries.of(stamps[keep], force_z[keep])


def _occlude(rows: np.ndarray, reported: np.ndarray, labels: Sequence[str], topic: str,
             warnings: list[str]) -> dict[str, int]:
    """Set the occluded positions of ``rows`` (n, k, 3) m, those reported (``reported``
    (n, k)) as NaN or exactly (0, 0, 0), to NaN; their count per label."""
    hidden = reported & ~visible(rows.reshape(-1, 3)).reshape(reported.shape)
    rows[hidden] = np.nan
    counts = {label: int(c) for label, c in zip(labels, hidden.sum(axis=0), strict=True)}
    if any(counts.values()):
        warnings.append(f"{topic}: {sum(counts.values())} occluded marker positions (NaN or "
                        "exactly (0, 0, 0), as mocap_node drops them) left out: "
                        f"{', '.join(f'{k} {v}' for k, v in counts.items())}")
    return counts


def _markers(reader: BagReader, topic: str, labels: Sequence[str], warnings: list[str]
             ) -> tuple[MarkerSeries, dict[str, int]]:
    """Marker frames of ``topic`` and the occluded positions per label."""
    name = require_topic(reader, topic, [MARKERS_TYPE])
    index = {label: i for i, label in enumerate(labels)}
    log, payloads = _payloads(reader, name)
    header = np.zeros(len(payloads), dtype=np.int64)
    rows = np.full((len(payloads), len(labels), 3), np.nan)
    reported = np.zeros(rows.shape[:2], dtype=bool)
    frames: set[str] = set()
    unknown: set[str] = set()
    for n, data in enumerate(payloads):
        header[n], frame, names, xyz = markers_frame(data)
        frames.add(frame)
        for marker_name, p in zip(names, xyz, strict=True):
            i = index.get(marker_name)
            if i is None:
                unknown.add(marker_name or "(unnamed)")
            else:
                rows[n, i], reported[n, i] = p, True
    if unknown:
        warnings.append(f"{name}: ignored markers not in the layout ({', '.join(labels)}): "
                        f"{', '.join(sorted(unknown))}")
    if len(frames) > 1:
        raise MetricsError(f"{reader.path}: {name} mixes frames {', '.join(sorted(frames))}; "
                           "allowed: one frame", parameter="markers_topic", value=sorted(frames),
                           allowed="one frame_id")
    frame = frames.pop() if frames else "mocap"
    stamps, keep = _usable(header, log, payloads, reader.path, name, warnings)
    rows = rows[keep]
    occluded = _occlude(rows, reported[keep], labels, name, warnings)
    return MarkerSeries.of(stamps[keep], labels, rows, frame_id=frame), occluded


def _registration(reader: BagReader, parent: str, warnings: list[str]) -> Registration | None:
    names = [t for t in reader.topics if t.lstrip("/") == "tf_static"
             and reader.topics[t] == TF_TYPE]
    found: Registration | None = None
    for _, _, msg in reader.messages(names) if names else ():
        for tf in msg.transforms:
            if tf.child_frame_id.lstrip("/") != BASE_FRAME:
                continue
            if tf.header.frame_id.lstrip("/") != parent.lstrip("/"):
                warnings.append(f"/tf_static: {tf.header.frame_id} -> {BASE_FRAME} ignored; the "
                                f"markers are in {parent}")
                continue
            t, q = tf.transform.translation, tf.transform.rotation
            found = Registration((t.x, t.y, t.z), (q.x, q.y, q.z, q.w), method="tf_static")
    return found


def load_bag(path: str | Path, *, labels: Sequence[str], tension_topic: str = "tension",
             markers_topic: str = "markers") -> BagSource:
    """Read one bag (rosbag2 folder or ``.mcap`` file); errors are :class:`BagError` or
    :class:`~tdcm_ros.metrics.errors.MetricsError` naming the file and topic."""
    reader = open_bag(path)
    warnings = list(reader.warnings)
    tension = _tension(reader, tension_topic, warnings)
    markers, occluded = _markers(reader, markers_topic, labels, warnings)
    registration = _registration(reader, markers.frame_id, warnings)
    return BagSource(Path(path), tension, markers, registration, tuple(warnings), occluded)
