"""Read the evaluation's inputs from a bag: tension, marker frames and the registration.

- tension: ``geometry_msgs/msg/WrenchStamped`` (``wrench.force.z``, N);
- markers: ``mocap4r2_msgs/msg/Markers`` (positions in the message's frame, matched to the
  layout's labels by ``marker_name``; unknown names are ignored and counted in a warning);
- registration: the ``/tf_static`` transform whose child is ``tdcm_base`` and whose parent is the
  markers' frame, if the bag has one.

Stamps are the header stamps (s since the epoch); a topic whose header stamps are all zero uses
the bag's log times instead (said in a warning).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tdcm_ros.bagio.reader import BagReader, open_bag, require_topic
from tdcm_ros.metrics.cdr import markers_frame, wrench_force_z
from tdcm_ros.metrics.errors import MetricsError
from tdcm_ros.metrics.registration import Registration
from tdcm_ros.metrics.series import MarkerSeries, TensionSeries

TENSION_TYPE = "geometry_msgs/msg/WrenchStamped"
MARKERS_TYPE = "mocap4r2_msgs/msg/Markers"
TF_TYPE = "tf2_msgs/msg/TFMessage"
BASE_FRAME = "tdcm_base"


@dataclass(frozen=True, eq=False)
class BagSource:
    """One bag's inputs: series, the registration it carries (or None) and reading warnings."""

    path: Path
    tension: TensionSeries
    markers: MarkerSeries
    registration: Registration | None
    warnings: tuple[str, ...]


def _stamps(header_ns: np.ndarray, log_ns: np.ndarray, topic: str, warnings: list[str]
            ) -> np.ndarray:
    if np.all(header_ns == 0):
        warnings.append(f"{topic}: header stamps are all zero; using the bag's log times")
        return log_ns * 1e-9
    return header_ns * 1e-9


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
    return TensionSeries.of(_stamps(header_ns, log, name, warnings), force_z)


def _markers(reader: BagReader, topic: str, labels: Sequence[str], warnings: list[str]
             ) -> MarkerSeries:
    name = require_topic(reader, topic, [MARKERS_TYPE])
    index = {label: i for i, label in enumerate(labels)}
    log, payloads = _payloads(reader, name)
    header = np.zeros(len(payloads), dtype=np.int64)
    rows = np.full((len(payloads), len(labels), 3), np.nan)
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
                rows[n, i] = p
    if unknown:
        warnings.append(f"{name}: ignored markers not in the layout ({', '.join(labels)}): "
                        f"{', '.join(sorted(unknown))}")
    if len(frames) > 1:
        raise MetricsError(f"{reader.path}: {name} mixes frames {', '.join(sorted(frames))}; "
                           "allowed: one frame", parameter="markers_topic", value=sorted(frames),
                           allowed="one frame_id")
    frame = frames.pop() if frames else "mocap"
    return MarkerSeries.of(_stamps(header, log, name, warnings), labels, rows, frame_id=frame)


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
    markers = _markers(reader, markers_topic, labels, warnings)
    registration = _registration(reader, markers.frame_id, warnings)
    return BagSource(Path(path), tension, markers, registration, tuple(warnings))
