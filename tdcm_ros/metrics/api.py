"""Public entry points: evaluate (and calibrate, :mod:`tdcm_ros.metrics.calibration`) bags.

::

    from tdcm_ros.metrics.api import evaluate_paths
    from tdcm_ros.metrics.options import options_from_sets
    ev = evaluate_paths(["run.mcap"], options_from_sets(["E=0.7e9"]))
    ev.metrics.rmse_m, ev.to_json()
    cal = calibrate_paths(["run.mcap"], ["E"])
    cal.parameters[0].value, cal.parameters[0].ci_low, cal.after.metrics
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from tdcm_ros.errors import InputError
from tdcm_ros.metrics.bagdata import BagSource, load_bag
from tdcm_ros.metrics.evaluation import (
    Evaluation,
    choose_registration,
    combine,
    evaluate_steps,
)
from tdcm_ros.metrics.measure import MeasuredStep, measure_steps
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.mocap import Registration
from tdcm_ros.model import Progress, report_progress

if TYPE_CHECKING:
    from tdcm_ros.metrics.calibration import Calibration

ESTIMATED_REGISTRATION_NOTE = (
    "the intervals leave out the registration's error: it was estimated from the markers, so "
    "its error is shared by every step rather than independent (a bag with /tf_static mocap -> "
    "tdcm_base, or a given registration, gives intervals that hold)")
"""Said with a calibration whose registration was estimated (the intervals assume it exact)."""


@dataclass(frozen=True)
class Topics:
    """Topic names read from the bags: ``tension`` one topic, or ``NAME=TOPIC`` values, one per
    tendon of the body (:mod:`tdcm_ros.metrics.tension_topics`), ``markers``, and
    ``joint_states`` whose joint ``roll_joint`` is the roll (rad; topic absent: roll 0)."""

    tension: str | tuple[str, ...] = "tension"
    markers: str = "markers"
    joint_states: str = "joint_states"
    roll_joint: str = "roll"


@dataclass(frozen=True)
class _BagNotes:
    """What an evaluation reports of a bag besides its steps: its path, reading warnings and
    occluded marker positions per label (a :class:`BagSource` without its series)."""

    path: Path
    warnings: tuple[str, ...]
    occluded: dict[str, int]

    @classmethod
    def of(cls, source: BagSource) -> _BagNotes:
        return cls(source.path, source.warnings, source.occluded)


def load_paths(paths: Sequence[str | Path], options: EvaluateOptions,
               topics: Topics | None = None, progress: Progress | None = None
               ) -> list[BagSource]:
    """Read every bag (in order); at least one path. ``progress``: stage ``reading bags``."""
    if not paths:
        raise InputError("no bag given; allowed: one or more bag folders or .mcap files",
                         parameter="BAG", value=[], allowed="one or more paths")
    names = topics or Topics()
    tendons = [t.name for t in options.design.tendon_list()]
    sources = []
    for done, path in enumerate(paths):
        report_progress(progress, "reading bags", done, len(paths))
        sources.append(load_bag(path, labels=options.layout.labels, tension_topic=names.tension,
                                markers_topic=names.markers, tendons=tendons,
                                align_tolerance_s=options.align_tolerance_s,
                                joint_states_topic=names.joint_states,
                                roll_joint=names.roll_joint))
    report_progress(progress, "reading bags", len(paths), len(paths))
    return sources


def prepare(sources: Sequence[BagSource], options: EvaluateOptions,
            registration: Registration | None = None
            ) -> list[tuple[list[MeasuredStep], Registration]]:
    """Measured steps of each bag with the registration it uses: ``registration``, else the
    bag's ``/tf_static``, else an estimate from its zero-tension and largest-tension steps."""
    prepared = []
    for source in sources:
        steps = measure_steps(source.tension, source.markers, options, source.roll)
        prepared.append((steps, choose_registration(
            steps, options, registration or source.registration)))
    return prepared


def evaluate_sources(sources: Sequence[BagSource], options: EvaluateOptions,
                     registration: Registration | None = None) -> Evaluation:
    """Evaluate loaded bags (see :func:`prepare` for the registration)."""
    return _evaluate([_BagNotes.of(s) for s in sources], prepare(sources, options, registration),
                     options)


def _evaluate(sources: Sequence[_BagNotes],
              prepared: Sequence[tuple[list[MeasuredStep], Registration]],
              options: EvaluateOptions) -> Evaluation:
    parts = []
    for source, (steps, reg) in zip(sources, prepared, strict=True):
        part = evaluate_steps(steps, reg, options)
        parts.append(Evaluation(part.records, part.metrics, part.registrations, options,
                                (*(f"{source.path}: {w}" for w in source.warnings),
                                 *(f"{source.path}: {w}" for w in part.warnings)),
                                occluded=source.occluded))
    return combine(parts, [str(s.path) for s in sources])


