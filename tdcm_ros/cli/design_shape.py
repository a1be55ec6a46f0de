"""``tdcm design --problem FILE``: design a pattern for a shape (per-notch variables, shape
targets, limits; :mod:`tdcm_ros.model.shape_file`), and export what it finds."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from tdcm_ros.cli.progress import ProgressBars
from tdcm_ros.errors import InputError, TdcmError
from tdcm_ros.model import (
    NoShapeDesignError,
    ShapeDesign,
    body_file_text,
    design_for_shape,
    mesh_body_file_text,
    read_problem_file,
    write_body_stl,
)

#: What ``--out DIR`` writes (``body.stl`` and ``body_mesh.yaml`` where the body has a mesh form).
FILES = ("design.json", "body.yaml", "body.stl", "body_mesh.yaml", "shape.png", "state.json")
#: Options of the uniform search that a problem file replaces.
UNIFORM_ONLY = ("free", "tension_max", "allowable_strain", "samples", "sampling", "ladder", "tol",
                "top", "tendon", "tensions", "design", "set", "profile", "routing", "loads",
                "axial")
HELP = """\
--problem FILE states a shape-design problem in YAML (SI units: m, N, Pa, rad):
  body: paper-experiment                 a preset or a body file (relative to FILE)
  load: {tension: 20.0, mu: 0.2}         N and capstan friction, or {stroke: 0.6e-3} (m)
  vary: - {field: w_d, law: each, low: 0.3e-3, high: 2.0e-3}
        fields: w_n w_d cut (per notch), w_t (per gap), R_outer r_inner R_c E w_base w_tip;
        law: each (one per notch) | uniform | linear (base, tip) | quadratic (base, middle, tip)
  targets (each at the file's load, or its own load: {...}):
    - tip: {angle: 1.0472, angle_tol: 0.0087}           tip x, z (m), angle (rad)
    - curve: {arc: {angle: 1.0472}, tol: 2.0e-4}        or points: [[x, z], ...] (m)
    - notch_angles: {kind: equal, tol: 0.02}            or tip_first (ratio: 3) or angles
    - stop_angle: {angle: 1.2, tol: 0.01}               the notches' hard stop (rad)
  limits: {max_strain: 0.06, stop_margin: 0.05}          strain; rad left before closing
  fabrication: {min_wall: 0.2e-3, min_backbone: 0.3e-3, min_web: 0.5e-3}   (m)
  search: {seed: 0, popsize: 15, maxiter: 300}
  examples: config/design/constant_curvature.yaml, config/design/tip_first_wrist.yaml
"""


def add_problem_arguments(parser: argparse.ArgumentParser, group: Any) -> None:
    """Add ``--problem`` to the target ``group`` and its own options to ``parser``."""
    group.add_argument("--problem", metavar="FILE",
                       help="design a pattern for a shape: a problem file (see below)")
    parser.add_argument("--workers", default="-1", metavar="K",
                        help="--problem: processes evaluating candidates (default -1: every "
                             "core)")
    parser.add_argument("--resume", action="store_true",
                        help="--problem: go on from DIR/state.json of an earlier --out DIR")


def _workers(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise InputError(f"--workers = {text!r} is not an integer", parameter="--workers",
                         value=text, allowed="a positive integer or -1") from None


def run_problem(args: argparse.Namespace) -> int:
    """Search the problem file, print the answer, write ``--out``; exit 2 on bad input, 3 when
    no design meets the targets (the closest is still written)."""
    out = Path(args.out) if args.out else None
    try:
        given = [f"--{name.replace('_', '-')}" for name in UNIFORM_ONLY
                 if getattr(args, name) not in (None, [])]
        if given:
            raise InputError(f"{', '.join(given)} apply to the uniform search; with --problem "
                             "the file states them", parameter=given[0], value=given,
                             allowed="the problem file's keys")
        if args.resume and out is None:
            raise InputError("--resume needs --out DIR (its state.json)", parameter="--resume",
                             value=True, allowed="with --out DIR")
        problem_file = read_problem_file(args.problem)
        options = problem_file.search
        seed = options.seed if args.seed is None else _seed(args.seed)
        if out is not None:
            out.mkdir(parents=True, exist_ok=True)
        with ProgressBars.of(args) as bars:
            found = design_for_shape(
                problem_file.problem, seed=seed, popsize=options.popsize,
                maxiter=options.maxiter, workers=_workers(args.workers), progress=bars,
                state=None if out is None else out / "state.json", resume=args.resume)
        status = 0
    except NoShapeDesignError as error:
        print(f"tdcm design: {error}", file=sys.stderr)
        found, status = error.found, error.exit_code
    except TdcmError as error:
        if args.json:
            print(json.dumps({"error": {"kind": error.kind, "message": str(error)}}))
        print(f"tdcm design: {error}", file=sys.stderr)
        return error.exit_code
    summary = {"problem": args.problem, **found.summary()}
    if out is not None:
        for path in write_answer(found, summary, out):
            print(f"wrote {path}", file=sys.stderr)
    if args.json:
        print(json.dumps(summary))
    else:
        _print(summary)
    return status


def _seed(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise InputError(f"--seed = {text!r} is not an integer", parameter="--seed", value=text,
                         allowed="an integer >= 0") from None


def write_answer(found: ShapeDesign, summary: dict[str, Any], out: Path) -> list[Path]:
    """``design.json``, and where a design was found ``body.yaml``, ``body.stl`` with the body
    file that names it, ``body_mesh.yaml`` (where the body has a mesh form: shaped sections, a
    linear material), and ``shape.png`` in ``out``."""
    from tdcm_ros.plotting import plot_shape_design

    paths = [out / "design.json"]
    paths[0].write_text(json.dumps(summary, indent=1) + "\n", encoding="utf-8")
    design = found.design
    if design is None:
        return paths
    paths.append(out / "body.yaml")
    paths[-1].write_text(body_file_text(design), encoding="utf-8")
    try:
        stl = write_body_stl(design, out / "body.stl")
        paths.append(stl)
        text = mesh_body_file_text(design, stl.name)
    except TdcmError as error:  # a section without a shape, a non-linear law, no manifold3d
        print(f"tdcm design: {error}; the body file {paths[1]} holds the design", file=sys.stderr)
    else:
        paths.append(out / "body_mesh.yaml")
        paths[-1].write_text(text, encoding="utf-8")
    if found.evaluation.results:
        paths.append(plot_shape_design(found, out / "shape.png"))
    return paths


def _print(summary: dict[str, Any]) -> None:
    """The human summary: verdict, variables (mm for lengths), each target, strain, cost."""
    verdict = "every target met" if summary["met"] else "NOT met (closest design)"
    print(f"design for shape {summary['problem']}: {verdict} after {summary['generations']} "
          f"generations, {summary['evaluations']} evaluations, {summary['seconds']:.1f} s")
    for name, value in summary["variables"].items():
        shown = f"{value:.6g} Pa" if name == "E" else f"{value * 1e3:.4f} mm"
        print(f"  {name:>16} = {shown}")
    for goal in summary["targets"]:
        achieved = ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}"
                             for k, v in goal["achieved"].items() if k != "angles")
        print(f"  {goal['target']} at {goal['load']}: max |residual| {goal['max_residual']:.3g} "
              f"(<= 1 meets it); {achieved}")
    for load, strain in summary["peak_strain"].items():
        print(f"  peak strain at {load}: {strain * 100:.3f} %")
