"""Labelling of motion-capture markers: ``m1``, ``m2``, ``m3`` ... by name or by arc length.

By **name**: a :class:`NameMap` maps Vicon names to labels. A key ``Subject:Marker`` matches
that full name only; a key ``Marker`` matches the marker part of any name (``TDCM:M1`` and
``M1``). Names that map to no label are counted as unlabelled.

By **arc length** (unlabelled markers, e.g. Vicon ``*12`` trajectories): each visible marker is
moved into ``tdcm_base`` with the registration and projected on a body axis, a polyline in
``tdcm_base`` (the straight undeformed axis, or the current predicted midline). Its arc length
is that of the closest point on the polyline. Markers and labels are then paired one to one
minimising the total ``|s_marker - s_label|`` (Hungarian assignment), among pairs whose marker
lies within ``max_distance`` (m) of the axis point at the label's arc length; markers left over
are unlabelled. The surface markers sit ``R_outer`` + ball radius off the midline and a bent
body leaves the straight axis by up to the tip deflection, so ``max_distance`` must cover both
(default 0.03 m on the straight axis).

Both return a :class:`LabelledFrame`: only visible, labelled markers, in label order.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.mocap.errors import LabelError
from tdcm_ros.mocap.occlusion import visible
from tdcm_ros.mocap.registration import Registration

Array = NDArray[np.float64]
_UNREACHABLE = 1e9


@dataclass(frozen=True)
class LabelledFrame:
    """Visible labelled markers: ``labels`` (k,) in label order, ``positions`` (k, 3) m in
    ``mocap``; ``occluded`` and ``unlabelled`` count the markers left out."""

    labels: tuple[str, ...]
    positions: Array
    occluded: int = 0
    unlabelled: int = 0


class Labeller(Protocol):
    """Labels one frame: ``names`` (k,) as reported (``None`` if unnamed), ``positions`` (k, 3)
    m in ``mocap``."""

    labels: tuple[str, ...]

    def __call__(self, names: Sequence[str] | None, positions: ArrayLike) -> LabelledFrame:
        """The labelled frame."""


def _check_labels(labels: Sequence[str]) -> tuple[str, ...]:
    result = tuple(str(label) for label in labels)
    if not result or any(not label for label in result) or len(set(result)) != len(result):
        raise LabelError(f"labels = {list(result)!r} are invalid; allowed: unique non-empty names",
                         parameter="labelling.labels", value=list(result),
                         allowed="unique non-empty names")
    return result


def marker_part(name: str) -> str:
    """``Marker`` of ``Subject:Marker`` (the name itself without a subject)."""
    return name.rsplit(":", 1)[-1]


class NameMap:
    """Vicon name -> label; keys ``Subject:Marker`` (exact) or ``Marker`` (any subject)."""

    def __init__(self, mapping: Mapping[str, str], labels: Sequence[str]) -> None:
        self.labels = _check_labels(labels)
        self.mapping = {str(k).strip(): str(v).strip() for k, v in mapping.items()}
        for key, label in self.mapping.items():
            if not key or label not in self.labels:
                raise LabelError(f"labelling.map entry {key!r} -> {label!r} is invalid; allowed: "
                                 f"a Vicon name mapped to one of {list(self.labels)}",
                                 parameter="labelling.map", value=f"{key}={label}",
                                 allowed=", ".join(self.labels))
        taken = list(self.mapping.values())
        if len(set(taken)) != len(taken):
            raise LabelError(f"labelling.map gives one label to several names: {self.mapping!r}",
                             parameter="labelling.map", value=self.mapping,
                             allowed="one Vicon name per label")

    @classmethod
    def parse(cls, entries: Sequence[str], labels: Sequence[str]) -> NameMap:
        """From ``["Vicon name=label", ...]`` entries."""
        mapping: dict[str, str] = {}
        for entry in entries:
            key, sep, label = str(entry).rpartition("=")
            if not sep or key.strip() in mapping:
                raise LabelError(f"labelling.map entry {entry!r} is invalid; allowed: unique "
                                 "'Vicon name=label' entries", parameter="labelling.map",
                                 value=entry, allowed="'Subject:Marker=m1' or 'Marker=m1'")
            mapping[key.strip()] = label
        return cls(mapping, labels)

    def label_of(self, name: str) -> str | None:
        """The label of the reported ``name``, or ``None``."""
        if name in self.mapping:
            return self.mapping[name]
        part = marker_part(name)
        for key, label in self.mapping.items():
            if marker_part(key) == part and (":" not in key or ":" not in name):
                return label
        return None

    def require(self, names: Sequence[str], source: str) -> None:
        """Raise :class:`LabelError` unless every label is found once among ``names``."""
        found = [self.label_of(name) for name in names]
        for label in self.labels:
            count = found.count(label)
            if count != 1:
                keys = [k for k, v in self.mapping.items() if v == label]
                raise LabelError(
                    f"{source}: label {label!r} (map keys {keys}) matches {count} markers; "
                    f"markers in the source: {list(names)}", parameter="labelling.map",
                    value=keys, allowed=", ".join(names))


class NameLabeller:
    """Labels by name with a :class:`NameMap`; drops occluded and unmapped markers."""

    def __init__(self, name_map: NameMap) -> None:
        self.name_map = name_map
        self.labels = name_map.labels

    def __call__(self, names: Sequence[str] | None, positions: ArrayLike) -> LabelledFrame:
        """The labelled frame; a second marker with an already used label is unlabelled."""
        p = np.asarray(positions, dtype=float).reshape(-1, 3)
        seen = visible(p)
        chosen: dict[str, Array] = {}
        occluded = unlabelled = 0
        for index, name in enumerate(names if names is not None else [""] * len(p)):
            label = self.name_map.label_of(name)
            if label is None:
                unlabelled += 1
            elif not seen[index]:
                occluded += 1
            elif label in chosen:
                unlabelled += 1
            else:
                chosen[label] = p[index]
        return _ordered(self.labels, chosen, occluded, unlabelled)


def _ordered(labels: tuple[str, ...], chosen: Mapping[str, Array], occluded: int,
             unlabelled: int) -> LabelledFrame:
    order = tuple(label for label in labels if label in chosen)
    positions = (np.array([chosen[label] for label in order]) if order
                 else np.zeros((0, 3)))
    return LabelledFrame(order, positions, occluded, unlabelled)


def straight_axis(length: float) -> Array:
    """The undeformed body axis in ``tdcm_base``: from the origin along +z, ``length`` m."""
    if not (np.isfinite(length) and length > 0.0):
        raise out_of_range("labelling.body_length", length, "(0, inf)", unit="m",
                           error=LabelError)
    return np.array([[0.0, 0.0, 0.0], [0.0, 0.0, float(length)]])


def _segments(polyline: Array) -> tuple[Array, Array, Array, Array]:
    start, delta = polyline[:-1], np.diff(polyline, axis=0)
    length = np.linalg.norm(delta, axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(length)])
    return start, delta, length, cumulative


def project_on_polyline(points: ArrayLike, polyline: ArrayLike) -> tuple[Array, Array]:
    """Arc length (k,) m of the closest polyline point to each of ``points`` (k, 3), and the
    distance (k,) m to it. ``polyline`` (m, 3), m >= 2, in the same frame."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    start, delta, length, cumulative = _segments(np.asarray(polyline, dtype=float))
    squared = np.maximum(length**2, 1e-30)
    t = np.clip(np.einsum("kmj,mj->km", p[:, None, :] - start[None], delta) / squared, 0.0, 1.0)
    closest = start[None] + t[..., None] * delta[None]
    distance = np.linalg.norm(p[:, None, :] - closest, axis=2)
    best = np.argmin(distance, axis=1)
    rows = np.arange(len(p))
    return cumulative[best] + t[rows, best] * length[best], distance[rows, best]


