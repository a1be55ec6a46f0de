"""Evaluation: measured steps against the model re-run at each step's mean tension (one per
tendon for a body with several).

Per step: the measured markers in its bending plane, the model's markers at the same surface
points (:func:`tdcm_ros.model.surface_points`), both tip deflections and the shape error;
then Table I (:mod:`tdcm_ros.metrics.table`) over the loading steps; the unloading steps
(:mod:`tdcm_ros.metrics.steps`) get the same metrics separately. A step is *flagged* (left out of every metric,
kept in the per-step table with a note) when its tip marker was never visible, the model has
no solution at its tension or its roll moved more than ``roll.tolerance_rad`` within it.

Roll: a step taken with the body rolled by ``phi`` (rad about the base +z axis, the step's mean
roll, :mod:`tdcm_ros.metrics.measure`) bends in ``tdcm_base``'s x-z plane turned by ``phi``. Its
measured markers are turned back by ``-phi`` (:func:`plane_markers`) into the planar model's
frame, ``tdcm_base`` itself at roll 0, and compared there: the deflection along
``deflection_axis`` and the shape error are those of the rolled bending plane, so a body at roll
``phi`` scores as the same body at roll 0. A registration estimated from steps at a roll is
turned to match (:func:`choose_registration`).

Friction (``options.friction_mu`` above 0): a recording's steps are solved in the order they
happened, each after the ones before it (:class:`~tdcm_ros.model.FrictionTrack`: stick-slip
capstan friction, so an unloading step is predicted above the loading one at the same level).

Band (``options.uncertainty``, a calibration's covariance): each predicted marker gets its
prediction covariance (:mod:`tdcm_ros.model.uncertainty`, linearised through the solver, plus
the fit's residual variance); :attr:`Evaluation.band` counts the measured markers inside their
95 % ellipsoid (the band's calibration: about 95 % when the model and its covariance hold).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import TdcmError
from tdcm_ros.metrics.geometry import deflection, measured_midline, station_distance
from tdcm_ros.metrics.measure import MeasuredStep, measure_steps
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.series import MarkerSeries, RollSeries, TensionSeries
from tdcm_ros.metrics.steps import LOADING, UNLOADING
from tdcm_ros.metrics.table import TableMetrics, table_metrics
from tdcm_ros.mocap import (
    Registration,
    RegistrationError,
    estimate_registration,
)
from tdcm_ros.model import (
    Design,
    FrictionTrack,
    SolveResult,
    inside_band,
    linearised_covariances,
    prediction_covariances,
    roll_points,
    surface_points,
)

Array = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class Prediction:
    """The model at one tension: markers (k, 3) and midline at the stations (m, 3), m."""

    result: SolveResult
    markers: Array
    midline: Array


#: Confidence of the band whose coverage an evaluation reports.
BAND_CONFIDENCE = 0.95


def predict(design: Design, tensions_n: Sequence[float], options: EvaluateOptions,
            warm_start: SolveResult | None = None, track: FrictionTrack | None = None
            ) -> Prediction:
    """Solve ``design`` at ``tensions_n`` (N, one per tendon) after ``track``'s history (none:
    a fresh track of ``options.friction_mu``; the caller advances it) and take the marker
    points and midline stations."""
    track = track or FrictionTrack(options.friction_mu)
    result = track.solve_at(design, solve_tension(tensions_n), settings=options.solver,
                            warm_start=warm_start)
    return Prediction(result, marker_points(result, design, options),
                      result.pose_at(stations(options))[0])


def marker_points(result: SolveResult, design: Design, options: EvaluateOptions) -> Array:
    """The marker points (k, 3) m of ``result`` (of ``design``) in ``tdcm_base``."""
    layout = options.layout
    return surface_points(result, layout.s, layout.radius(design.R_outer), layout.side_rad)[0]


def band_inside(measured: Array, tensions_n: Sequence[float], prediction: Prediction,
                track: FrictionTrack, options: EvaluateOptions) -> NDArray[np.bool_]:
    """Per visible marker of ``measured`` (k, 3) m: inside the prediction's
    :data:`BAND_CONFIDENCE` band (``options.uncertainty`` carried through the solver after
    ``track``'s history, the prediction's)."""
    uncertainty = options.uncertainty
    assert uncertainty is not None
    tension = solve_tension(tensions_n)

    def markers_at(design: Design, mu: float) -> Array:
        moved = track.solve_at(design, tension, mu=mu, settings=options.solver,
                               warm_start=prediction.result)
        return marker_points(moved, design, options)

    covariances = prediction_covariances(linearised_covariances(
        markers_at, options.design, track.mu, uncertainty, prediction.markers),
        uncertainty.residual_m)
    seen = ~np.isnan(measured[:, 0])
    return inside_band(measured[seen] - prediction.markers[seen], covariances[seen],
                       BAND_CONFIDENCE)


def solve_tension(tensions_n: Sequence[float]) -> float | list[float]:
    """``tensions_n`` (N, one per tendon) as :func:`~tdcm_ros.model.solve` takes them: the number
    itself for one tendon (its errors name ``tension``), else the list."""
    return float(tensions_n[0]) if len(tensions_n) == 1 else [float(t) for t in tensions_n]


def stations(options: EvaluateOptions) -> Array:
    """Arc-length stations (m) of the shape error: base to the tip marker."""
    return np.linspace(0.0, options.layout.arc_lengths[-1], options.stations)


#: Table I's keys at the head of :meth:`Evaluation.to_json` (the rest go to its ``details``).
TABLE_KEYS = ("mape_pct", "rmse_m", "mae_m", "shape_error_m", "deflection_mean_m", "n_trials",
              "n_steps")


@dataclass(frozen=True, eq=False)
class StepRecord:
    """One step of the evaluation (SI units; markers and midlines in the step's bending plane:
    ``tdcm_base`` turned by ``roll_rad`` about +z, ``plane_markers``); ``trial`` counts from
    1, ``phase`` is ``loading`` or ``unloading``; ``tensions_n`` the step's mean tension by tendon
    name (N, the body file's order); ``roll_rad`` its mean roll (rad)."""

    trial: int
    tensions_n: dict[str, float]
    start_s: float
    end_s: float
    frames: int
    measured_markers: Array
    predicted_markers: Array | None
    measured_deflection_m: float | None
    predicted_deflection_m: float | None
    shape_error_m: float | None
    measured_midline: Array | None
    predicted_midline: Array | None
    missing: tuple[str, ...]
    note: str
    phase: str = LOADING
    inside_band: NDArray[np.bool_] | None = None
    """Per visible marker: inside the predicted 95 % band (None: no band)."""
    roll_rad: float = 0.0

    @property
    def usable(self) -> bool:
        """Both tip deflections exist: the step counts in the metrics."""
        return self.measured_deflection_m is not None and self.predicted_deflection_m is not None

    @property
    def tension_n(self) -> float:
        """The step's level: its largest tension (N), the tension itself for one tendon (Table
        I's highest-tension step per trial)."""
        return max(self.tensions_n.values())

    def to_json(self) -> dict[str, Any]:
        """``trial``, ``phase``, ``tension_n`` (one tendon) or ``tensions_n`` (several: N by
        tendon name), ``measured_deflection_m`` and ``predicted_deflection_m`` (tip), extras;
        units in the keys."""
        tension = {"tension_n": self.tension_n} if len(self.tensions_n) == 1 else {
            "tensions_n": dict(self.tensions_n)}
        return {"trial": self.trial, "phase": self.phase, **tension,
                "measured_deflection_m": self.measured_deflection_m,
                "predicted_deflection_m": self.predicted_deflection_m,
                "shape_error_m": self.shape_error_m, "start_s": self.start_s,
                "end_s": self.end_s, "frames": self.frames, "missing_markers": list(self.missing),
                "note": self.note}


@dataclass(frozen=True, eq=False)
class Evaluation:
    """Per-step records, Table I (of the loading steps), the registration used per source, any
    warnings and the occluded marker positions (NaN or exactly zero, left out) per label."""

    records: tuple[StepRecord, ...]
    metrics: TableMetrics
    registrations: tuple[Registration, ...]
    options: EvaluateOptions
    warnings: tuple[str, ...] = ()
    sources: tuple[str, ...] = ("arrays",)
    occluded: dict[str, int] = field(default_factory=dict)

    @property
    def band(self) -> tuple[int, int] | None:
        """Measured markers inside their predicted 95 % band, and markers compared (steps
        with a prediction); None without an uncertainty."""
        flags = [r.inside_band for r in self.records if r.inside_band is not None]
        if self.options.uncertainty is None or not flags:
            return None
        return int(sum(int(f.sum()) for f in flags)), int(sum(f.size for f in flags))

    @property
    def unloading(self) -> TableMetrics | None:
        """The Table I metrics of the unloading steps (``None`` if there is none)."""
        if not any(r.phase == UNLOADING for r in self.records):
            return None
        return metrics_of(self.records, self.options, phase=UNLOADING)

    def hysteresis_m(self) -> list[float | None]:
        """Per record: for an unloading step, its measured tip deflection minus that of the
        same trial's loading step nearest in tension (the largest difference over the tendons)
        with every tendon within ``2 steps.tolerance_n`` (the same level), in m; ``None`` for
        loading steps and where no such pair was measured."""
        band = 2.0 * self.options.steps.tolerance_n
        loading = [r for r in self.records
                   if r.phase == LOADING and r.measured_deflection_m is not None]
        out: list[float | None] = []
        for r in self.records:
            pairs = [p for p in loading if p.trial == r.trial
                     and tension_distance(p.tensions_n, r.tensions_n) <= band]
            if r.phase != UNLOADING or r.measured_deflection_m is None or not pairs:
                out.append(None)
                continue
            pair = min(pairs, key=lambda p: tension_distance(p.tensions_n, r.tensions_n))
            out.append(r.measured_deflection_m - float(pair.measured_deflection_m or 0.0))
        return out

    def to_json(self) -> dict[str, Any]:
        """The ``--json`` document, each number once with its unit in its key: Table I of the
        loading steps first, then ``steps`` (each with ``hysteresis_m``, :meth:`hysteresis_m`),
        ``unloading`` (Table I of the unloading steps, or null) and ``details`` (the rest of
        Table I's counts, the registrations, the design, warnings)."""
        m, unloading = self.metrics, self.unloading
        table = m.to_dict()
        head = {key: table.pop(key) for key in TABLE_KEYS}
        return {**head,
                "steps": [{**r.to_json(), "hysteresis_m": h}
                          for r, h in zip(self.records, self.hysteresis_m(), strict=True)],
                "unloading": None if unloading is None else unloading.to_dict(),
                "band": self.band_json(),
                "details": {**table, "sources": [
                    {"source": name, "registration": registration_json(reg)}
                    for name, reg in zip(self.sources, self.registrations, strict=True)],
                            "design": self.options.design.to_dict(),
                            "deflection_axis": self.options.deflection_axis,
                            "occluded_markers": dict(self.occluded),
                            "warnings": list(self.warnings)}}


    def band_json(self) -> dict[str, Any] | None:
        """``confidence``, ``inside``, ``markers`` and ``coverage`` of :attr:`band`, or None."""
        band = self.band
        if band is None:
            return None
        inside, markers = band
        return {"confidence": BAND_CONFIDENCE, "inside": inside, "markers": markers,
                "coverage": inside / markers if markers else None}


def tension_distance(a: Mapping[str, float], b: Mapping[str, float]) -> float:
    """The largest difference (N) between two steps' tensions of the same tendons."""
    return max(abs(a[name] - b[name]) for name in a)


def tensions_text(tensions_n: Mapping[str, float]) -> str:
    """A step's tensions in words: ``8.026 N`` for one tendon, else ``flexor 8.026 N, extensor
    0.012 N``."""
    if len(tensions_n) == 1:
        return f"{next(iter(tensions_n.values())):.3f} N"
    return ", ".join(f"{name} {value:.3f} N" for name, value in tensions_n.items())


def registration_json(reg: Registration) -> dict[str, Any]:
    """The registration as JSON: method, translation (m), quaternion (x, y, z, w), residual."""
    return {"method": reg.method, "translation_m": list(reg.translation),
            "quaternion_xyzw": list(reg.quaternion), "residual_m": reg.residual_m}


def choose_registration(steps: Sequence[MeasuredStep], options: EvaluateOptions,
                        given: Registration | None) -> Registration:
    """``given`` if any, else estimated from the highest step with every marker visible that
    has a zero-tension step (at most ``steps.zero_n``) at its roll (within
    ``roll.tolerance_rad``), and the lowest such zero-tension step; steps whose roll moved
    (:func:`roll_note`) are left out. The estimate, made in their bending plane, is turned by
    their roll into ``tdcm_base``."""
    if given is not None:
        return given
    complete = [m for m in steps if not m.missing and not roll_note(m, options)]
    zero = [m for m in complete if m.tension_n <= options.steps.zero_n]

    def at_roll_of(step: MeasuredStep) -> list[MeasuredStep]:
        return [m for m in zero if abs(m.roll_rad - step.roll_rad) <= options.roll_tolerance_rad]

    bent = max((m for m in complete if at_roll_of(m)), key=lambda m: m.tension_n, default=None)
    if bent is None:
        raise RegistrationError(
            "no registration given (no /tf_static mocap -> tdcm_base) and no zero-tension step "
            f"(<= steps.zero_n = {options.steps.zero_n:g} N) with every marker visible to "
            "estimate it", parameter="registration", value=None,
            allowed="a mocap -> tdcm_base transform or a zero-tension hold")
    rest = min(at_roll_of(bent), key=lambda m: m.tension_n)
    layout = options.layout
    plane = estimate_registration(rest.markers, layout.s,
                                  radius=layout.radius(options.design.R_outer),
                                  side_rad=layout.side_rad, bent_markers=bent.markers)
    return rolled_registration(plane, bent.roll_rad)


def rolled_registration(plane: Registration, roll_rad: float) -> Registration:
    """``mocap`` -> ``tdcm_base`` from ``plane``, the registration onto the bending plane of a
    body rolled by ``roll_rad`` (rad about +z): its rotation ``R`` becomes ``R R_z(-roll)``;
    ``plane`` itself at roll 0."""
    if roll_rad == 0.0:
        return plane
    rotation = roll_points(plane.rotation, roll_rad)  # each row turned: R R_z(-roll)
    return Registration.from_matrix(rotation, plane.translation, method=plane.method,
                                    residual_m=plane.residual_m)


def plane_markers(step: MeasuredStep, registration: Registration) -> Array:
    """The step's mean markers (k, 3) m in its bending plane: moved into ``tdcm_base`` and
    turned back by its roll (-``roll_rad`` about +z), the frame of the planar model."""
    return roll_points(registration.to_base(step.markers), -step.roll_rad)


def roll_note(step: MeasuredStep, options: EvaluateOptions) -> str:
    """Why the step is left out for its roll (it moved more than ``roll.tolerance_rad`` over
    the step's frames), or ``""``."""
    if step.roll_spread_rad <= options.roll_tolerance_rad:
        return ""
    return (f"roll moved {step.roll_spread_rad:.4g} rad within the step (allowed: at most "
            f"roll.tolerance_rad = {options.roll_tolerance_rad:g} rad)")


def model_tensions(tensions_n: Sequence[float], options: EvaluateOptions) -> tuple[float, ...]:
    """The tensions (N, one per tendon) the model runs at: a mean within
    ``steps.tolerance_n`` below zero is load-cell noise around zero and becomes 0."""
    return tuple(0.0 if -options.steps.tolerance_n <= t < 0.0 else t for t in tensions_n)


def score_steps(steps: Sequence[MeasuredStep], registration: Registration,
                options: EvaluateOptions) -> tuple[list[StepRecord], list[str]]:
    """Per-step records against the model of ``options.design``; warnings for flagged steps."""
    design = options.design
    names = [t.name for t in design.tendon_list()]
    offset = options.layout.rest_offset(design.R_outer)
    radius = options.layout.radius(design.R_outer)
    at = stations(options)
    records: list[StepRecord] = []
    warnings: list[str] = []
    warm: SolveResult | None = None
    track = FrictionTrack(options.friction_mu)
    for measured in steps:
        base = plane_markers(measured, registration)
        tensions = dict(zip(names, measured.tensions_n, strict=True))
        note, pred, inside = "", None, None
        try:
            level = model_tensions(measured.tensions_n, options)
            pred = predict(design, level, options, warm, track)
            warm = pred.result
            if options.uncertainty is not None:
                inside = band_inside(base, level, pred, track, options)
            track.state.advance(pred.result)
        except TdcmError as error:
            note = f"model: {error}"
        rolled = roll_note(measured, options)
        tip_seen = not np.isnan(base[-1, 0])
        note = note or rolled or (
            "" if tip_seen else f"tip marker {options.layout.labels[-1]} not visible")
        seen = tip_seen and not rolled  # one measurement at one roll
        midline = measured_midline(base, options.layout, radius, at) if seen else None
        if note:
            warnings.append(f"trial {measured.step.trial + 1} step at "
                            f"{tensions_text(tensions)} left out: {note}")
        records.append(StepRecord(
            trial=measured.step.trial + 1, tensions_n=tensions,
            start_s=measured.step.start_s, end_s=measured.step.end_s, frames=measured.frames,
            measured_markers=base, predicted_markers=None if pred is None else pred.markers,
            measured_deflection_m=float(deflection(base[-1], offset, options.deflection_axis))
            if seen else None,
            predicted_deflection_m=None if pred is None else float(
                deflection(pred.markers[-1], offset, options.deflection_axis)),
            shape_error_m=None if pred is None or midline is None else station_distance(
                midline, pred.midline),
            measured_midline=midline, predicted_midline=None if pred is None else pred.midline,
            missing=measured.missing, note=note, phase=measured.step.phase,
            inside_band=None if rolled else inside, roll_rad=measured.roll_rad))
    return records, warnings



def metrics_of(records: Sequence[StepRecord], options: EvaluateOptions, *,
               phase: str = LOADING) -> TableMetrics:
    """Table I of the records of ``phase`` (default: the loading steps, the paper's protocol)."""
    def col(values: list[float | None]) -> Array:
        return np.array([np.nan if v is None else v for v in values], dtype=float)

    records = [r for r in records if r.phase == phase]
    return table_metrics(
        [r.trial for r in records], [r.tension_n for r in records],
        col([r.measured_deflection_m if r.usable else None for r in records]),
        col([r.predicted_deflection_m if r.usable else None for r in records]),
        col([r.shape_error_m for r in records]), mape_threshold_m=options.mape_threshold_m)


def evaluate_series(tension: TensionSeries, markers: MarkerSeries,
                    options: EvaluateOptions | None = None,
                    registration: Registration | None = None,
                    roll: RollSeries | None = None) -> Evaluation:
    """Evaluate one recording given as arrays. ``registration`` maps the markers' frame to
    ``tdcm_base``; ``None`` estimates it from the data (see :func:`.choose_registration`).
    ``roll``: the body's roll (``None``: 0 throughout)."""
    opts = options or EvaluateOptions()
    steps = measure_steps(tension, markers, opts, roll)
    return evaluate_steps(steps, choose_registration(steps, opts, registration), opts)


def evaluate_steps(steps: Sequence[MeasuredStep], registration: Registration,
                   options: EvaluateOptions) -> Evaluation:
    """Evaluate measured steps (markers in the registration's parent frame)."""
    records, warnings = score_steps(steps, registration, options)
    return Evaluation(tuple(records), metrics_of(records, options), (registration,), options,
                      tuple(warnings))


def combine(parts: Sequence[Evaluation], sources: Sequence[str]) -> Evaluation:
    """One evaluation of several recordings (same options): trials numbered on across them."""
    records: list[StepRecord] = []
    offset = 0
    for part in parts:
        records.extend(replace(r, trial=r.trial + offset) for r in part.records)
        offset = max((r.trial for r in records), default=offset)
    opts = parts[0].options
    occluded: dict[str, int] = {}
    for part in parts:
        for label, count in part.occluded.items():
            occluded[label] = occluded.get(label, 0) + count
    return Evaluation(tuple(records), metrics_of(records, opts),
                      tuple(r for p in parts for r in p.registrations), opts,
                      tuple(w for p in parts for w in p.warnings), tuple(sources), occluded)
