"""Read the evaluation's inputs from a bag: tension, marker frames and the registration.

- tension: ``geometry_msgs/msg/WrenchStamped`` (``wrench.force.z``, N) or, as model_node takes
  it, ``std_msgs/msg/Float64`` (``data``, N; no header: stamped by the bag's log times) or
  ``sensor_msgs/msg/JointState`` (an effort in N per tendon, by the body file's tendon names); a
  body with several tendons takes the JointState, or a WrenchStamped or Float64 topic per
  tendon, put on the first tendon's stamps (:mod:`tdcm_ros.metrics.tension_topics`);
- markers: ``mocap4r2_msgs/msg/Markers`` (positions in the message's frame, matched to the
  layout's labels by ``marker_name``; unknown names are ignored and counted in a warning; a
  layout label never seen is an error listing the names the bag holds, with their frame counts). A
  position that is NaN or exactly ``(0, 0, 0)`` is an occluded marker, as mocap_node treats it
  (:func:`tdcm_ros.mocap.occlusion.visible`): missing, counted, never a measurement;
- registration: the ``/tf_static`` transform whose child is ``tdcm_base`` and whose parent is the
  markers' frame, if the bag has one;
- roll: the position (rad about the base +z axis) of one joint of a ``sensor_msgs/msg/JointState``
  topic (``joint_states``, joint ``roll``), if the bag has the topic (none: roll 0 throughout);
  a message without a finite position for the joint is left out (counted in a warning), and a
  topic without any leaves roll 0 (said in a warning).

Stamps are the header stamps (s since the epoch); a topic whose header stamps are all zero uses
the bag's log times instead (said in a warning). Messages are left out, counted in a warning:

- duplicates: the same topic, stamp and payload bytes as an earlier message (payloads are
  compared by a keyed 64-bit hash, :func:`hash`: two different payloads under one stamp collide
  with probability 2^-64; only the messages whose stamp another message shares are hashed, in a
  second read of their topic, so a bag without shared stamps is read once and holds no hashes);
- implausible stamps: at or before 0 s, at or beyond 2^31 - 1 s (the int32 ``sec`` maximum), or more
  than :data:`FAR_S` from the median stamp of the topic's other messages. A topic with no
  plausible stamp at all is an error naming it, the count and a stamp.

A topic is read in batches of :data:`BATCH` messages, each decoded into arrays and its payloads
dropped, so memory holds a few numbers per message rather than the bag's bytes. The tension (one
topic) and the markers are read in one pass over the bag: every chunk holding both is
decompressed once, not once per topic, and its messages are taken by the chunk's message index
(:meth:`~tdcm_ros.bagio.reader.BagReader.raw_blocks`), not one by one.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Generic, TypeVar

import numpy as np

from tdcm_ros.bagio import BagError
from tdcm_ros.bagio.reader import BagReader, open_bag, require_topic
from tdcm_ros.errors import TdcmError
from tdcm_ros.metrics.align import on_first_stamps
from tdcm_ros.metrics.cdr import (
    float64_data,
    joint_efforts,
    joint_positions,
    markers_groups,
    wrench_force_z,
)
from tdcm_ros.metrics.errors import MetricsError, TensionTopicError
from tdcm_ros.metrics.series import MarkerSeries, RollSeries, TensionSeries
from tdcm_ros.metrics.tension_topics import OPTION, TensionTopics, tension_topics
from tdcm_ros.mocap import Registration, visible

TENSION_TYPE = "geometry_msgs/msg/WrenchStamped"
FLOAT_TENSION_TYPE = "std_msgs/msg/Float64"
JOINT_STATE_TYPE = "sensor_msgs/msg/JointState"
MARKERS_TYPE = "mocap4r2_msgs/msg/Markers"
TF_TYPE = "tf2_msgs/msg/TFMessage"
ONE_TENSION_TYPES = (TENSION_TYPE, FLOAT_TENSION_TYPE)
"""Types of a topic holding one tendon's tension."""
BASE_FRAME = "tdcm_base"
MAX_STAMP_S = 2.0**31 - 1.0
"""Stamps (s since the epoch) at or beyond this are implausible: the int32 ``sec`` maximum."""
FAR_S = 86_400.0
"""Stamps farther than this (s) from the median stamp of their topic are implausible."""
BATCH = 8192
"""Messages of a topic decoded at a time, at most (their payloads are then dropped)."""
_Decode = Callable[[Sequence[bytes]], tuple[np.ndarray, ...]]
"""Payloads of one topic -> their header stamps (ns) and value arrays (one row per message)."""
_Read = tuple[np.ndarray, bool, np.ndarray, list[np.ndarray]]
"""A topic read (:meth:`_Reading.result`): stamps (ns since the epoch), whether they are the log
times, the mask of the messages that are not duplicates and the value arrays."""
_T = TypeVar("_T")
_SECONDS_BLOCK = 1 << 16
"""Stamps converted from ns to s at a time (:func:`_seconds`)."""


