"""The simulated world of a scene: the true body under the listed mechanics, seen by the
listed sensing effects, with the listed timing effects.

Stateful and seeded: friction history, dropout bursts and every random draw depend only on the
scene's seed and the sequence of calls. Shapes are warm-started from the previous solve and,
unless a stateful effect (friction) makes the shape depend on history, cached by tension.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass
from time import perf_counter
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from tdcm_ros.errors import out_of_range
from tdcm_ros.model import SolveResult, solve
from tdcm_ros.model.limits import check_tension
from tdcm_ros.model.loading import Loading
from tdcm_ros.nodes.shape_messages import surface_points
from tdcm_ros.scenes.effects import Effect
from tdcm_ros.scenes.effects.mechanics import MechanicsEffect
from tdcm_ros.scenes.effects.sensing import Pose, SensingEffect
from tdcm_ros.scenes.effects.timing import LATENCY_TOPICS, Latency
from tdcm_ros.scenes.errors import InvalidSceneError

if TYPE_CHECKING:
    from tdcm_ros.scenes.scene import Scene

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

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.mechanics = cast(list[MechanicsEffect], scene.build_effects("mechanics"))
        self.sensing = cast(list[SensingEffect], scene.build_effects("sensing"))
        self.timing = cast(list[Latency], scene.build_effects("timing"))
        self.loading = self._loading()
        self._stateful = any(effect.stateful for effect in self.mechanics)
        self._cache: OrderedDict[float, SolveResult] = OrderedDict()
        self._last: SolveResult | None = None
        self.solves = 0  #: solver calls made (cache hits excluded)
        self.solve_time_s = 0.0  #: wall time in those calls (s)
        self.true_mocap_to_base: Pose = scene.mocap_pose
        published = scene.mocap_pose
        for effect in self.sensing:
            published = effect.published(published)
        self.mocap_to_base: Pose = published
        self._rotation = Rotation.from_quat(scene.mocap_pose[1])

    @property
    def effects(self) -> list[Effect]:
        """Every effect instance of this world (actuation runs in the twin, not here)."""
        return [*self.mechanics, *self.sensing, *self.timing]

    def _loading(self) -> Loading | None:
        if not self.mechanics:
            return None
        fields: dict[str, Any] = {}
        for effect in self.mechanics:
            effect.contribute(fields)
        return Loading(**fields)

    def solve(self, true_tension: float) -> SolveResult:
        """The true body's shape at base tension ``true_tension`` (N), frame tdcm_base.

        Raises the model's typed errors at a physical limit or on non-convergence.
        """
        tension = check_tension(true_tension)
        cached = self._lookup(tension)
        if cached is not None:
            return cached
        started = perf_counter()
        try:
            result = solve(self.scene.true_design, tension, warm_start=self._warm_start(tension),
                           loading=self.loading)
        finally:
            self.solves += 1
            self.solve_time_s += perf_counter() - started
        for effect in self.mechanics:
            effect.commit()
        self._last = result
        if not self._stateful:
            self._cache[tension] = result
            if len(self._cache) > CACHE_SIZE:
                self._cache.popitem(last=False)
        return result

    def _warm_start(self, tension: float) -> SolveResult | None:
        """The previous shape, unless the tension ratio makes its rescaling meaningless (the
        solver scales a warm start by ``tension / previous``; from ~0 N that overflows)."""
        last = self._last
        if last is None or not WARM_RATIO[0] <= tension / max(last.tension_n, 1e-300) \
                <= WARM_RATIO[1]:
            return None
        return last

    def _lookup(self, tension: float) -> SolveResult | None:
        if self._stateful:  # history matters: only the same tension again is the same state
            last = self._last
            return last if last is not None and last.tension_n == tension else None
        hit = self._cache.get(tension)
        if hit is not None:
            self._cache.move_to_end(tension)
        return hit

    def body_markers(self, result: SolveResult) -> Array:
        """True marker centres (k, 3) m in tdcm_base on the shape ``result``."""
        scene = self.scene
        s = np.asarray(scene.marker_arc_lengths, dtype=float)
        radius, side = scene.marker_radius, scene.marker_side_rad
        for effect in self.sensing:
            s, radius, side = effect.placement(s, radius, side)
        points, _ = surface_points(result, s, radius, side)
        return points

    def markers(self, stamp_s: float, true_tension: float) -> MarkerFrame:
        """The motion-capture frame at ``stamp_s`` (s) for base tension ``true_tension`` (N):
        marker positions (k, 3) m in ``mocap``, NaN rows not visible."""
        if not math.isfinite(stamp_s):
            raise out_of_range("stamp_s", stamp_s, "a finite time", unit="s")
        body = self.body_markers(self.solve(true_tension))
        positions = self._rotation.apply(body) + self.true_mocap_to_base[0]
        for effect in self.sensing:
            positions = effect.observe(positions, stamp_s)
        return MarkerFrame(labels=self.scene.marker_labels, positions=positions)

    def delay_s(self, topic: str) -> float:
        """Latency (s) of one message on ``topic``; 0.0 when the scene lists no latency."""
        if topic not in LATENCY_TOPICS:
            allowed = ", ".join(LATENCY_TOPICS)
            raise InvalidSceneError(f"topic {topic!r} has no latency model; allowed: {allowed}",
                                    parameter="topic", value=topic, allowed=allowed)
        return sum(effect.delay(topic) for effect in self.timing)
