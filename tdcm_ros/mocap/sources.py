"""Marker sources of ``mocap_node`` without any transport: CSV replay and scene simulation.

Both hand out :class:`RawFrame` objects (stamp, frame number, names, positions in ``mocap``)
when they are due on the caller's clock (ns since the epoch); the node labels and publishes
them. The live-driver source needs no state and lives in the node.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.mocap.errors import MocapError
from tdcm_ros.mocap.nexus_csv import Trajectories

Array = NDArray[np.float64]
MAX_BURST = 1000
"""Most frames one :meth:`.CsvReplay.due` call returns; a longer backlog is handed out on later calls."""


class SourceError(MocapError, InputError):
    """A source produced data that breaks its contract (e.g. a scene frame of the wrong shape)."""


@dataclass(frozen=True)
class RawFrame:
    """One unlabelled frame: ``stamp_ns`` (ns since the epoch), ``frame_number``, ``names``
    (k,) or ``None``, ``positions`` (k, 3) m in ``mocap`` (NaN/zero rows = not visible)."""

    stamp_ns: int
    frame_number: int
    names: tuple[str, ...] | None
    positions: Array


class CsvReplay:
    """Replays :class:`Trajectories` in real time times ``rate_scale``, optionally looping.

    Row ``i`` of pass ``j`` is due at ``start_ns + (j * (T + 1/rate) + t_i) / rate_scale``
    (``T`` the recording's duration) and is stamped with that time (replay time).
    """

    def __init__(self, trajectories: Trajectories, *, rate_scale: float, loop: bool,
                 start_ns: int) -> None:
        if not (np.isfinite(rate_scale) and rate_scale > 0.0):
            raise out_of_range("csv.rate_scale", rate_scale, "(0, inf)")
        self.trajectories = trajectories
        self.rate_scale = float(rate_scale)
        self.loop = loop
        self.start_ns = int(start_ns)
        times = trajectories.times_s
        self.pass_s = float(times[-1]) + 1.0 / trajectories.rate_hz
        self._offsets_ns = np.round(times / self.rate_scale * 1e9).astype(np.int64)
        self._pass_ns = round(self.pass_s / self.rate_scale * 1e9)
        self.next_row = 0
        self.passes = 0

    @property
    def finished(self) -> bool:
        """True once the last row of a non-looping replay was handed out."""
        return not self.loop and self.passes > 0

    def _due_ns(self) -> int:
        return self.start_ns + self.passes * self._pass_ns + int(self._offsets_ns[self.next_row])

    def due(self, now_ns: int) -> list[RawFrame]:
        """Rows due at ``now_ns``, in order (at most :data:`.MAX_BURST`)."""
        frames: list[RawFrame] = []
        names = self.trajectories.names
        while not self.finished and len(frames) < MAX_BURST and self._due_ns() <= now_ns:
            row = self.next_row
            frames.append(RawFrame(self._due_ns(), int(self.trajectories.frames[row]), names,
                                   self.trajectories.positions[row]))
            self.next_row += 1
            if self.next_row == len(self.trajectories.frames):
                self.next_row = 0
                self.passes += 1
        return frames


class MarkerFrame(Protocol):
    """What a scene world returns (see CONTRACTS.md): labels and (k, 3) m positions in ``mocap``,
    NaN rows not visible."""

    @property
    def labels(self) -> tuple[str, ...]: ...
    @property
    def positions(self) -> Array: ...


class MarkerWorld(Protocol):
    """The part of a scene world the simulation source uses."""

    def markers(self, stamp_s: float, true_tension: float, roll: float = 0.0) -> MarkerFrame:
        """Markers of the simulated bench at ``stamp_s`` (s) under ``true_tension`` (N), the
        body rolled by ``roll`` (rad) about the base +z axis."""


def no_delay() -> float:
    """A zero latency (s)."""
    return 0.0


class SimSource:
    """Samples a scene world's markers and hands each out ``delay()`` s after its stamp.

    ``delay`` is drawn once per frame, so a latency with jitter varies from frame to frame.
    """

    def __init__(self, world: MarkerWorld, *, delay: Callable[[], float] = no_delay) -> None:
        self.world = world
        self.delay = delay
        self.frame_number = 0
        self._queue: deque[tuple[int, RawFrame]] = deque()

    def sample(self, now_ns: int, true_tension: float, roll: float = 0.0) -> None:
        """Ask the world for the markers at ``now_ns`` under ``true_tension`` (N) and body roll
        ``roll`` (rad); queue them."""
        frame = self.world.markers(now_ns / 1e9, true_tension, roll)
        labels = tuple(str(label) for label in frame.labels)
        positions = np.asarray(frame.positions, dtype=float)
        if positions.shape != (len(labels), 3):
            raise SourceError(f"scene marker frame has positions of shape {positions.shape} for "
                              f"{len(labels)} labels", parameter="sim.scene", value=positions.shape,
                              allowed=f"({len(labels)}, 3)")
        delay_s = float(self.delay())
        if not (np.isfinite(delay_s) and delay_s >= 0.0):
            raise out_of_range("delay_s", delay_s, "[0, inf)", unit="s", error=SourceError)
        self.frame_number += 1
        self._queue.append((now_ns + round(delay_s * 1e9),
                            RawFrame(now_ns, self.frame_number, labels, positions)))

    @property
    def pending(self) -> bool:
        """True while sampled frames wait for their delay."""
        return bool(self._queue)

    def due(self, now_ns: int) -> list[RawFrame]:
        """Queued frames whose delay has passed, oldest first."""
        frames: list[RawFrame] = []
        while self._queue and self._queue[0][0] <= now_ns:
            frames.append(self._queue.popleft()[1])
        return frames
