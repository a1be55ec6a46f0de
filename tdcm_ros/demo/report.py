"""After the run: evaluate the demo's bag, write plots and JSON, calibrate E, show the metrics after
(a tracking run: :func:`tracking_report`)."""

from __future__ import annotations

import json
from itertools import pairwise
from pathlib import Path
from typing import Any

from tdcm_ros.demo.plan import DemoPlan
from tdcm_ros.metrics import (
    EvaluateOptions,
    Evaluation,
    MarkerLayout,
    settings_for_hold,
)
from tdcm_ros.model import Progress
from tdcm_ros.scenes import CircleTrajectory


def scene_options(plan: DemoPlan) -> EvaluateOptions:
    """Evaluation options matching the run: the estimator's design, the marker layout and step
    settings derived from the schedule's hold time (:func:`settings_for_hold`)."""
    scene = plan.scene
    layout = MarkerLayout(
        labels=tuple(scene.marker_labels), arc_lengths=tuple(scene.marker_arc_lengths),
        ball_radius=scene.marker_ball_radius, side_deg=scene.marker_side_deg,
        radial_offset=scene.marker_radial_offset)
    return EvaluateOptions(design=scene.design, steps=settings_for_hold(plan.schedule.hold),
                           layout=layout)


def missed_holds(plan: DemoPlan, evaluation: Evaluation) -> str:
    """A warning when the evaluation found fewer loading steps than the schedule holds (the
    step settings did not fit the run), else ``""``."""
    scheduled = len(plan.schedule.levels) * plan.schedule.trials
    found = sum(r.phase == "loading" for r in evaluation.records)
    if found >= scheduled:
        return ""
    steps = evaluation.options.steps
    return (f"warning: found {found} of the schedule's {scheduled} holds (steps.min_hold_s = "
            f"{steps.min_hold_s:g} s, steps.settle_s = {steps.settle_s:g} s, steps.tolerance_n "
            f"= {steps.tolerance_n:g} N); adjust them with --set steps.<name>=VALUE")


def fitted_names(plan: DemoPlan) -> tuple[str, ...]:
    """What the demo calibrates: E, and the tendon's friction ``mu`` where the scene has
    friction and its schedule unloads (the unloading steps' hysteresis is what tells ``mu``
    from ``E``; on loading steps alone the fit cannot, see :mod:`tdcm_ros.metrics.calibration`)."""
    levels = list(plan.schedule.levels)
    unloads = any(later < earlier for earlier, later in pairwise(levels))
    return ("E", "mu") if unloads and "tendon_friction" in plan.scene.effect_names() else ("E",)


def report(plan: DemoPlan, options: EvaluateOptions, *, calibrate: bool,
           progress: Progress | None = None) -> None:
    """Print Table I and the per-step table of the bag evaluated with ``options`` (see
    :func:`scene_options`), write ``plots/`` and ``metrics.json``; calibrate. ``progress``
    follows the reading, the fit and the evaluations (see ``calibrate_paths``)."""
    from tdcm_ros.metrics import (
        format_calibration,
        format_evaluation,
        write_calibration_plots,
        write_plots,
    )
    from tdcm_ros.metrics.api import evaluate_paths

    fit = None
    names = fitted_names(plan)
    if calibrate:
        from tdcm_ros.metrics.api import calibrate_paths

        fit = calibrate_paths([plan.bag], names, options,  # its `before` is the evaluation
                              progress=progress)
    evaluation = fit.before if fit is not None else evaluate_paths([plan.bag], options,
                                                                   progress=progress)
    print(f"\n== evaluation of {plan.bag} (estimator: scene {plan.scene.name!r} nominal design) ==")
    print(format_evaluation(evaluation))
    if warning := missed_holds(plan, evaluation):
        print(warning)
    for path in write_plots(evaluation, plan.out / "plots"):
        print(f"plot written to {path}")
    results = {"scene": plan.scene.name, "before_calibration": evaluation.to_json()}
    if fit is not None:
        print(f"\n== calibration of {' and '.join(names)} on {plan.bag} (start: the scene's "
              f"nominal E{', no friction' if 'mu' in names else ''}) ==")
        print(format_calibration(fit))
        results["calibration"] = fit.fit_json()
        results["after_calibration"] = fit.after.to_json()
        for path in write_calibration_plots(fit, plan.out / "plots"):
            print(f"plot written to {path}")
    path = plan.out / "metrics.json"
    path.write_text(json.dumps(results, indent=2), encoding="utf-8")
    print(f"metrics written to {path}")


def tracking_report(bag: Path, circle: CircleTrajectory, out: Path, scene_name: str, *,
                    world_gain: float | None = None) -> dict[str, Any]:
    """A tracking run's report (:mod:`tdcm_ros.demo.tracking_report`): read ``bag``, print the
    phases' errors, write ``out/plots/tracking_*.png`` and ``out/metrics.json``; returns what
    was written to the JSON. ``world_gain`` is the scene's ``E_model / E_world`` (what the
    controller's ``gain`` estimates), shown beside it."""
    from tdcm_ros.demo.tracking_plots import write_tracking_plots
    from tdcm_ros.demo.tracking_report import format_phases, phase_errors, read_tracking

    record = read_tracking(bag)
    errors = phase_errors(record, circle)
    print(f"\n== tracking error of {bag}: |measured - target| of the tip (3D), each phase after "
          f"its first {circle.settle:g} s ==")
    print(format_phases(errors))
    for path in write_tracking_plots(record, errors, circle, out / "plots",
                                     world_gain=world_gain):
        print(f"plot written to {path}")
    results: dict[str, Any] = {
        "scene": scene_name, "trajectory": circle.to_dict(),
        "tracking": {e.phase: e.to_json() for e in errors},
        "samples": {"targets": len(record.targets), "measured": len(record.measured),
                    "predicted": len(record.predicted)}}
    if record.gain is not None:
        results["final_gain"] = float(record.gain[1][-1])
        print(f"controller gain at the end: {results['final_gain']:.4f}"
              + ("" if record.gain_std is None else f" +- {float(record.gain_std[1][-1]):.4f}")
              + ("" if world_gain is None else f" (the scene's E_model / E_world: "
                                               f"{world_gain:.4f})"))
    if record.gain_std is not None:
        results["final_gain_std"] = float(record.gain_std[1][-1])
    if world_gain is not None:
        results["world_gain"] = world_gain
    path = out / "metrics.json"
    path.write_text(json.dumps(results, indent=2), encoding="utf-8")
    print(f"metrics written to {path}")
    return results
