"""The simulated world of a compiled scene: the true body under the listed mechanics, seen by
the listed sensing effects, with the listed timing effects.

Built from a :class:`~tdcm_ros.scenes.compiled.CompiledScene` (``Scene.world()`` compiles one);
it walks the bundle's per-stage effects and nothing else. Stateful and seeded: friction
history, dropout bursts and every random draw depend only on the scene's seed and the sequence
of calls. Shapes are warm-started from the previous solve and, unless a mechanics effect keeps
a history (friction) that makes the shape depend on the path, cached by tension (and roll).

Roll (:mod:`tdcm_ros.model.roll`): the body turns about the base +z axis by the true roll
(rad), its markers with it (they are glued to it). The scene's loads stay fixed in
``tdcm_base``: the planar solve takes their part in the rolled bending plane
(:func:`~tdcm_ros.model.roll_loading`), so a horizontal gravity bends the body less as it rolls
away from the x-z plane and not at all at +-pi/2; the out-of-plane part is not modelled.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass
from time import perf_counter

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from tdcm_ros.errors import out_of_range
from tdcm_ros.model import (
    Loading,
    SolveResult,
    check_roll,
    check_tension,
    depends_on_roll,
    roll_loading,
    roll_points,
    solve,
    surface_points,
)
from tdcm_ros.scenes.compiled import CompiledScene
from tdcm_ros.scenes.effects.timing import LATENCY_TOPICS
from tdcm_ros.scenes.errors import InvalidSceneError
from tdcm_ros.scenes.stages import Mechanics, Metered, Pose, Sensing, Timing

Array = NDArray[np.float64]
CACHE_SIZE = 512
WARM_RATIO = (1e-3, 1e3)  #: tension ratios over which the previous shape is a useful start


@dataclass(frozen=True)
class MarkerFrame:
    """One motion-capture frame: ``positions`` (k, 3) m in ``mocap``, NaN rows not visible."""

    labels: tuple[str, ...]
    positions: Array


class World:
    """See the module docstring; build with :meth:`Scene.world`."""

    def __init__(self, compiled: CompiledScene) -> None:
        self.compiled = compiled
        self.bench = compiled.bench
        self._cache: OrderedDict[tuple[float, float], SolveResult] = OrderedDict()
        self._last: tuple[tuple[float, float], SolveResult] | None = None
        self._rolls = depends_on_roll(compiled.loading)
        self.solves = 0  #: solver calls made (cache hits excluded)
        self.solve_time_s = 0.0  #: wall time in those calls (s)
        self.true_mocap_to_base: Pose = self.bench.mocap_pose
        published = self.bench.mocap_pose
        for effect in self.sensing:
            published = effect.published(published)
        self.mocap_to_base: Pose = published
        self._rotation = Rotation.from_quat(self.bench.mocap_pose[1])

    @property
    def loading(self) -> Loading | None:
        """What the listed mechanics effects add to the solve; None without any."""
        return self.compiled.loading

    @property
    def mechanics(self) -> tuple[Mechanics, ...]:
        """The listed mechanics effects, in file order."""
        return self.compiled.mechanics

    @property
    def sensing(self) -> tuple[Sensing, ...]:
        """The listed sensing effects, in file order."""
        return self.compiled.sensing

    @property
    def timing(self) -> tuple[Timing, ...]:
        """The listed timing effects, in file order."""
        return self.compiled.timing

    @property
    def effects(self) -> list[Metered]:
        """Every effect instance of this world (actuation runs in the twin, not here)."""
        return [*self.mechanics, *self.sensing, *self.timing]

    @property
    def _stateful(self) -> bool:
        return bool(self.compiled.histories)

    def solve(self, true_tension: float, roll: float = 0.0) -> SolveResult:
        """The true body's planar shape at base tension ``true_tension`` (N), in its bending
        plane rolled by ``roll`` (rad): frame tdcm_base at roll 0 (turn it with
        :func:`~tdcm_ros.model.roll_points`). The roll matters only through the loads' part in
        that plane (module docstring).

        Raises the model's typed errors at a physical limit or on non-convergence; only a
        converged result advances the mechanics effects' histories.
        """
        tension = check_tension(true_tension)
        phi = check_roll(roll)
        key = (tension, math.cos(phi) if self._rolls else 1.0)  # the in-plane loads' factor
        cached = self._lookup(key)
        if cached is not None:
            return cached
        started = perf_counter()
        try:
            result = solve(self.bench.true_design, tension, warm_start=self._warm_start(tension),
                           loading=roll_loading(self.loading, phi))
        finally:
            self.solves += 1
            self.solve_time_s += perf_counter() - started
        for history in self.compiled.histories:
            history.advance(result)
        self._last = (key, result)
        if not self._stateful:
            self._cache[key] = result
            if len(self._cache) > CACHE_SIZE:
                self._cache.popitem(last=False)
        return result

    def _warm_start(self, tension: float) -> SolveResult | None:
        """The previous shape, unless the tension ratio makes its rescaling meaningless (the
        solver scales a warm start by ``tension / previous``; from ~0 N that overflows)."""
        if self._last is None:
            return None
        last = self._last[1]
        if not WARM_RATIO[0] <= tension / max(last.tension_n, 1e-300) <= WARM_RATIO[1]:
            return None
        return last

    def _lookup(self, key: tuple[float, float]) -> SolveResult | None:
        """The shape solved for ``(tension, in-plane load factor)``, if kept."""
        if self._stateful:  # history matters: only the same state again is the same shape
            last = self._last
            return last[1] if last is not None and last[0] == key else None
        hit = self._cache.get(key)
        if hit is not None:
            self._cache.move_to_end(key)
        return hit

    def body_markers(self, result: SolveResult, roll: float = 0.0) -> Array:
        """True marker centres (k, 3) m in tdcm_base on the planar shape ``result`` turned by
        ``roll`` (rad) about the base +z axis."""
        bench = self.bench
        s = np.asarray(bench.marker_arc_lengths, dtype=float)
        radius, side = bench.marker_radius, bench.marker_side_rad
        for effect in self.sensing:
            s, radius, side = effect.placement(s, radius, side)
        points, _ = surface_points(result, s, radius, side)
        return roll_points(points, roll)

    def markers(self, stamp_s: float, true_tension: float, roll: float = 0.0) -> MarkerFrame:
        """The motion-capture frame at ``stamp_s`` (s) for base tension ``true_tension`` (N)
        and body roll ``roll`` (rad about the base +z axis): marker positions (k, 3) m in
        ``mocap``, NaN rows not visible."""
        if not math.isfinite(stamp_s):
            raise out_of_range("stamp_s", stamp_s, "a finite time", unit="s")
        body = self.body_markers(self.solve(true_tension, roll), roll)
        positions = self._rotation.apply(body) + self.true_mocap_to_base[0]
        for effect in self.sensing:
            positions = effect.observe(positions, stamp_s)
        return MarkerFrame(labels=self.bench.marker_labels, positions=positions)

    def delay_s(self, topic: str) -> float:
        """Latency (s) of one message on ``topic``; 0.0 when the scene lists no latency."""
        if topic not in LATENCY_TOPICS:
            allowed = ", ".join(LATENCY_TOPICS)
            raise InvalidSceneError(f"topic {topic!r} has no latency model; allowed: {allowed}",
                                    parameter="topic", value=topic, allowed=allowed)
        return sum(effect.delay(topic) for effect in self.timing)
