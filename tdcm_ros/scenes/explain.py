"""``tdcm scene explain``: what each listed effect costs and how far it moves the tip.

Every figure is measured on this machine, against the same scene without the effect, at the
schedule's top tension:

- mechanics: the world solves the first trial's levels in order up to the top (friction
  history matters); cost = extra wall time per solve (best of ``repeats`` sweeps); tip change =
  distance between the true tips (tdcm_base).
- actuation: the device twin holds the top setpoint for one hold time; cost = extra wall time
  per 1 ms twin step; tip change = distance between the world's tips at the true tensions the
  twin reached (mean over the last second of the hold, or its last half if shorter).
- sensing: ``samples`` motion-capture frames at the mocap rate; cost = the effect's own time
  per call (per frame; once per world for ``registration_error``); tip change = RMS distance between the tip marker as the estimator sees it
  (mapped to tdcm_base through the published transform), over frames where both see it.
- timing: cost per message; no tip change (it shifts time, not position).

A mechanics or actuation cost is a difference of two timings, so it carries their noise: the
scene's own timing is measured twice and the difference between the two is the timing noise
(at least the clock's resolution, and at least how much faster the scene ran with the effect
than without). A cost not above the noise is reported as "below the timing noise" with the
noise, never as a negative number.
- material: the world's true E against the estimator's nominal E (not an effect; shown
  because it is usually the largest gap).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from functools import cached_property
from time import perf_counter

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from tdcm_ros.device import Heartbeat, Mode, SetMode, SetSetpoint, encode
from tdcm_ros.device.twin import DeviceTwin
from tdcm_ros.scenes.effects import REGISTRY, STAGES
from tdcm_ros.scenes.effects.timing import LATENCY_TOPICS
from tdcm_ros.scenes.scene import Scene
from tdcm_ros.scenes.stages import Pose
from tdcm_ros.scenes.world import World

Array = NDArray[np.float64]
HEARTBEAT_S = 0.1


#: the resolution of ``perf_counter`` (s): the smallest timing noise a difference can have
CLOCK_RESOLUTION_S = time.get_clock_info("perf_counter").resolution


@dataclass(frozen=True)
class EffectReport:
    """One row: cost per ``cost_unit`` (s, >= 0), tip change (m, None when not applicable) and,
    for a cost measured as a difference of timings, the timing noise it is read against (s)."""

    name: str
    stage: str
    cost_s: float
    cost_unit: str
    tip_change_m: float | None
    note: str
    noise_s: float | None = None

    @property
    def below_noise(self) -> bool:
        """True when the cost is a timing difference not above its noise."""
        return self.noise_s is not None and self.cost_s <= self.noise_s


def timed_difference(with_s: float, without_s: float, repeat_s: float) -> tuple[float, float]:
    """Cost (s, >= 0) of an effect timed as ``with_s - without_s`` and its noise (s): the
    larger of ``|repeat_s - with_s|`` (the same work timed twice), the clock's resolution and
    ``without_s - with_s`` (an effect does not make the work faster, so that is noise too)."""
    difference = with_s - without_s
    noise = max(abs(repeat_s - with_s), CLOCK_RESOLUTION_S, -difference)
    return max(difference, 0.0), noise


@dataclass(frozen=True)
class Explanation:
    """The rows of ``scene explain`` and the conditions they were measured under."""

    scene: str
    top_tension_n: float
    rows: tuple[EffectReport, ...]
    base_solve_s: float
    true_tip_m: tuple[float, float, float]

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form."""
        data = asdict(self)
        data["rows"] = [asdict(row) for row in self.rows]
        return data


def sweep_levels(scene: Scene) -> list[float]:
    """The first trial's levels in order, up to and including the first top level (N)."""
    levels = list(scene.schedule.levels)
    return levels[: levels.index(max(levels)) + 1]


def _sweep(scene: Scene, repeats: int) -> tuple[Array, float]:
    """True tip (m) at the top of the sweep and the wall time per solve (s): for each level
    the fastest of ``repeats`` fresh sweeps (robust to a busy machine), averaged."""
    levels = sweep_levels(scene)
    times = np.full((repeats, len(levels)), np.inf)
    tip = np.zeros(3)
    for r in range(repeats):
        world = scene.world()
        for k, level in enumerate(levels):
            started = perf_counter()
            result = world.solve(level)
            times[r, k] = perf_counter() - started
            tip = result.tip_position
    return tip, float(np.mean(np.min(times, axis=0)))