@dataclass(frozen=True, eq=False)
class BagSource:
    """One bag's inputs: series, the registration it carries (or None), reading warnings, the
    occluded marker positions (NaN or exactly zero) left out, per label, and the roll (None:
    no roll topic, roll 0 throughout)."""

    path: Path
    tension: TensionSeries
    markers: MarkerSeries
    registration: Registration | None
    warnings: tuple[str, ...]
    occluded: dict[str, int] = field(default_factory=dict)
    roll: RollSeries | None = None


def _unique(stamps_ns: np.ndarray, digests: Callable[[list[int]], list[int]]) -> np.ndarray:
    """Mask of the messages kept: each is dropped that repeats an earlier one's stamp (ns) and
    payload (see the module docstring); ``digests`` gives the payload hashes of the messages at
    the positions asked for (only those whose stamp is shared)."""
    keep = np.ones(len(stamps_ns), dtype=bool)
    if np.all(np.diff(stamps_ns) > 0):  # strictly increasing: no stamp is shared
        return keep
    order = np.argsort(stamps_ns, kind="stable")
    equal = np.flatnonzero(np.diff(stamps_ns[order]) == 0)  # positions equal to the next
    shared = order[np.union1d(equal, equal + 1)].tolist()  # only stamps shared, in order
    seen: set[tuple[int, int]] = set()
    for n, digest in zip(shared, digests(shared), strict=True):
        key = (int(stamps_ns[n]), digest)
        keep[n] = key not in seen
        seen.add(key)
    return keep


def _plausible(t: np.ndarray, path: Path, topic: str, warnings: list[str]) -> np.ndarray:
    """Mask of the messages whose stamps ``t`` (s since the epoch) are plausible (see the module
    docstring). One temporary of the stamps' size at a time."""
    keep = (t > 0.0) & (t < MAX_STAMP_S)
    if keep.any():
        # t[keep] is a copy of its own: its median may sort it in place
        off = t - np.median(t[keep], overwrite_input=True)
        keep &= np.abs(off, out=off) <= FAR_S
        del off
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


class _Column:
    """Rows appended batch by batch into one array, grown by doubling past ``capacity`` (no list
    of parts joined at the end: that join would hold every row twice)."""

    def __init__(self, capacity: int) -> None:
        self._capacity = max(capacity, 1)
        self._data: np.ndarray | None = None
        self._size = 0

    def extend(self, rows: np.ndarray) -> None:
        if self._data is None:
            self._data = np.empty((self._capacity, *rows.shape[1:]), rows.dtype)
        end = self._size + len(rows)
        if end > len(self._data):
            grown = np.empty((max(end, 2 * len(self._data)), *rows.shape[1:]), rows.dtype)
            grown[:self._size] = self._data[:self._size]
            self._data = grown
        self._data[self._size:end] = rows
        self._size = end

    def array(self) -> np.ndarray:
        """The rows so far (a view)."""
        return np.empty(0) if self._data is None else self._data[:self._size]


