"""Host times of the device's clock: when each telemetry frame was taken, for its stamp.

A frame's device time (s since the device's boot) plus an offset gives its host time (ns since
the epoch). Each read bounds the offset from above: every frame read by host time ``now`` was
taken at or before ``now``, so ``offset <= now - device_time(newest frame read)``, tightest for
the frames that waited least. :class:`DeviceClockMap` keeps the smallest such bound over the
last ``window_s`` of device time (so a slowly drifting device clock is followed) and forgets it
when the device clock goes back (a reboot). Frames read in a burst (a line or a device twin that
stalled and caught up) then keep the times they were taken, where stamping each read's newest
frame "now" put the first frames of a burst split over two reads up to the stall's length late
and collapsed the rest onto one stamp (57 tension stamps equal to their predecessor in a demo
beside a CPU hog, which lost a 1.5 s hold).
"""

from __future__ import annotations

from collections import deque

#: s of device time the offset's bound is kept: a clock off by 0.5 % (a ceramic resonator)
#: drifts 10 ms in it.
WINDOW_S = 2.0


class DeviceClockMap:
    """Device time (s) -> host time (ns since the epoch); see the module docstring."""

    def __init__(self, window_s: float = WINDOW_S) -> None:
        self.window_s = window_s
        #: (device s, offset ns) bounds, offsets increasing from the left (a monotonic queue)
        self._bounds: deque[tuple[float, int]] = deque()
        self._newest_s = -float("inf")

    def observe(self, device_s: float, read_ns: int) -> None:
        """A frame of ``device_s`` was read by host time ``read_ns``."""
        if device_s < self._newest_s:  # the device rebooted: its clock starts again
            self._bounds.clear()
        self._newest_s = device_s
        offset = read_ns - round(device_s * 1e9)
        while self._bounds and self._bounds[-1][1] >= offset:
            self._bounds.pop()
        self._bounds.append((device_s, offset))
        while self._bounds[0][0] < device_s - self.window_s:
            self._bounds.popleft()

    def host_ns(self, device_s: float) -> int:
        """Host time of ``device_s`` (at least one frame observed)."""
        return round(device_s * 1e9) + self._bounds[0][1]
