"""Time series the metrics work on: tension samples, labelled marker frames and the body's roll
(SI units)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.metrics.errors import MarkersNotVisibleError, MetricsError
from tdcm_ros.model import InvalidRollError

Array = NDArray[np.float64]


def _sorted_stamps(name: str, stamps: ArrayLike) -> tuple[Array, NDArray[np.int64]]:
    t = np.asarray(stamps, dtype=float)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise MetricsError(f"{name} = array of shape {t.shape}; allowed: a non-empty 1-D array "
                           "of finite stamps (s)", parameter=name, value=t.shape,
                           allowed="non-empty 1-D finite (s)")
    order = np.argsort(t, kind="stable")
    return t[order], order


@dataclass(frozen=True, eq=False)
class TensionSeries:
    """Measured tendon tension: ``stamps_s`` (n,) s ascending; ``tension_n`` N, finite: (n,) for
    one unnamed tendon (``names`` empty), or (n, J) for the J tendons ``names`` (a column each,
    in the body file's order)."""

    stamps_s: Array
    tension_n: Array
    names: tuple[str, ...] = ()

    @classmethod
    def of(cls, stamps_s: ArrayLike, tension_n: ArrayLike, names: Sequence[str] = ()
           ) -> TensionSeries:
        """Validate, drop the samples with a non-finite tension and sort by stamp."""
        t, order = _sorted_stamps("tension stamps", stamps_s)
        x = np.asarray(tension_n, dtype=float)
        shape = (len(order), len(names)) if names else (len(order),)
        if x.shape != shape:
            raise MetricsError(f"tension samples of shape {x.shape}; allowed: {shape}, one "
                               f"per stamp{' and tendon' if names else ''}",
                               parameter="tension", value=x.shape, allowed=str(shape))
        x = x[order]
        keep = np.all(np.isfinite(x.reshape(len(order), -1)), axis=1)
        if not keep.any():
            raise MetricsError("no finite tension sample; allowed: finite values (N)",
                               parameter="tension", value="all non-finite", allowed="finite (N)")
        return cls(t[keep], x[keep], tuple(names))


@dataclass(frozen=True, eq=False)
class MarkerSeries:
    """Labelled marker frames: ``stamps_s`` (n,) ascending, ``positions`` (n, k, 3) m in the frame
    ``frame_id``, NaN rows where a marker was not visible; ``labels`` (k,)."""

    stamps_s: Array
    labels: tuple[str, ...]
    positions: Array
    frame_id: str = "mocap"

    @classmethod
    def of(cls, stamps_s: ArrayLike, labels: Sequence[str], positions: ArrayLike, *,
           frame_id: str = "mocap") -> MarkerSeries:
        """Validate and sort by stamp; a position row with any non-finite value becomes NaN."""
        t, order = _sorted_stamps("marker stamps", stamps_s)
        p = np.asarray(positions, dtype=float)
        if p.shape != (len(order), len(labels), 3):
            raise MetricsError(f"marker positions of shape {p.shape}; allowed: "
                               f"({len(order)}, {len(labels)}, 3)", parameter="markers",
                               value=p.shape, allowed=f"({len(order)}, {len(labels)}, 3)")
        p = p[order]  # the one copy: the caller's array is never changed
        p[~np.all(np.isfinite(p), axis=2)] = np.nan
        return cls(t, tuple(labels), p, frame_id)

    def visible(self) -> NDArray[np.bool_]:
        """(n, k) True where the marker was seen."""
        return ~np.isnan(self.positions[:, :, 0])

    def require_visible(self, present: Mapping[str, int] | None = None) -> None:
        """Raise :class:`MarkersNotVisibleError` naming the markers never seen; ``present`` (the
        marker names the data holds, with the frames each was seen in) is listed in the error
        with the parameter that maps them onto the layout."""
        never = [label for label, seen in zip(self.labels, np.any(self.visible(), axis=0),
                                              strict=True) if not seen]
        if not never:
            return
        hint = ""
        if present:
            listed = ", ".join(f"{name} ({count} frames)" for name, count in
                               sorted(present.items(), key=lambda item: (-item[1], item[0])))
            likely = ",".join(sorted(sorted(present, key=lambda n: -present[n])
                                     [:len(self.labels)]))
            hint = (f"; the data holds markers {listed}; map them base to tip with "
                    f"markers.labels (tdcm evaluate/calibrate: --set markers.labels={likely}; "
                    "metrics_node: parameter markers.labels)")
        raise MarkersNotVisibleError(
            f"markers {', '.join(never)} never come into view in {len(self.stamps_s)} "
            f"frames{hint}; allowed: each marker visible in at least one frame",
            parameter="markers.labels" if present else "markers", value=never,
            allowed="visible in >= 1 frame")


@dataclass(frozen=True, eq=False)
class RollSeries:
    """The body's roll about the base +z axis: ``stamps_s`` (n,) s ascending, ``roll_rad`` (n,)
    rad, finite; held from each sample to the next (:meth:`at`)."""

    stamps_s: Array
    roll_rad: Array

    @classmethod
    def of(cls, stamps_s: ArrayLike, roll_rad: ArrayLike, parameter: str = "roll"
           ) -> RollSeries:
        """Validate and sort by stamp; a non-finite roll is an
        :class:`~tdcm_ros.model.InvalidRollError` naming ``parameter`` and the value."""
        t, order = _sorted_stamps("roll stamps", stamps_s)
        x = np.asarray(roll_rad, dtype=float)
        if x.shape != t.shape:
            raise MetricsError(f"roll samples of shape {x.shape}; allowed: {t.shape}, one per "
                               "stamp", parameter=parameter, value=x.shape, allowed=str(t.shape))
        if not np.all(finite := np.isfinite(x)):
            raise out_of_range(parameter, float(x[~finite][0]), "a finite real number "
                               "(-inf, inf)", unit="rad", error=InvalidRollError)
        return cls(t, x[order])

    def at(self, stamps_s: ArrayLike) -> Array:
        """The roll (rad) at each stamp (s): the latest sample at or before it, else the first
        (as :class:`~tdcm_ros.model.RollHistory` pairs a stamp with its roll)."""
        index = np.searchsorted(self.stamps_s, np.asarray(stamps_s, dtype=float), side="right")
        return self.roll_rad[np.maximum(index - 1, 0)]
