"""After a tracking run: the tip's tracking error per phase, read from the bag alone.

The bag holds the targets the demo published (``target_point``, ``tdcm_base``, with the lap
each belongs to on ``tracking/lap``: 0 the approach, then 1, 2, ...), the tip the shape
controller measured from motion capture (``controller/measured_tip``) and the one its model
predicted (``controller/predicted_tip``). Each measured tip is compared with the target at its
stamp (linear interpolation between the published targets: the circle is continuous, so this
is the target in force at that instant, without the publishing rate's steps). A sample belongs
to the lap announced last before it was recorded (log times); a phase is a run of laps
(:data:`~tdcm_ros.scenes.PHASES`: feed-forward, feedback, feed-forward with the learned gain;
:class:`~tdcm_ros.scenes.CircleTrajectory`), and its first ``settle_s`` are left out (the
move off the approach hold, the estimator's convergence after feedback starts). Per phase:
RMSE and maximum of ``|measured - target|`` (m, 3D), and of the predicted tip for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.bagio import BagError
from tdcm_ros.bagio.reader import open_bag, require_topic
from tdcm_ros.scenes import PHASE_MODES, PHASES, CircleTrajectory

Array = NDArray[np.float64]
TARGET_TOPIC = "target_point"
LAP_TOPIC = "tracking/lap"
MEASURED_TOPIC = "controller/measured_tip"
PREDICTED_TOPIC = "controller/predicted_tip"
GAIN_TOPIC = "controller/gain"
GAIN_STD_TOPIC = "controller/gain_std"
POINT_TYPE = "geometry_msgs/msg/PointStamped"
LAP_TYPE = "std_msgs/msg/Int32"
SCALAR_TYPE = "std_msgs/msg/Float64"
#: What the report reads; the demo records them (besides its other topics).
REPORTED_TOPICS = (TARGET_TOPIC, LAP_TOPIC, MEASURED_TOPIC, PREDICTED_TOPIC, GAIN_TOPIC,
                   GAIN_STD_TOPIC)


@dataclass(frozen=True)
class Series:
    """Stamped points: ``stamps_s`` (n,) s (header stamps), ``points`` (n, 3) m in
    ``tdcm_base``, ``log_s`` (n,) s when the recorder got them; times from the record's
    origin."""

    stamps_s: Array
    points: Array
    log_s: Array

    def __len__(self) -> int:
        return len(self.stamps_s)


@dataclass(frozen=True)
class TrackingRecord:
    """What the bag holds for the report; times in s from ``origin_ns`` (the first target's
    stamp, ns since the epoch: float seconds since the epoch would keep only 0.2 us)."""

    origin_ns: int
    targets: Series
    measured: Series
    predicted: Series
    lap_log_s: Array    #: log time of each lap announcement
    lap_index: NDArray[np.int64]
    gain: tuple[Array, Array] | None = None       #: (log times, values)
    gain_std: tuple[Array, Array] | None = None


def _stamp_ns(message: Any) -> int:
    return int(message.header.stamp.sec) * 10**9 + int(message.header.stamp.nanosec)


def _check_frame(bag: Path, topic: str, message: Any) -> None:
    frame = str(message.header.frame_id).lstrip("/")
    if frame != "tdcm_base":
        raise BagError(f"{bag}: {topic} is in frame {frame!r}; the report compares points in "
                       "'tdcm_base'", parameter=topic, value=frame, allowed="tdcm_base")


def read_tracking(bag: str | Path) -> TrackingRecord:
    """The report's topics from the bag at ``bag``; BagError names a missing or empty one."""
    path = Path(bag)
    reader = open_bag(path)
    names = {topic: require_topic(reader, topic, [kind]) for topic, kind in (
        (TARGET_TOPIC, POINT_TYPE), (LAP_TOPIC, LAP_TYPE), (MEASURED_TOPIC, POINT_TYPE),
        (PREDICTED_TOPIC, POINT_TYPE))}
    optional = {topic: reader.resolve(topic) for topic in (GAIN_TOPIC, GAIN_STD_TOPIC)
                if any(name.lstrip("/") == topic for name in reader.topics)}
    topic_of = {name: topic for topic, name in {**names, **optional}.items()}
    points: dict[str, list[tuple[int, float, float, float, int]]] = {
        TARGET_TOPIC: [], MEASURED_TOPIC: [], PREDICTED_TOPIC: []}
    scalars: dict[str, list[tuple[int, float]]] = {LAP_TOPIC: [], GAIN_TOPIC: [],
                                                   GAIN_STD_TOPIC: []}
    for name, log_ns, message in reader.messages(list(topic_of)):
        topic = topic_of[name]
        if topic in points:
            _check_frame(path, topic, message)
            p = message.point
            points[topic].append((_stamp_ns(message), float(p.x), float(p.y), float(p.z),
                                  log_ns))
        else:
            scalars[topic].append((log_ns, float(message.data)))
    origin = min(row[0] for row in points[TARGET_TOPIC])

    def seconds(ns: list[int]) -> Array:
        return 1e-9 * (np.array(ns, dtype=np.int64) - origin).astype(float)

    def series(topic: str) -> Series:
        rows = sorted(points[topic])
        return Series(seconds([r[0] for r in rows]),
                      np.array([r[1:4] for r in rows], dtype=float).reshape(-1, 3),
                      seconds([r[4] for r in rows]))

    def scalar(topic: str) -> tuple[Array, Array] | None:
        rows = scalars[topic]
        if not rows:
            return None
        return seconds([r[0] for r in rows]), np.array([r[1] for r in rows], dtype=float)

    laps = scalars[LAP_TOPIC]
    return TrackingRecord(origin_ns=origin, targets=series(TARGET_TOPIC), measured=series(MEASURED_TOPIC),
                          predicted=series(PREDICTED_TOPIC),
                          lap_log_s=seconds([r[0] for r in laps]),
                          lap_index=np.array([int(r[1]) for r in laps], dtype=np.int64), gain=scalar(GAIN_TOPIC),
                          gain_std=scalar(GAIN_STD_TOPIC))


