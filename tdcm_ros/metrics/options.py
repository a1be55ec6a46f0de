"""Evaluation options and the ``NAME=VALUE`` syntax of ``tdcm evaluate/calibrate --set``.

Names (SI units):

- ``design.preset`` (a preset name or a body file, applied first), ``design.<field>`` or a bare
  design field
  (``E``, ``w_d``, ``N``, ``profile``, ...);
- ``solver.<field>``: a :class:`~tdcm_ros.model.SolverSettings` field;
- ``steps.<field>``: a :class:`~tdcm_ros.metrics.steps.StepSettings` field;
- ``markers.labels`` / ``markers.arc_lengths`` (comma lists), ``markers.ball_radius`` (m),
  ``markers.side_deg``;
- ``align.tolerance_s``, ``mape_threshold_m``, ``stations``, ``deflection_axis``,
  ``roll.tolerance_rad``;
- ``friction.mu``: the tendon's capstan friction (a model file's ``friction`` section sets it
  with its design; :class:`~tdcm_ros.model.ModelSpec`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.metrics.geometry import DEFLECTION_AXES
from tdcm_ros.metrics.steps import STEP_SPECS, StepSettings
from tdcm_ros.model import (
    FIELD_SPECS,
    MARKER_SPECS,
    SOLVER_SPECS,
    Design,
    InvalidSettingsError,
    MarkerLayout,
    ParameterCovariance,
    SolverSettings,
    parse_field,
    preset,
    read_model,
)
from tdcm_ros.spec import Spec, check_fields, spec_field, specs_of

DEFAULT_PRESET = "paper-experiment"


@dataclass(frozen=True)
class EvaluateOptions:
    """Everything an evaluation depends on besides the data."""

    design: Design = field(default_factory=lambda: preset(DEFAULT_PRESET))
    solver: SolverSettings = field(default_factory=SolverSettings)
    steps: StepSettings = field(default_factory=StepSettings)
    layout: MarkerLayout = field(default_factory=MarkerLayout)
    align_tolerance_s: float = spec_field(
        0.02, name="align.tolerance_s", unit="s", low=0.0, high=10.0,
        description="largest gap between a marker frame and its nearest tension sample, and "
                    "between the samples of a body's tension topics (one per tendon)")
    mape_threshold_m: float = spec_field(
        1e-3, unit="m", low=1e-9, high=1.0,
        description="steps measured below this tip deflection are left out of MAPE")
    stations: int = spec_field(50, low=2, high=10_000, description=(
        "arc-length stations (from the base to the tip marker) of the shape error"))
    deflection_axis: str = spec_field("marker", choices=DEFLECTION_AXES, description=(
        "marker: distance from the tip marker's rest line; body: from the body axis"))
    roll_tolerance_rad: float = spec_field(
        0.02, name="roll.tolerance_rad", unit="rad", low=0.0, high=math.pi,
        description="largest roll change (max - min over its marker frames) a step may hold; "
                    "a step whose roll moves more is left out of the metrics")
    friction_mu: float = spec_field(0.0, name="friction.mu", low=0.0, high=10.0, description=(
        "capstan friction coefficient tendon/channel; above 0 each recording's steps are "
        "solved in the order they happened, with stick-slip friction"))
    uncertainty: ParameterCovariance | None = None
    """The fitted parameters' covariance (a model file's ``uncertainty``): the predicted 95 %
    band whose coverage the evaluation reports; None: no band."""

    def __post_init__(self) -> None:
        check_fields(self, OPTION_SPECS)
        self.layout.check_within(self.design.length)

    def with_design(self, design: Design) -> EvaluateOptions:
        """The same options for another design."""
        return replace(self, design=design)


#: Specs of the evaluation options that are not a design, solver, step or marker group.
OPTION_SPECS = specs_of(EvaluateOptions)


#: Every ``--set`` group but the design: name prefix -> (specs by field, error class).
_GROUPS: dict[str, tuple[Mapping[str, Spec], type[InputError]]] = {
    "solver.": (SOLVER_SPECS, InvalidSettingsError), "steps.": (STEP_SPECS, InputError),
    "markers.": (MARKER_SPECS, InputError), "": (OPTION_SPECS, InputError)}
#: ``--set`` name -> (group prefix, field, spec, error class), derived from the specs.
_SETTABLE = {f"{prefix}{spec.name}": (prefix, field, spec, error)
             for prefix, (specs, error) in _GROUPS.items() for field, spec in specs.items()}


def known_names() -> list[str]:
    """Every accepted ``--set`` name (design fields also bare)."""
    return ["design.preset", *(f"design.{n}" for n in [*FIELD_SPECS, "profile"]), *_SETTABLE]


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
            model = read_model(text)
            design = model.design
            opts = replace(opts, friction_mu=model.friction_mu, uncertainty=model.uncertainty)
    design_over = {n[7:]: parse_field(n[7:], t) for n, t in parsed if n.startswith("design.")
                   and n != "design.preset"}
    groups: dict[str, dict[str, Any]] = {prefix: {} for prefix in _GROUPS}
    for name, text in parsed:
        if name in _SETTABLE:
            prefix, field, spec, error = _SETTABLE[name]
            groups[prefix][field] = spec.parse(text, name, error=error)
    return replace(opts, design=design.with_overrides(**design_over),
                   solver=opts.solver.with_overrides(**groups["solver."]),
                   steps=replace(opts.steps, **groups["steps."]),
                   layout=replace(opts.layout, **groups["markers."]), **groups[""])