class _Reading:
    """One topic decoded batch by batch (:func:`_read_all`): header stamps, log times (kept only
    while every header stamp is zero) and the decoded values. A decoding error
    stops the topic's decoding and is raised by :meth:`result`: with several topics read in one
    pass, each topic's error comes when its result is taken, in the order reading the topics
    one after the other gives."""

    def __init__(self, reader: BagReader, name: str, decode: _Decode) -> None:
        self.name = name
        self._reader = reader
        self._decode = decode
        self._capacity = reader.counts.get(name, 0)
        self._header, self._log = _Column(self._capacity), _Column(self._capacity)
        self.read_with: list[str] = [name]
        """The topics of the pass that reads this one (:func:`_read_all`)."""
        self._values: list[_Column] = []
        self._from_log = True
        self._error: TdcmError | None = None

    def add(self, log_ns: np.ndarray, payloads: Sequence[bytes]) -> None:
        """Decode messages of this topic, in log-time order: their log times (ns) and CDR
        payloads."""
        if self._error is not None:
            return
        try:
            header_ns, *decoded = self._decode(payloads)
        except TdcmError as error:
            self._error = error
            return
        self._values = self._values or [_Column(self._capacity) for _ in decoded]
        for column, rows in zip(self._values, decoded, strict=True):
            column.extend(rows)
        self._header.extend(header_ns)
        self._from_log = self._from_log and not header_ns.any()
        if self._from_log:
            self._log.extend(log_ns)

    @property
    def failed(self) -> bool:
        """Whether decoding raised an error (:meth:`result` raises it)."""
        return self._error is not None

    def result(self) -> _Read:
        """The topic read (:data:`_Read`); its columns are handed over, not kept."""
        if self._error is not None:
            raise self._error
        stamps_ns = (self._log if self._from_log else self._header).array()
        if not stamps_ns.size:
            raise BagError(f"{self._reader.path}: topic {self.name} has no readable messages")
        read = (stamps_ns, self._from_log, _unique(stamps_ns, self._digests),
                [c.array() for c in self._values])
        self._header, self._log = _Column(0), _Column(0)
        self._values = []
        return read

    def _digests(self, positions: list[int]) -> list[int]:
        """Hashes of the payloads of this topic's messages at ``positions`` (0-based, in the
        order read), read again in a pass over the same topics as the first (the same order)."""
        wanted = set(positions)
        found: dict[int, int] = {}
        messages = (data for topic, _, data in self._reader.raw_messages(self.read_with)
                    if topic == self.name)
        for n, data in enumerate(messages):
            if n in wanted:
                found[n] = hash(data)
        return [found[n] for n in positions]


def _read_all(reader: BagReader, readings: Sequence[_Reading]) -> None:
    """Read the topics of ``readings`` in one pass, :data:`BATCH` messages at a time."""
    by_name: dict[str, list[_Reading]] = {}
    for reading in readings:
        by_name.setdefault(reading.name, []).append(reading)
    for reading in readings:
        reading.read_with = list(by_name)
    for topic, log_ns, payloads in reader.raw_blocks(list(by_name), BATCH):
        for reading in by_name[topic]:
            reading.add(log_ns, payloads)
        if all(reading.failed for reading in readings):
            return


def _read(reader: BagReader, name: str, decode: _Decode) -> _Read:
    """Read topic ``name`` alone (:class:`_Reading`)."""
    reading = _Reading(reader, name, decode)
    _read_all(reader, [reading])
    return reading.result()


@dataclass(frozen=True)
class _Plan(Generic[_T]):
    """Topics to read and what is made of them once they are read (:func:`_run`)."""

    readings: list[_Reading]
    finish: Callable[[], _T]


def _run(reader: BagReader, plan: _Plan[_T]) -> _T:
    """Read ``plan``'s topics in one pass and finish it."""
    _read_all(reader, plan.readings)
    return plan.finish()


def _seconds(stamps_ns: np.ndarray) -> np.ndarray:
    """The stamps ``stamps_ns`` (int64, ns) as float64 seconds, written over their own buffer a
    block at a time (a ufunc writing over its input copies it whole first): ``stamps_ns`` is
    spent."""
    seconds = stamps_ns.view(np.float64)
    for a in range(0, len(stamps_ns), _SECONDS_BLOCK):
        seconds[a:a + _SECONDS_BLOCK] = stamps_ns[a:a + _SECONDS_BLOCK] * 1e-9
    return seconds