def _twin_hold(scene: Scene, setpoint: float, repeats: int) -> tuple[float, float]:
    """Mean true tension (N) at the end of a hold at ``setpoint`` N (see module docstring), the wall
    time per 1 ms twin step (s, fastest of ``repeats`` holds)."""
    hold = scene.schedule.hold
    steps = max(1, round(hold / HEARTBEAT_S))
    best = math.inf
    tension = 0.0
    for _ in range(repeats):
        twin = DeviceTwin(scene.plant_config())
        twin.receive(encode(SetSetpoint(newtons=setpoint)) + encode(SetMode(mode=Mode.TENSION)))
        started = perf_counter()
        for _ in range(steps):
            twin.advance(HEARTBEAT_S)
            twin.receive(encode(Heartbeat()))
        best = min(best, (perf_counter() - started) / (steps * HEARTBEAT_S * 1000))
        truth = [t for stamp, t in twin.take_truth() if stamp >= twin.time - min(1.0, hold / 2)]
        tension = float(np.mean(truth))
    return tension, best


def _to_base(points: Array, pose: Pose) -> Array:
    """Points (k, 3) m from ``mocap`` into tdcm_base through the transform ``pose``."""
    base: Array = Rotation.from_quat(pose[1]).inv().apply(points - pose[0])
    return base


def _sensing_frames(scene: Scene, top: float, samples: int) -> tuple[Array, World]:
    """Tip marker seen in tdcm_base over ``samples`` frames (samples, 3) and the world."""
    world = scene.world()
    tips = np.empty((samples, 3))
    for i in range(samples):
        frame = world.markers(i / scene.mocap_rate_hz, top)
        tips[i] = _to_base(frame.positions[-1:], world.mocap_to_base)[0]
    return tips, world


class _Reference:
    """The scene's own measurements every effect is compared with, each taken once, when first
    needed, including a second timing of the same work (the timing noise)."""

    def __init__(self, scene: Scene, top: float, repeats: int) -> None:
        self.scene, self.top, self.repeats = scene, top, repeats

    @cached_property
    def sweep(self) -> tuple[Array, float]:
        """True tip (m) and wall time per solve (s) of the scene's sweep, after one untimed
        sweep (the process's first solves build caches: 37 ms instead of 0.4 ms per solve)."""
        _sweep(self.scene, 1)
        return _sweep(self.scene, self.repeats)

    @cached_property
    def repeat_solve_s(self) -> float:
        """The wall time per solve of the same sweep, timed again (s)."""
        return _sweep(self.scene, self.repeats)[1]

    @cached_property
    def hold(self) -> tuple[float, float]:
        """True tension (N) and wall time per twin step (s) of the scene's hold."""
        return _twin_hold(self.scene, self.top, self.repeats)

    @cached_property
    def repeat_step_s(self) -> float:
        """The wall time per twin step of the same hold, timed again (s)."""
        return _twin_hold(self.scene, self.top, self.repeats)[1]


def explain(scene: Scene, *, samples: int = 400, repeats: int = 5) -> Explanation:
    """Measure every listed effect (see the module docstring)."""
    top = max(scene.schedule.levels)
    reference = _Reference(scene, top, repeats)
    true_tip, base_solve = reference.sweep
    rows: list[EffectReport] = []
    if scene.true_design.E != scene.design.E:
        nominal_tip, _ = _sweep(scene.with_nominal_material(), 1)
        rows.append(EffectReport(
            "material", "material", 0.0, "solve", float(np.linalg.norm(true_tip - nominal_tip)),
            f"true E {scene.true_design.E / 1e9:.3g} GPa vs nominal {scene.design.E / 1e9:.3g}"
            " GPa"))
    for stage in STAGES:
        for name in scene.effect_names(stage):
            rows.append(_measure(scene, name, reference, samples))
    return Explanation(scene=scene.name, top_tension_n=top, rows=tuple(rows),
                       base_solve_s=base_solve, true_tip_m=tuple(true_tip.tolist()))