def evaluate_paths(paths: Sequence[str | Path], options: EvaluateOptions | None = None, *,
                   topics: Topics | None = None, registration: Registration | None = None,
                   progress: Progress | None = None) -> Evaluation:
    """Evaluate bags (rosbag2 folders or ``.mcap`` files) against the model of
    ``options.design``; see :class:`~tdcm_ros.metrics.evaluation.Evaluation`.
    ``progress``: stage ``reading bags``. The bags' series are dropped once their steps are
    measured: the model runs without them in memory."""
    opts = options or EvaluateOptions()
    notes, prepared = _measured(paths, opts, topics, registration, progress)
    return _evaluate(notes, prepared, opts)


def _measured(paths: Sequence[str | Path], opts: EvaluateOptions, topics: Topics | None,
              registration: Registration | None, progress: Progress | None
              ) -> tuple[list[_BagNotes], list[tuple[list[MeasuredStep], Registration]]]:
    """Each bag's notes and its measured steps with their registration (:func:`prepare`); the
    bags' series are dropped on return: the model runs without them in memory."""
    sources = load_paths(paths, opts, topics, progress)
    prepared = prepare(sources, opts, registration)
    return [_BagNotes.of(s) for s in sources], prepared


def calibrate_paths(paths: Sequence[str | Path], fit: Sequence[str] = ("E",),
                    options: EvaluateOptions | None = None, *, topics: Topics | None = None,
                    registration: Registration | None = None, confidence: float = 0.95,
                    hold_out: int = 0, progress: Progress | None = None) -> Calibration:
    """Fit the design fields and friction ``fit`` (start: ``options.design`` and
    ``options.friction_mu``) to the bags' marker positions by least squares; see
    :mod:`tdcm_ros.metrics.calibration`. ``hold_out``: the last so many trials of each bag are
    not fitted but evaluated with the fitted model (:attr:`.Calibration.held_out`: Table I and
    the band's coverage on steps the fit never saw). ``progress``: stages ``reading bags``,
    ``fitting NAMES`` (model evaluations) and ``Table I before and after`` (2)."""
    # on use only: evaluating never loads the fit's scipy.optimize
    from tdcm_ros.metrics.calibration import Calibration, calibrate_steps

    opts = options or EvaluateOptions()
    notes, measured = _measured(paths, opts, topics, registration, progress)
    prepared, held = split_trials(notes, measured, hold_out)
    fitted, params, corr, condition, rms, count, warnings = calibrate_steps(
        prepared, fit, opts, confidence=confidence, progress=progress)
    estimated = [ESTIMATED_REGISTRATION_NOTE] if any(
        reg.method == "estimated" for _, reg in prepared) else []
    report_progress(progress, "Table I before and after", 0, 2)
    before = _evaluate(notes, prepared, opts)
    report_progress(progress, "Table I before and after", 1, 2)
    after = _evaluate(notes, prepared, fitted)
    report_progress(progress, "Table I before and after", 2, 2)
    return Calibration(tuple(params), confidence, corr, condition, rms, count, not warnings,
                       before, after, tuple(warnings),
                       _evaluate(notes, held, fitted) if hold_out else None, tuple(estimated))


def split_trials(sources: Sequence[_BagNotes],
                 prepared: Sequence[tuple[list[MeasuredStep], Registration]], hold_out: int
                 ) -> tuple[list[tuple[list[MeasuredStep], Registration]],
                            list[tuple[list[MeasuredStep], Registration]]]:
    """Each bag's steps split into those fitted and those of its last ``hold_out`` trials."""
    if hold_out < 0:
        raise InputError(f"--hold-out {hold_out}; allowed: 0 or more trials",
                         parameter="--hold-out", value=hold_out, allowed="[0, inf)")
    if not hold_out:
        return list(prepared), []
    fitted, held = [], []
    for source, (steps, reg) in zip(sources, prepared, strict=True):
        trials = sorted({m.step.trial for m in steps})
        if len(trials) <= hold_out:
            raise InputError(f"--hold-out {hold_out} leaves no trial to fit in {source.path} "
                             f"({len(trials)} trials); allowed: fewer than {len(trials)}",
                             parameter="--hold-out", value=hold_out,
                             allowed=f"[0, {len(trials) - 1}]")
        first_held = trials[-hold_out]
        fitted.append(([m for m in steps if m.step.trial < first_held], reg))
        held.append(([m for m in steps if m.step.trial >= first_held], reg))
    return fitted, held