def _usable(stamps_ns: np.ndarray, from_log: bool, unique: np.ndarray, path: Path, topic: str,
            warnings: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The stamps (s since the epoch) of the messages kept, neither duplicated (``unique``, which
    becomes the mask of those kept) nor implausibly stamped, and that mask."""
    if from_log:
        warnings.append(f"{topic}: header stamps are all zero; using the bag's log times")
    if dropped := int((~unique).sum()):
        warnings.append(f"{topic}: {dropped} duplicated messages (same stamp and payload as an "
                        "earlier one) left out")
    keep = unique
    stamps = _seconds(stamps_ns if keep.all() else stamps_ns[keep])
    plausible = _plausible(stamps, path, topic, warnings)
    keep[keep] = plausible
    return (stamps if plausible.all() else stamps[plausible]), keep


def _tension_series(stamps: np.ndarray, force: np.ndarray) -> TensionSeries:
    """:meth:`TensionSeries.of`, without its sorted and filtered copies when the stamps (s)
    already ascend and every tension (N) is finite, as in a bag read in log-time order."""
    if stamps.size and np.all(np.diff(stamps) >= 0) and np.all(np.isfinite(force)):
        return TensionSeries(stamps, force)
    return TensionSeries.of(stamps, force)


def _tension_topic(reader: BagReader, topic: str, types: Sequence[str], which: str) -> str:
    """:func:`require_topic`, its error saying in ``which`` what ``topic`` is."""
    try:
        return require_topic(reader, topic, types)
    except BagError as error:
        raise BagError(f"{error} ({which})", parameter="tension_topic", value=topic) from error


def _tension_plan(reader: BagReader, name: str, warnings: list[str]) -> _Plan[TensionSeries]:
    """One tension (N) from the WrenchStamped or Float64 topic ``name`` (a stored name)."""
    floats = reader.topics[name] == FLOAT_TENSION_TYPE
    reading = _Reading(reader, name, float64_data if floats else wrench_force_z)

    def finish() -> TensionSeries:
        stamps_ns, from_log, unique, (force,) = reading.result()
        if floats:
            warnings.append(f"{name}: {FLOAT_TENSION_TYPE} has no header; stamped by the bag's "
                            f"log times")
            from_log = False  # said above, not as all-zero header stamps
        stamps, keep = _usable(stamps_ns, from_log, unique, reader.path, name, warnings)
        del stamps_ns  # free the stamps (ns) before the series is built
        return _tension_series(stamps, force if keep.all() else force[keep])

    return _Plan([reading], finish)


def _joint_tensions_plan(reader: BagReader, name: str, tendons: Sequence[str],
                         warnings: list[str]) -> _Plan[TensionSeries]:
    """The tendons' tensions (N) from the efforts of the JointState topic ``name``, by name; a
    tendon it never gives a finite effort for is an error, a message without one for every
    tendon is left out (counted in a warning)."""
    present: Counter[str] = Counter()
    reading = _Reading(reader, name, lambda payloads: joint_efforts(payloads, tendons, present))
    return _Plan([reading], lambda: _joint_tensions(reader, reading.result(), name, tendons,
                                                    present, warnings))


def _joint_tensions(reader: BagReader, read: _Read, name: str, tendons: Sequence[str],
                    present: Counter[str], warnings: list[str]) -> TensionSeries:
    """:func:`_joint_tensions_plan` finished: the topic's ``read`` and the joints ``present``
    with efforts."""
    stamps_ns, from_log, unique, (efforts,) = read
    if never := [t for t, column in zip(tendons, efforts.T, strict=True)
                 if not np.isfinite(column).any()]:
        held = ", ".join(f"{joint} ({count} messages)" for joint, count in
                         sorted(present.items())) or "none"
        raise TensionTopicError(
            f"{reader.path}: {OPTION} {name} ({JOINT_STATE_TYPE}) has no effort for tendon(s) "
            f"{', '.join(never)} in {len(efforts)} messages; its joints with efforts: {held}; "
            f"allowed: an effort (N) for each tendon of the body (--design), by its name "
            f"({', '.join(tendons)})", parameter=OPTION, value=never, allowed=", ".join(tendons))
    stamps, keep = _usable(stamps_ns, from_log, unique, reader.path, name, warnings)
    rows = efforts if keep.all() else efforts[keep]
    if partial := int((~np.all(np.isfinite(rows), axis=1)).sum()):
        warnings.append(f"{name}: {partial} messages without a finite effort for every tendon "
                        f"({', '.join(tendons)}) left out")
    several = len(tendons) > 1
    return TensionSeries.of(stamps, rows if several else rows[:, 0], tendons if several else ())


def _tensions_per_tendon(reader: BagReader, topics: TensionTopics, align_tolerance_s: float,
                         warnings: list[str]) -> TensionSeries:
    """The tensions (N) of the layout ``topics`` with a topic per tendon (see the module
    docstring): each topic read in turn, then put on the first one's stamps."""
    tendons = topics.tendons
    series = [_run(reader, _tension_plan(reader, _tension_topic(
        reader, topic, ONE_TENSION_TYPES,
        f"the tension topic of tendon {tendon}: {OPTION} {tendon}={topic}"), warnings))
        for tendon, topic in zip(tendons, topics.per_tendon, strict=True)]
    stamps, values = on_first_stamps([s.stamps_s for s in series],
                                     [s.tension_n for s in series], align_tolerance_s)
    first = topics.per_tendon[0]
    if dropped := series[0].stamps_s.size - stamps.size:
        warnings.append(f"{first}: {dropped} of {series[0].stamps_s.size} samples without a "
                        f"sample of every other tendon's topic within align.tolerance_s = "
                        f"{align_tolerance_s:g} s left out")
    if not stamps.size:
        raise TensionTopicError(
            f"{reader.path}: no sample of {first} has a sample of every other tendon's topic "
            f"({', '.join(topics.per_tendon[1:])}) within align.tolerance_s = "
            f"{align_tolerance_s:g} s; allowed: topics sampled over the same time, within "
            "align.tolerance_s of each other (--set align.tolerance_s=SECONDS)",
            parameter="align.tolerance_s", value=align_tolerance_s,
            allowed="the largest gap between the topics' samples (s)")
    return TensionSeries(stamps, values if len(series) > 1 else values[:, 0],
                         tendons if len(series) > 1 else ())


def _shared_tension_plan(reader: BagReader, topic: str, tendons: Sequence[str],
                         warnings: list[str]) -> _Plan[TensionSeries]:
    """The tensions (N) of ``tendons`` from the one topic ``topic`` (see the module docstring)."""
    name = _tension_topic(reader, topic, [*ONE_TENSION_TYPES, JOINT_STATE_TYPE],
                          f"the tension topic: evaluate {OPTION}, calibrate {OPTION}")
    if reader.topics[name] == JOINT_STATE_TYPE:
        return _joint_tensions_plan(reader, name, tendons, warnings)
    if len(tendons) > 1:
        raise TensionTopicError(
            f"{reader.path}: {OPTION} {name} is a {reader.topics[name]}: one tension, but the "
            f"body has {len(tendons)} tendons ({', '.join(tendons)}); allowed: a "
            f"{JOINT_STATE_TYPE} topic with an effort per tendon, or NAME=TOPIC for each tendon",
            parameter=OPTION, value=name, allowed=f"{JOINT_STATE_TYPE}, or NAME=TOPIC per tendon")
    return _tension_plan(reader, name, warnings)


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


def _frames(payloads: Sequence[bytes], index: dict[str, int], frames: set[str],
            present: Counter[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Header stamps (ns), positions (n, k, 3) m (NaN where not reported) and the reported mask
    (n, k) of Markers payloads; their frame ids are added to ``frames`` and the frames each
    marker name is reported in are counted in ``present``."""
    header = np.zeros(len(payloads), dtype=np.int64)
    rows = np.full((len(payloads), len(index), 3), np.nan)
    reported = np.zeros(rows.shape[:2], dtype=bool)
    for at, stamps, frame, names, xyz in markers_groups(payloads):
        header[at] = stamps
        frames.add(frame)
        present.update({name or "(unnamed)": len(at) for name in names})  # once per frame
        for marker_name, p in zip(names, xyz.transpose(1, 0, 2), strict=True):
            i = index.get(marker_name)
            if i is not None:  # a name given twice in a frame: its last position
                rows[at, i], reported[at, i] = p, True
    return header, rows, reported


def _markers_plan(reader: BagReader, topic: str, labels: Sequence[str], warnings: list[str]
                  ) -> _Plan[tuple[MarkerSeries, dict[str, int]]]:
    """Marker frames of ``topic`` and the occluded positions per label."""
    name = require_topic(reader, topic, [MARKERS_TYPE])
    index = {label: i for i, label in enumerate(labels)}
    frames: set[str] = set()
    present: Counter[str] = Counter()
    reading = _Reading(reader, name, lambda payloads: _frames(payloads, index, frames, present))
    return _Plan([reading], lambda: _markers(reader, reading.result(), name, labels, frames,
                                             present, warnings))


def _markers(reader: BagReader, read: _Read, name: str, labels: Sequence[str], frames: set[str],
             present: Counter[str], warnings: list[str]) -> tuple[MarkerSeries, dict[str, int]]:
    """:func:`_markers_plan` finished: the topic's ``read``, its ``frames`` ids and the frames
    each marker name is ``present`` in."""
    stamps_ns, from_log, unique, (rows, reported) = read
    if unknown := set(present) - set(labels):
        warnings.append(f"{name}: ignored markers not in the layout ({', '.join(labels)}): "
                        f"{', '.join(sorted(unknown))}")
    if len(frames) > 1:
        raise MetricsError(f"{reader.path}: {name} mixes frames {', '.join(sorted(frames))}; "
                           "allowed: one frame", parameter="markers_topic", value=sorted(frames),
                           allowed="one frame_id")
    frame = frames.pop() if frames else "mocap"
    stamps, keep = _usable(stamps_ns, from_log, unique, reader.path, name, warnings)
    if not keep.all():
        rows, reported = rows[keep], reported[keep]
    occluded = _occlude(rows, reported, labels, name, warnings)
    series = MarkerSeries.of(stamps, labels, rows, frame_id=frame)
    series.require_visible(dict(present))
    return series, occluded


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


def _roll(reader: BagReader, topic: str, joint: str, warnings: list[str]) -> RollSeries | None:
    """The roll (rad) from the position of ``joint`` in the JointState topic ``topic``; None
    when the bag has no such topic or it holds no finite position of ``joint``."""
    name = next((t for t in (topic, "/" + topic.lstrip("/")) if reader.counts.get(t)), None)
    if name is None:
        return None
    name = require_topic(reader, name, [JOINT_STATE_TYPE])
    stamps_ns, from_log, unique, (positions, named) = _read(
        reader, name, lambda payloads: joint_positions(payloads, joint))
    stamps, keep = _usable(stamps_ns, from_log, unique, reader.path, name, warnings)
    about = named if keep.all() else named[keep]  # messages of other joints are no roll samples
    stamps, rolls = stamps[about], (positions if keep.all() else positions[keep])[about]
    finite = np.isfinite(rolls)
    if not finite.any():
        warnings.append(f"{name}: no finite position of joint {joint} (the roll) in "
                        f"{rolls.size} messages naming it; roll 0 assumed")
        return None
    if dropped := int((~finite).sum()):
        warnings.append(f"{name}: {dropped} messages without a finite position of joint "
                        f"{joint} (the roll) left out")
    return RollSeries.of(stamps[finite], rolls[finite], f"{name} {joint} position")


def load_bag(path: str | Path, *, labels: Sequence[str],
             tension_topic: str | Sequence[str] = "tension", markers_topic: str = "markers",
             tendons: Sequence[str] = ("tendon_1",), align_tolerance_s: float = 0.02,
             joint_states_topic: str = "joint_states", roll_joint: str = "roll") -> BagSource:
    """Read one bag (rosbag2 folder or ``.mcap`` file) of a body whose tendons are ``tendons``
    (names, the body file's order; default: the paper's one); ``tension_topic`` one topic or
    ``NAME=TOPIC`` values (:func:`~tdcm_ros.metrics.tension_topics.tension_topics`), topics per
    tendon aligned within ``align_tolerance_s`` (s); the roll from joint ``roll_joint`` of
    ``joint_states_topic`` if present. Errors are :class:`BagError` or
    :class:`~tdcm_ros.metrics.errors.MetricsError` naming the file and topic."""
    topics = tension_topics(tension_topic, tendons)
    reader = open_bag(path)
    warnings = list(reader.warnings)
    if topics.shared is None:
        tension = _tensions_per_tendon(reader, topics, align_tolerance_s, warnings)
        markers, occluded = _run(reader, _markers_plan(reader, markers_topic, labels, warnings))
    else:  # the tension and the markers in one pass
        tensions = _shared_tension_plan(reader, topics.shared, topics.tendons, warnings)
        try:
            markers_plan: _Plan[tuple[MarkerSeries, dict[str, int]]] | None = _markers_plan(
                reader, markers_topic, labels, warnings)
        except BagError:  # no such markers topic: said once the tension is read, as before
            markers_plan = None
        _read_all(reader, [*tensions.readings, *(markers_plan.readings if markers_plan else [])])
        tension = tensions.finish()
        if markers_plan is None:
            markers_plan = _markers_plan(reader, markers_topic, labels, warnings)  # raises
        markers, occluded = markers_plan.finish()
    registration = _registration(reader, markers.frame_id, warnings)
    roll = _roll(reader, joint_states_topic, roll_joint, warnings)
    return BagSource(Path(path), tension, markers, registration, tuple(warnings), occluded, roll)