def points_at(series: Series, stamps_s: Array) -> Array:
    """The points (n, 3) m of ``series`` at ``stamps_s`` (s), linear between its stamps; NaN
    rows outside its span."""
    out = np.full((len(stamps_s), 3), np.nan)
    if not len(series):
        return out
    inside = (stamps_s >= series.stamps_s[0]) & (stamps_s <= series.stamps_s[-1])
    for axis in range(3):
        out[inside, axis] = np.interp(stamps_s[inside], series.stamps_s, series.points[:, axis])
    return out


def lap_of(record: TrackingRecord, log_s: Array) -> NDArray[np.int64]:
    """The lap announced last before each log time (s); -1 before the first announcement."""
    order = np.argsort(record.lap_log_s, kind="stable")
    times, laps = record.lap_log_s[order], record.lap_index[order]
    index = np.searchsorted(times, log_s, side="right") - 1
    return np.where(index >= 0, laps[np.clip(index, 0, None)], -1)


@dataclass(frozen=True)
class PhaseError:
    """The tracking error of one phase after its settle time (m, 3D distances)."""

    phase: str              #: one of :data:`~tdcm_ros.scenes.PHASES`
    laps: tuple[int, ...]
    start_s: float          #: the phase's first announcement (s from the first target)
    window_s: tuple[float, float]  #: evaluated span (s from the first target)
    samples: int
    rmse_m: float
    max_m: float
    mean_m: tuple[float, float, float]   #: mean of measured - target per axis (bias)
    predicted_rmse_m: float  #: RMSE of predicted - target over the same span
    model_rmse_m: float      #: RMSE of predicted - measured (the model's error)

    @property
    def mode(self) -> str:
        """The controller's ``mode`` during the phase."""
        return PHASE_MODES[self.phase]

    def to_json(self) -> dict[str, Any]:
        """JSON-ready (SI units)."""
        return {"phase": self.phase, "mode": self.mode, "laps": list(self.laps),
                "start_s": self.start_s,
                "window_s": list(self.window_s), "samples": self.samples,
                "rmse_m": self.rmse_m, "max_m": self.max_m, "mean_error_m": list(self.mean_m),
                "predicted_rmse_m": self.predicted_rmse_m, "model_rmse_m": self.model_rmse_m}


def _rms(vectors: Array) -> float:
    return float(np.sqrt(np.mean(np.sum(vectors ** 2, axis=1)))) if len(vectors) else float("nan")


def phase_errors(record: TrackingRecord, circle: CircleTrajectory) -> list[PhaseError]:
    """One :class:`PhaseError` per phase (in :data:`~tdcm_ros.scenes.PHASES` order) whose
    laps the bag holds.

    Raises BagError if a phase has no measured sample after its settle time."""
    measured = record.measured
    target = points_at(record.targets, measured.stamps_s)
    laps = lap_of(record, measured.log_s)
    predicted = points_at(record.predicted, measured.stamps_s)  # the model at those instants
    errors = []
    for phase in PHASES:
        phase_laps = tuple(lap for lap in range(1, circle.laps + 1)
                           if circle.phase_of_lap(lap) == phase)
        announced = record.lap_log_s[np.isin(record.lap_index, phase_laps)]
        if not len(announced):
            continue
        start = float(announced.min())
        keep = (np.isin(laps, phase_laps) & (measured.log_s >= start + circle.settle)
                & np.all(np.isfinite(target), axis=1))
        if not keep.any():
            raise BagError(f"the {phase} phase has no measured tip after its first "
                           f"{circle.settle:g} s (trajectory.settle_s)",
                           parameter="trajectory.settle_s", value=circle.settle)
        error = measured.points[keep] - target[keep]
        mean = error.mean(axis=0)
        distance = np.linalg.norm(error, axis=1)
        stamps = measured.stamps_s[keep]
        with_model = keep & np.all(np.isfinite(predicted), axis=1)
        errors.append(PhaseError(
            phase=phase, laps=phase_laps, start_s=start,
            window_s=(float(stamps.min()), float(stamps.max())), samples=int(keep.sum()),
            rmse_m=_rms(error), max_m=float(distance.max()),
            mean_m=(float(mean[0]), float(mean[1]), float(mean[2])),
            predicted_rmse_m=_rms(predicted[with_model] - target[with_model]),
            model_rmse_m=_rms(predicted[with_model] - measured.points[with_model])))
    return errors


def format_phases(errors: list[PhaseError]) -> str:
    """A table of the phases' errors (mm)."""
    header = (f"{'phase':19s} {'laps':>6s} {'window (s)':>15s} {'samples':>8s} {'RMSE':>9s} "
              f"{'max':>9s} {'model vs target':>16s} {'model vs measured':>18s}")
    lines = [header]
    for e in errors:
        laps = f"{e.laps[0]}-{e.laps[-1]}" if len(e.laps) > 1 else str(e.laps[0])
        window = f"{e.window_s[0]:.1f}-{e.window_s[1]:.1f}"
        lines.append(f"{e.phase:19s} {laps:>6s} {window:>15s} {e.samples:8d} "
                     f"{e.rmse_m * 1e3:6.3f} mm {e.max_m * 1e3:6.3f} mm "
                     f"{e.predicted_rmse_m * 1e3:13.3f} mm {e.model_rmse_m * 1e3:15.3f} mm")
    return "\n".join(lines)
