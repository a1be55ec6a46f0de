"""The simulated bench's ground truth as a time series, for markers sampled at their own times.

The scene simulation of ``mocap_node`` makes each marker frame from the true tension and roll at
the frame's stamp, as a camera system measures the body when it is there. The truth arrives as
stamped samples (``sim/tension_true``, ``sim/joint_states_true``, from the device twin) and can
arrive late: a twin whose thread was not scheduled for 1.8 s sends that stretch at once. Frames
built from the latest sample at the time of the tick instead froze the body for that long (a
3.4 mm jump of the measured tip in the tracking demo beside a CPU hog). So a frame at time ``t``
is made once the truth covers ``t`` (:class:`TruthTrack`, interpolated), on a fixed grid of frame
times (:class:`FrameClock`). The node takes the truth as held (the bench stands still: a stopped
twin) when no sample has arrived for ``TRUTH_STALE_NS`` of its clock (or the stamps are on
another clock, ``TRUTH_OTHER_CLOCK_NS`` behind), and then goes on at the
clock (:mod:`tdcm_ros.nodes.mocap_node`); old stamps alone do not make it held, since a node
working through a backlog of truth reads old stamps that are still to be covered. Every sample
counts, so both ends queue :data:`tdcm_ros.device.twin.TRUTH_DEPTH` of them: a dropped sample
would be interpolated across.

Times are ns since the epoch; values in SI units (N, rad).
"""

from __future__ import annotations

import bisect
from collections import deque
from collections.abc import Iterator

#: Samples a track keeps (10 s of a 1 kHz load cell; older ones are dropped).
TRACK_KEPT = 10_000


class TruthTrack:
    """Stamped samples of one quantity, in arrival order; :meth:`at` interpolates them."""

    def __init__(self, kept: int = TRACK_KEPT) -> None:
        self._stamps: deque[int] = deque(maxlen=kept)
        self._values: deque[float] = deque(maxlen=kept)

    def __bool__(self) -> bool:
        return bool(self._stamps)

    @property
    def newest_ns(self) -> int:
        """Stamp (ns) of the newest sample; the track must not be empty."""
        return self._stamps[-1]

    def add(self, stamp_ns: int, value: float) -> None:
        """Append a sample; one stamped at the newest replaces its value, one stamped before it
        is dropped, so the stamps stay increasing."""
        if self._stamps and stamp_ns <= self._stamps[-1]:
            if stamp_ns == self._stamps[-1]:
                self._values[-1] = value
            return
        self._stamps.append(stamp_ns)
        self._values.append(value)

    def at(self, stamp_ns: int) -> float:
        """The value at ``stamp_ns``: linear between the samples around it, the first or the
        newest sample's value outside them; the track must not be empty."""
        stamps, values = self._stamps, self._values
        after = bisect.bisect_right(stamps, stamp_ns)
        if after == 0:
            return values[0]
        if after == len(stamps):
            return values[-1]
        t0, t1 = stamps[after - 1], stamps[after]
        v0, v1 = values[after - 1], values[after]
        return v0 + (v1 - v0) * ((stamp_ns - t0) / (t1 - t0))


class FrameClock:
    """Frame times ``start + k * period`` (ns), handed out once each, oldest first."""

    def __init__(self, rate_hz: float) -> None:
        self.period_ns = round(1e9 / rate_hz)
        self._next_ns: int | None = None

    def until(self, end_ns: int) -> Iterator[int]:
        """The frame times not handed out yet up to ``end_ns`` (the first call starts the grid
        at ``end_ns``)."""
        if self._next_ns is None:
            self._next_ns = end_ns
        while self._next_ns <= end_ns:
            stamp = self._next_ns
            self._next_ns += self.period_ns
            yield stamp
