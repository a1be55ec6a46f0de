"""Streaming form of the evaluation for the live node: samples in, finished steps and running
Table I out, with the same definitions as the offline evaluation.

A tension sample is one tension (N) per tendon of the design (one for the paper's body).
Tension samples and marker frames are buffered; :meth:`RunningEvaluation.update` runs step
detection on the buffer. A step is *finished* once the buffer reaches ``settle_s`` past its end
(the tension left the band); finished steps are averaged, scored against the model and dropped
from the buffer. Trials and phases are assigned over all finished steps at each update, as the
offline evaluation does (from the steps' median levels and the lowest level between steps):
a zero hold after a rise is the trial's unloading until the next rise makes it the start of the
next trial (the running Table I then counts it as loading). The buffer keeps at most
``max_buffer_s`` of data (older samples are dropped when no step finishes, e.g. a long ramp).

Per-frame errors (:meth:`RunningEvaluation.sample_errors`) take the model at the tension
nearest the frame's stamp from a :class:`~tdcm_ros.metrics.lookup.MarkerTable` (one tendon) or
a :class:`~tdcm_ros.metrics.lookup.MarkerLattice` (several tendons).

Roll (issues 18, 33): the per-frame errors (:meth:`RunningEvaluation.sample_errors`) compare
with the model rolled by the roll current at the frame's stamp (:meth:`RunningEvaluation.add_roll`,
:class:`~tdcm_ros.model.RollHistory`, the last :data:`ROLL_SAMPLES` samples kept). A finished
step takes the mean roll over its frames, each frame the roll at its stamp, and is scored in its
bending plane as offline (:mod:`tdcm_ros.metrics.measure`, :mod:`tdcm_ros.metrics.evaluation`):
a step whose roll moved more than ``roll.tolerance_rad`` is left out of Table I.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import TdcmError, out_of_range
from tdcm_ros.metrics.evaluation import (
    StepRecord,
    choose_registration,
    metrics_of,
    score_steps,
)
from tdcm_ros.metrics.lookup import MarkerLattice, MarkerTable
from tdcm_ros.metrics.measure import MeasuredStep, average_markers
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.series import MarkerSeries, RollSeries, TensionSeries
from tdcm_ros.metrics.steps import (
    assign_phases,
    assign_trials,
    detect_steps,
    sample_levels,
)
from tdcm_ros.metrics.table import TableMetrics
from tdcm_ros.mocap import Registration
from tdcm_ros.model import RollHistory, roll_points

Array = NDArray[np.float64]
#: Roll samples kept (the newest): 655 s of a 100 Hz roll, 131 s at 500 Hz (the tension buffer
#: keeps ``max_buffer_s``, 120 s by default).
ROLL_SAMPLES = 65_536


class RunningEvaluation:
    """Running Table I of a live stream; registration given, or (``estimate``) estimated from
    the finished steps once a zero-tension and a bent step exist."""

    def __init__(self, options: EvaluateOptions, registration: Registration | None = None, *,
                 max_buffer_s: float = 120.0, estimate: bool = True) -> None:
        if not (np.isfinite(max_buffer_s) and max_buffer_s > 0.0):
            raise out_of_range("max_buffer_s", max_buffer_s, "(0, inf) s")
        self.options = options
        self.registration = registration
        self.max_buffer_s = float(max_buffer_s)
        self.estimate = estimate
        self.tendons = tuple(t.name for t in options.design.tendon_list())
        self.table: MarkerTable | MarkerLattice = (
            MarkerTable(options.design, options.layout, settings=options.solver)
            if len(self.tendons) == 1 else
            MarkerLattice(options.design, options.layout, settings=options.solver))
        self._t: list[float] = []
        self._x: list[tuple[float, ...]] = []
        self._frame_t: list[float] = []
        self._frames: list[Array] = []
        self.rolls = RollHistory(ROLL_SAMPLES)
        self.measured: list[MeasuredStep] = []
        self._dips: list[float] = []
        self._low_since_step = np.inf
        self.records: list[StepRecord] = []
        self.metrics: TableMetrics | None = None
        self.used_registration: Registration | None = registration
        self.problem = ""

    @property
    def has_markers(self) -> bool:
        """Whether any marker frame or finished step is held."""
        return bool(self._frames or self.measured)

    def restart_markers(self, registration: Registration | None) -> None:
        """Drop the marker frames, the finished steps and the table (markers of another frame)
        and use ``registration`` from now on; the tension and roll samples stay."""
        self._frame_t.clear()
        self._frames.clear()
        self.measured.clear()
        self._dips.clear()
        self.records = []
        self.metrics = None
        self.registration = self.used_registration = registration
        self.problem = ""

    def set_registration(self, registration: Registration) -> None:
        """Use ``registration`` from now on (finished steps are re-scored)."""
        self.registration = self.used_registration = registration
        self._rescore()

    def add_tension(self, stamp_s: float, tension_n: float | Sequence[float]) -> None:
        """One tension sample: stamp (s) and the tension (N), one per tendon of the design in
        its order (a number for one tendon); out-of-order samples are ignored."""
        row = tuple(np.atleast_1d(np.asarray(tension_n, dtype=float)).tolist())
        if len(row) != len(self.tendons):
            raise out_of_range("tension_n", row, f"{len(self.tendons)} values (N): one per "
                               f"tendon ({', '.join(self.tendons)})")
        if self._t and stamp_s <= self._t[-1]:
            return
        self._t.append(float(stamp_s))
        self._x.append(row)

    def add_roll(self, stamp_s: float, roll_rad: float) -> bool:
        """One roll sample (s; rad about the base +z axis); False when out of order (ignored).
        Raises :class:`~tdcm_ros.model.InvalidRollError` unless the roll is finite."""
        return self.rolls.add(float(stamp_s), roll_rad)

    def add_markers(self, stamp_s: float, positions: ArrayLike) -> None:
        """One marker frame (s; (k, 3) m in the markers' frame, NaN rows not visible)."""
        self._frame_t.append(float(stamp_s))
        self._frames.append(np.asarray(positions, dtype=float))

    def tension_at(self, stamp_s: float) -> tuple[float, ...] | None:
        """The buffered tension nearest ``stamp_s`` within the alignment tolerance (N, one per
        tendon)."""
        if not self._t:
            return None
        t = np.asarray(self._t)
        i = int(np.argmin(np.abs(t - stamp_s)))
        return self._x[i] if abs(t[i] - stamp_s) <= self.options.align_tolerance_s else None

    def model_markers(self, tension_n: Sequence[float]) -> Array:
        """The model's marker points (k, 3) m in ``tdcm_base`` at ``tension_n`` (N, one per
        tendon; a negative one is taken as 0), from :attr:`table`."""
        at = np.maximum(np.asarray(tension_n, dtype=float), 0.0)
        return self.table.markers(at[0] if isinstance(self.table, MarkerTable) else at)

    def sample_errors(self, stamp_s: float, positions: ArrayLike) -> Array | None:
        """Measured minus predicted marker points (k, 3) m in ``tdcm_base`` for one frame, the
        model at the aligned tension (:meth:`model_markers`) rolled by the roll at the frame's
        stamp (0 without any); ``None`` without a registration (given or estimated yet) or an
        aligned tension."""
        tension = self.tension_at(stamp_s)
        if tension is None or self.used_registration is None:
            return None
        measured = self.used_registration.to_base(np.asarray(positions, dtype=float))
        predicted = roll_points(self.model_markers(tension), self.rolls.at(stamp_s))
        return measured - predicted

    def update(self) -> list[StepRecord]:
        """Finish the steps that ended; returns their records (Table I updated)."""
        if len(self._t) < 2:
            return []
        t, x = np.asarray(self._t), np.asarray(self._x)
        several = len(self.tendons) > 1
        tension = TensionSeries(t, x if several else x[:, 0], self.tendons if several else ())
        cfg = self.options.steps
        done = [s for s in detect_steps(t, tension.tension_n, cfg)
                if s.end_s < t[-1] - cfg.settle_s]
        if not done:
            self._trim(t[-1] - self.max_buffer_s)
            return []
        levels = sample_levels(x)
        if self._frames:
            markers = MarkerSeries.of(self._frame_t, self.options.layout.labels,
                                      np.asarray(self._frames))
            roll = RollSeries.of(*self.rolls.samples()) if len(self.rolls) else None
            new = average_markers(tension, markers, done, self.options, roll)
        else:
            empty = np.full((len(self.options.layout.labels), 3), np.nan)
            new = [MeasuredStep(s, s.means_n, empty, 0, self.options.layout.labels) for s in done]
        previous_stop = 0
        for step in done:
            between = levels[previous_stop:step.start]
            self._dips.append(min(self._low_since_step,
                                  float(between.min()) if between.size else np.inf))
            self._low_since_step = np.inf
            previous_stop = step.stop
        tail = levels[done[-1].stop:]
        self._low_since_step = float(tail.min()) if tail.size else np.inf
        self.measured.extend(new)
        self._trim(done[-1].end_s, keep_low=True)
        before = len(self.records)
        self._rescore()
        return self.records[before:]

    def _trim(self, until_s: float, keep_low: bool = False) -> None:
        keep = int(np.searchsorted(np.asarray(self._t), until_s, side="right"))
        if not keep_low and keep:
            self._low_since_step = min(self._low_since_step,
                                       float(sample_levels(self._x[:keep]).min()))
        del self._t[:keep], self._x[:keep]
        first = int(np.searchsorted(np.asarray(self._frame_t),
                                    until_s - self.options.align_tolerance_s, side="right"))
        del self._frame_t[:first], self._frames[:first]

    def _rescore(self) -> None:
        if not self.measured:
            return
        if self.registration is None and not self.estimate:
            self.problem = "waiting for a registration (estimation off)"
            return
        try:
            reg = self.registration or choose_registration(self.measured, self.options, None)
        except TdcmError as error:
            self.problem = f"waiting for a registration: {error}"
            return
        records, warnings = score_steps(self.measured, reg, self.options)
        trials = assign_trials([m.step.median_n for m in self.measured], self._dips,
                               self.options.steps.zero_n)
        phases = assign_phases([m.step.medians_n for m in self.measured], trials,
                               self.options.steps.tolerance_n)
        self.records = [replace(r, trial=k + 1, phase=phase)
                        for r, k, phase in zip(records, trials, phases, strict=True)]
        self.metrics = metrics_of(self.records, self.options)
        self.used_registration = reg
        self.problem = warnings[-1] if warnings else ""
