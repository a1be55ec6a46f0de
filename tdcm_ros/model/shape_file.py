"""Shape-design problem files: the body to start from, what varies, the shape wanted and the
limits, in YAML (SI units: m, N, Pa, rad)::

    body: paper-experiment               # a preset, or a body file (relative to this file)
    load: {tension: 20.0, mu: 0.2}       # N, capstan friction; or {stroke: 0.6e-3} (m)
    vary:                                # base to tip; law: each | uniform | linear | quadratic
      - {field: w_d, law: each, low: 0.3e-3, high: 2.0e-3}
    targets:                             # each may carry its own load: {...}
      - tip: {angle: 1.0471975511965976, angle_tol: 0.0087}
      - notch_angles: {kind: equal, tol: 0.02}
    limits: {max_strain: 0.06}           # default: the material's recoverable strain, else 2.9 %
    fabrication: {min_wall: 0.2e-3, min_backbone: 0.3e-3, min_web: 0.5e-3}
    search: {seed: 0, popsize: 15, maxiter: 300}

Targets: ``tip`` (``x``, ``z``, ``angle``, ``position_tol``, ``angle_tol``), ``curve``
(``points: [[x, z], ...]`` or ``arc: {angle, length}``, the length defaulting to the base
body's; ``tol``, m), ``notch_angles`` (``kind: equal | tip_first | angles``, ``tol``,
``ratio``, ``angles``), ``stop_angle`` (``angle``, ``tol``): see
:mod:`tdcm_ros.model.shape_targets`. Every problem is an
:class:`~tdcm_ros.model.inverse.InvalidTargetError` (or the body's
:class:`~tdcm_ros.model.errors.InvalidDesignError`) naming the key by its path
(``targets[1].tip.angle``), the value and the allowed range.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tdcm_ros.errors import InputError, out_of_range, reject_unknown
from tdcm_ros.model.body_file import is_body_file, named_design
from tdcm_ros.model.design import Design
from tdcm_ros.model.design_space import DEFAULT_ALLOWABLE_STRAIN
from tdcm_ros.model.design_variables import Variable, VariableSet
from tdcm_ros.model.inverse import InvalidTargetError
from tdcm_ros.model.shape_problem import Goal, Load, ShapeProblem
from tdcm_ros.model.shape_search import DEFAULT_MAXITER, DEFAULT_POPSIZE
from tdcm_ros.model.shape_targets import (
    CurveTarget,
    Limits,
    NotchAngleTarget,
    StopAngleTarget,
    Target,
    TipTarget,
)
from tdcm_ros.yamlio import load_yaml

TOP_KEYS = ("body", "load", "vary", "targets", "limits", "fabrication", "search")
TARGET_KINDS = ("tip", "curve", "notch_angles", "stop_angle")


@dataclass(frozen=True)
class SearchOptions:
    """The file's ``search``: ``seed``, ``popsize`` (per variable), ``maxiter`` (generations)."""

    seed: int = 0
    popsize: int = DEFAULT_POPSIZE
    maxiter: int = DEFAULT_MAXITER


@dataclass(frozen=True, eq=False)
class ShapeFile:
    """A problem file read: its ``problem`` and ``search`` options, and where it came from."""

    problem: ShapeProblem
    search: SearchOptions
    source: str


def _mapping(value: Any, where: str, keys: tuple[str, ...]) -> Mapping[str, Any]:
    if not isinstance(value, dict):
        raise out_of_range(where, value, "a mapping of keys to values", error=InvalidTargetError)
    reject_unknown(f"key of {where}", value, keys, error=InvalidTargetError)
    return value


def _prefixed(where: str, build: Any, *args: Any, **kwargs: Any) -> Any:
    """``build(*args, **kwargs)`` with an input error's parameter prefixed by ``where``."""
    try:
        return build(*args, **kwargs)
    except TypeError as error:
        raise InvalidTargetError(f"{where}: {error}", parameter=where, value=kwargs,
                                 allowed="the keys this entry takes") from error
    except InputError as error:
        parameter = f"{where}: {error.parameter}" if error.parameter else where
        raise type(error)(f"{where}: {error}", parameter=parameter, value=error.value,
                          allowed=error.allowed) from error


def _load(value: Any, where: str) -> Load:
    entry = _mapping(value, where, ("tension", "stroke", "mu"))
    return _prefixed(where, Load, **entry)