def _measure(scene: Scene, name: str, reference: _Reference, samples: int) -> EffectReport:
    cls = REGISTRY[name]
    without = scene.without(name)
    top, repeats = reference.top, reference.repeats
    if cls.stage == "mechanics":
        true_tip, base_solve = reference.sweep
        tip, per_solve = _sweep(without, repeats)
        cost, noise = timed_difference(base_solve, per_solve, reference.repeat_solve_s)
        return EffectReport(name, cls.stage, cost, "solve",
                            float(np.linalg.norm(true_tip - tip)),
                            f"tip deflection {np.hypot(*true_tip[:2]) * 1e3:.3f} mm with, "
                            f"{np.hypot(*tip[:2]) * 1e3:.3f} mm without", noise)
    if cls.stage == "actuation":
        t_with, step_with = reference.hold
        t_without, step_without = _twin_hold(without, top, repeats)
        cost, noise = timed_difference(step_with, step_without, reference.repeat_step_s)
        world = scene.world()
        tip_with = world.solve(t_with).tip_position
        tip_without = world.solve(t_without).tip_position
        return EffectReport(name, cls.stage, cost, "twin step (1 ms)",
                            float(np.linalg.norm(tip_with - tip_without)),
                            f"true tension {t_with:.3f} N with, {t_without:.3f} N without", noise)
    if cls.stage == "sensing":
        tips, world = _sensing_frames(scene, top, samples)
        tips_without, _ = _sensing_frames(without, top, samples)
        effect = next(e for e in world.sensing if e.name == name)
        both = np.all(np.isfinite(tips) & np.isfinite(tips_without), axis=1)
        change = (float(np.sqrt(np.mean(np.sum((tips[both] - tips_without[both]) ** 2, axis=1))))
                  if both.any() else None)
        seen = float(np.mean(np.all(np.isfinite(tips), axis=1)))
        return EffectReport(name, cls.stage, effect.cost_s, cls.cost_unit, change,
                            f"tip marker seen in {seen:.1%} of {samples} frames")
    world = scene.world()
    latency = world.timing[0]
    delays = {topic: [world.delay_s(topic) for _ in range(samples)] for topic in LATENCY_TOPICS}
    note = ", ".join(f"{topic} {np.mean(d) * 1e3:.2f} ms (max {np.max(d) * 1e3:.2f})"
                     for topic, d in delays.items())
    return EffectReport(name, cls.stage, latency.cost_s, "message", None, note)


def _us(seconds: float) -> str:
    """Microseconds with one decimal, or two significant digits between 0 and 1 us."""
    us = seconds * 1e6
    return f"{us:.2g}" if 0.0 < us < 1.0 else f"{us:.1f}"


def format_cost(row: EffectReport) -> str:
    """``"12.3 us"``; a timed difference with its noise, ``"241.9 ± 5.3 us"``, or
    ``"< 0.21 us (below the timing noise)"`` when it is not above the noise."""
    if row.noise_s is None:
        return f"{_us(row.cost_s)} us"
    if row.below_noise:
        return f"< {_us(row.noise_s)} us (below the timing noise)"
    return f"{_us(row.cost_s)} ± {_us(row.noise_s)} us"


def format_table(report: Explanation) -> str:
    """The report as a plain-text table."""
    header = ("effect", "stage", "cost", "per", "tip change (mm)", "note")
    lines = [(row.name, row.stage, format_cost(row), row.cost_unit,
              "-" if row.tip_change_m is None else f"{row.tip_change_m * 1e3:.4f}", row.note)
             for row in report.rows]
    widths = [max(len(str(r[i])) for r in [header, *lines]) for i in range(len(header))]
    tip = ", ".join(f"{v * 1e3:.3f}" for v in report.true_tip_m)
    title = (f"scene {report.scene}: effects measured at the schedule's top tension "
             f"{report.top_tension_n:g} N; base solve {report.base_solve_s * 1e3:.2f} ms; "
             f"true tip (x, y, z) = ({tip}) mm")
    out = [title]
    for row in [header, *lines]:
        out.append("  ".join(str(cell).ljust(w) for cell, w in zip(row, widths, strict=True))
                   .rstrip())
    if not report.rows:
        out.append("(no effects: the world is the paper's base model)")
    return "\n".join(out)