def point_at(polyline: ArrayLike, s: ArrayLike) -> Array:
    """Points (k, 3) of ``polyline`` (m, 3) at arc lengths ``s`` (k,) m (clamped to its ends)."""
    line = np.asarray(polyline, dtype=float)
    _, _, _, cumulative = _segments(line)
    arc = np.clip(np.asarray(s, dtype=float), 0.0, cumulative[-1])
    return np.stack([np.interp(arc, cumulative, line[:, j]) for j in range(3)], axis=1)


class ArcLengthLabeller:
    """Labels unnamed markers by their arc length along a body axis (module docstring)."""

    def __init__(self, labels: Sequence[str], arc_lengths: Sequence[float],
                 registration: Registration, axis: ArrayLike, max_distance: float) -> None:
        self.labels = _check_labels(labels)
        self.arc_lengths = np.asarray(arc_lengths, dtype=float)
        if self.arc_lengths.shape != (len(self.labels),) or not np.all(
                np.isfinite(self.arc_lengths)) or np.any(self.arc_lengths < 0.0):
            raise out_of_range("labelling.arc_lengths", list(arc_lengths),
                               f"{len(self.labels)} arc lengths >= 0 (one per label)", unit="m",
                               error=LabelError)
        if not (np.isfinite(max_distance) and max_distance > 0.0):
            raise out_of_range("labelling.max_distance", max_distance, "(0, inf)", unit="m",
                               error=LabelError)
        self.registration = registration
        self.max_distance = float(max_distance)
        self.set_axis(axis)

    def set_axis(self, axis: ArrayLike) -> None:
        """Replace the body axis: a polyline (m, 3), m >= 2, in ``tdcm_base`` (m)."""
        line = np.asarray(axis, dtype=float)
        if line.ndim != 2 or line.shape[0] < 2 or line.shape[1] != 3 or not np.all(
                np.isfinite(line)) or _segments(line)[3][-1] <= 0.0:
            raise out_of_range("axis", line.shape, "a finite polyline (m >= 2, 3) of non-zero "
                               "length", error=LabelError)
        self.axis = line
        self.label_points = point_at(line, self.arc_lengths)

    def __call__(self, names: Sequence[str] | None, positions: ArrayLike) -> LabelledFrame:
        """The labelled frame; ``names`` are ignored."""
        p = np.asarray(positions, dtype=float).reshape(-1, 3)
        seen = visible(p)
        candidates = p[seen]
        occluded = int(len(p) - seen.sum())
        if not len(candidates):
            return LabelledFrame((), np.zeros((0, 3)), occluded, 0)
        base = self.registration.to_base(candidates)
        s, _ = project_on_polyline(base, self.axis)
        gap = np.linalg.norm(base[:, None, :] - self.label_points[None], axis=2)
        cost = np.where(gap <= self.max_distance,
                        np.abs(s[:, None] - self.arc_lengths[None]), _UNREACHABLE)
        # scipy on use only: the mocap face imports this module
        from scipy.optimize import linear_sum_assignment

        rows, cols = linear_sum_assignment(cost)
        chosen = {self.labels[c]: candidates[r] for r, c in zip(rows, cols, strict=True)
                  if cost[r, c] < _UNREACHABLE}
        return _ordered(self.labels, chosen, occluded, len(candidates) - len(chosen))
