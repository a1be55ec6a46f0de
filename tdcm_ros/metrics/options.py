"""Evaluation options and the ``NAME=VALUE`` syntax of ``tdcm evaluate/calibrate --set``.

Names (SI units):

- ``design.preset`` (a preset name, applied first), ``design.<field>`` or a bare design field
  (``E``, ``w_d``, ``N``, ``profile``, ...);
- ``solver.<field>``: a :class:`~tdcm_ros.model.SolverSettings` field;
- ``steps.<field>``: a :class:`~tdcm_ros.metrics.steps.StepSettings` field;
- ``markers.labels`` / ``markers.arc_lengths`` (comma lists), ``markers.ball_radius`` (m),
  ``markers.side_deg``;
- ``align.tolerance_s``, ``mape_threshold_m``, ``stations``, ``deflection_axis``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.metrics.geometry import DEFLECTION_AXES, MarkerLayout
from tdcm_ros.metrics.steps import StepSettings
from tdcm_ros.model import FIELD_SPECS, Design, SolverSettings, parse_field, preset

DEFAULT_PRESET = "paper-experiment"


@dataclass(frozen=True)
class EvaluateOptions:
    """Everything an evaluation depends on besides the data."""

    design: Design = field(default_factory=lambda: preset(DEFAULT_PRESET))
    solver: SolverSettings = field(default_factory=SolverSettings)
    steps: StepSettings = field(default_factory=StepSettings)
    layout: MarkerLayout = field(default_factory=MarkerLayout)
    align_tolerance_s: float = 0.02
    """Largest gap (s) between a marker frame and its nearest tension sample."""
    mape_threshold_m: float = 1e-3
    """Steps measured below this tip deflection (m) are left out of MAPE."""
    stations: int = 50
    """Arc-length stations (from the base to the tip marker) of the shape error."""
    deflection_axis: str = "marker"
    """``marker``: distance from the tip marker's rest line; ``body``: from the body axis."""

    def __post_init__(self) -> None:
        if not (np.isfinite(self.align_tolerance_s) and self.align_tolerance_s >= 0.0):
            raise out_of_range("align.tolerance_s", self.align_tolerance_s, "[0, inf) s")
        if not (np.isfinite(self.mape_threshold_m) and self.mape_threshold_m > 0.0):
            raise out_of_range("mape_threshold_m", self.mape_threshold_m, "(0, inf) m")
        if isinstance(self.stations, bool) or not isinstance(self.stations, int) \
                or not 2 <= self.stations <= 10_000:
            raise out_of_range("stations", self.stations, "integer in [2, 10000]")
        if self.deflection_axis not in DEFLECTION_AXES:
            raise out_of_range("deflection_axis", self.deflection_axis,
                               " | ".join(DEFLECTION_AXES))
        self.layout.check_within(self.design.length)

    def with_design(self, design: Design) -> EvaluateOptions:
        """The same options for another design."""
        return replace(self, design=design)


def _split_list(text: str) -> list[str]:
    return [part.strip() for part in text.split(",") if part.strip()]


def _number(name: str, text: str, kind: type = float) -> Any:
    try:
        return kind(text)
    except ValueError:
        raise InputError(f"{name} = {text!r} is not {'an integer' if kind is int else 'a number'}",
                         parameter=name, value=text, allowed=kind.__name__) from None


def _typed(name: str, current: Any, text: str) -> Any:
    if isinstance(current, bool):
        return text.lower() in ("1", "true", "yes")
    if isinstance(current, int):
        return _number(name, text, int)
    if isinstance(current, float):
        return _number(name, text)
    return text


_TOP = {"align.tolerance_s": "align_tolerance_s", "mape_threshold_m": "mape_threshold_m",
        "stations": "stations", "deflection_axis": "deflection_axis"}


def known_names() -> list[str]:
    """Every accepted ``--set`` name (design fields also bare)."""
    names = ["design.preset", *(f"design.{n}" for n in [*FIELD_SPECS, "profile"])]
    names += [f"solver.{f.name}" for f in fields(SolverSettings)]
    names += [f"steps.{f.name}" for f in fields(StepSettings)]
    names += [f"markers.{f.name}" for f in fields(MarkerLayout)]
    return names + list(_TOP)


def options_from_sets(pairs: Sequence[str], base: EvaluateOptions | None = None
                      ) -> EvaluateOptions:
    """Apply ``NAME=VALUE`` strings over ``base`` (defaults: the paper-experiment design)."""
    parsed: list[tuple[str, str]] = []
    for pair in pairs:
        name, sep, text = pair.partition("=")
        name, text = name.strip(), text.strip()
        if not sep or not name:
            raise InputError(f"--set {pair!r} is not NAME=VALUE", parameter="--set", value=pair,
                             allowed="NAME=VALUE, e.g. E=1.2e9 or steps.tolerance_n=0.2")
        if name in FIELD_SPECS or name == "profile":
            name = f"design.{name}"
        if name not in known_names():
            allowed = ", ".join(known_names())
            raise InputError(f"unknown --set name {name!r}; allowed: {allowed} (design fields "
                             "also without 'design.')", parameter="--set", value=name,
                             allowed=allowed)
        parsed.append((name, text))
    opts = base or EvaluateOptions()
    design = opts.design
    for name, text in parsed:  # the preset first, whatever the order given
        if name == "design.preset":
            design = preset(text)
    design_over = {n[7:]: parse_field(n[7:], t) for n, t in parsed if n.startswith("design.")
                   and n != "design.preset"}
    groups: dict[str, dict[str, Any]] = {"solver": {}, "steps": {}, "markers": {}}
    top: dict[str, Any] = {}
    for name, text in parsed:
        head, _, tail = name.partition(".")
        if name in _TOP:
            attr = _TOP[name]
            top[attr] = _typed(name, getattr(opts, attr), text)
        elif head == "markers" and tail in ("labels", "arc_lengths"):
            items = _split_list(text)
            groups["markers"][tail] = tuple(items) if tail == "labels" else tuple(
                _number(name, v) for v in items)
        elif head in groups:
            target = {"solver": opts.solver, "steps": opts.steps, "markers": opts.layout}[head]
            groups[head][tail] = _typed(name, getattr(target, tail), text)
    return replace(opts, design=design.with_overrides(**design_over),
                   solver=opts.solver.with_overrides(**groups["solver"]),
                   steps=replace(opts.steps, **groups["steps"]),
                   layout=replace(opts.layout, **groups["markers"]), **top)