def _target(entry: Any, where: str, design: Design) -> tuple[Target, Any]:
    entry = _mapping(entry, where, (*TARGET_KINDS, "load"))
    kinds = [k for k in TARGET_KINDS if k in entry]
    if len(kinds) != 1:
        raise out_of_range(where, dict(entry), "one of " + ", ".join(TARGET_KINDS) +
                           " (and optionally load)", error=InvalidTargetError)
    kind = kinds[0]
    at = f"{where}.{kind}"
    body = entry[kind]
    target: Target
    if kind == "tip":
        target = _prefixed(at, TipTarget, **_mapping(body, at, (
            "x", "z", "angle", "position_tol", "angle_tol")))
    elif kind == "curve":
        spec = dict(_mapping(body, at, ("points", "arc", "tol")))
        if ("points" in spec) == ("arc" in spec):
            raise out_of_range(at, spec, "one of points, arc", error=InvalidTargetError)
        if "arc" in spec:
            arc = dict(_mapping(spec.pop("arc"), f"{at}.arc", ("angle", "length", "points")))
            arc.setdefault("length", design.length)
            target = _prefixed(at, CurveTarget.arc, **arc, **spec)
        else:
            target = _prefixed(at, CurveTarget, **spec)
    elif kind == "notch_angles":
        spec = dict(_mapping(body, at, ("kind", "tol", "ratio", "angles")))
        if "angles" in spec and isinstance(spec["angles"], list):
            spec["angles"] = tuple(spec["angles"])
        target = _prefixed(at, NotchAngleTarget, **spec)
    else:
        target = _prefixed(at, StopAngleTarget, **_mapping(body, at, ("angle", "tol")))
    return target, entry.get("load")


def problem_from_mapping(data: Any, source: str = "problem", folder: Path | None = None
                         ) -> ShapeFile:
    """The checked problem of a problem file's parsed YAML ``data``; a body file it names is
    read relative to ``folder``."""
    top = _mapping(data, source, TOP_KEYS)
    for key in ("body", "vary", "targets"):
        if key not in top:
            raise InvalidTargetError(f"{source} has no {key}; allowed: see tdcm design --help",
                                     parameter=key, value=None, allowed="present")
    name = top["body"]
    if not isinstance(name, str):
        raise out_of_range("body", name, "a preset name or a body file's path",
                           error=InvalidTargetError)
    if is_body_file(name) and folder is not None and not Path(name).is_absolute():
        name = str(folder / name)
    base = named_design(name)
    if not isinstance(top["vary"], list):
        raise out_of_range("vary", top["vary"], "a list of {field, law, low, high}",
                           error=InvalidTargetError)
    variables = VariableSet(base, tuple(
        _prefixed(f"vary[{i}]", Variable, **_mapping(v, f"vary[{i}]", (
            "field", "law", "low", "high"))) for i, v in enumerate(top["vary"])))
    default = _load(top["load"], "load") if "load" in top else None
    if not isinstance(top["targets"], list):
        raise out_of_range("targets", top["targets"], "a list of targets",
                           error=InvalidTargetError)
    goals = []
    for i, entry in enumerate(top["targets"]):
        target, load = _target(entry, f"targets[{i}]", base)
        at = _load(load, f"targets[{i}].load") if load is not None else default
        if at is None:
            raise InvalidTargetError(f"targets[{i}] has no load and the file none; allowed: "
                                     "load: {tension: N} or {stroke: m}",
                                     parameter=f"targets[{i}].load", value=None,
                                     allowed="a load")
        goals.append(Goal(target, at))
    recoverable = base.material.recoverable_strain
    limit_keys = dict(_mapping(top.get("limits", {}), "limits", ("max_strain", "stop_margin")))
    limit_keys.setdefault("max_strain", recoverable if math.isfinite(recoverable)
                          else DEFAULT_ALLOWABLE_STRAIN)
    fabrication = _mapping(top.get("fabrication", {}), "fabrication",
                           ("min_wall", "min_backbone", "min_web"))
    limits = _prefixed("limits", Limits, **limit_keys, **fabrication)
    search = _prefixed("search", SearchOptions, **_mapping(top.get("search", {}), "search", (
        "seed", "popsize", "maxiter")))
    return ShapeFile(ShapeProblem(variables, tuple(goals), limits), search, source)


def read_problem_file(path: str | Path) -> ShapeFile:
    """The checked problem of the problem file at ``path`` (the package's bounded YAML loader)."""
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise InvalidTargetError(f"cannot read problem file {source}: {error}",
                                 parameter="problem", value=source,
                                 allowed="a readable UTF-8 YAML file") from error
    data = load_yaml(text, source, parameter="problem", error=InvalidTargetError)
    return problem_from_mapping(data, source, Path(path).resolve().parent)
