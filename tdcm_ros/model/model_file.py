"""Model files: a body file (:mod:`tdcm_ros.model.body_file`) with what a calibration adds.

::

    # ... the body file's tube, material, tendons and segments ...
    friction: {mu: 0.3}                  # capstan coefficient tendon/channel, stick-slip
    uncertainty:                         # tdcm calibrate --out: the fit's covariance
      parameters: [E, mu]                # real design fields and mu
      values: [7.0e+8, 0.3]              # where they were fitted (SI)
      covariance: [[4.0e+14, 1.0e+5], [1.0e+5, 1.0e-4]]
      residual_m: 1.2e-4                 # m, the fit's residual standard deviation

``friction.mu`` (default 0, the paper's frictionless tendon) makes the estimator solve each
tension after the ones before it (:class:`~tdcm_ros.model.friction.FrictionTrack`);
``uncertainty`` gives each predicted point a covariance
(:mod:`tdcm_ros.model.uncertainty`). A preset name is a model without either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tdcm_ros.errors import reject_unknown
from tdcm_ros.model.body_file import body_file_text, body_from_mapping, is_body_file
from tdcm_ros.model.design import Design, preset
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.friction import check_mu
from tdcm_ros.model.uncertainty import InvalidUncertaintyError, ParameterCovariance
from tdcm_ros.yamlio import load_yaml


@dataclass(frozen=True, eq=False)
class ModelSpec:
    """A design with its tendon friction ``friction_mu`` and, after a calibration, its
    parameters' covariance."""

    design: Design
    friction_mu: float = 0.0
    uncertainty: ParameterCovariance | None = None

    def text(self) -> str:
        """The model file: the design's body file with ``friction`` and ``uncertainty``."""
        def number(value: float) -> str:
            return repr(float(value))

        lines = [body_file_text(self.design).rstrip("\n")]
        if self.friction_mu:
            lines.append(f"friction: {{mu: {number(self.friction_mu)}}}")
        if self.uncertainty is not None:
            u = self.uncertainty
            rows = ", ".join("[" + ", ".join(number(v) for v in row) + "]"
                             for row in u.covariance.tolist())
            lines += ["uncertainty:", f"  parameters: [{', '.join(u.names)}]",
                      f"  values: [{', '.join(number(v) for v in u.values.tolist())}]",
                      f"  covariance: [{rows}]", f"  residual_m: {number(u.residual_m)}"]
        return "\n".join(lines) + "\n"


def read_model(name: str) -> ModelSpec:
    """The model ``name`` names: a model (or body) file if it is one, else a preset."""
    if not is_body_file(name):
        return ModelSpec(preset(name))
    try:
        text = Path(name).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise InvalidDesignError(f"cannot read body file {name}: {error}", parameter="design",
                                 value=name, allowed="a readable UTF-8 YAML file") from error
    data = load_yaml(text, name, parameter="design", error=InvalidDesignError)
    design = body_from_mapping(data, name).design()
    return ModelSpec(design, _friction(data.get("friction"), name),
                     _uncertainty(data.get("uncertainty"), name))


def _friction(section: Any, source: str) -> float:
    if section is None:
        return 0.0
    if not isinstance(section, dict):
        raise InvalidDesignError(f"{source}: friction = {section!r} is not a mapping; allowed: "
                                 "{mu: NUMBER}", parameter="friction", value=section,
                                 allowed="{mu: NUMBER}")
    reject_unknown("friction key", section, ("mu",), error=InvalidDesignError)
    return check_mu(_real(section.get("mu", 0.0), "friction.mu", source),
                    f"{source}: friction.mu")


def _uncertainty(section: Any, source: str) -> ParameterCovariance | None:
    if section is None:
        return None
    keys = ("parameters", "values", "covariance", "residual_m")
    if not isinstance(section, dict) or any(k not in section for k in keys):
        raise InvalidDesignError(f"{source}: uncertainty needs {', '.join(keys)}",
                                 parameter="uncertainty", value=section, allowed=", ".join(keys))
    reject_unknown("uncertainty key", section, keys, error=InvalidDesignError)
    names = section["parameters"]
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InvalidDesignError(f"{source}: uncertainty.parameters = {names!r}; allowed: a list "
                                 "of names", parameter="uncertainty.parameters", value=names,
                                 allowed="[NAME, ...]")
    try:
        values = np.array(section["values"], dtype=float)
        covariance = np.array(section["covariance"], dtype=float)
    except (TypeError, ValueError) as error:
        raise InvalidDesignError(f"{source}: uncertainty values and covariance must be numbers "
                                 f"({error})", parameter="uncertainty", value=section,
                                 allowed="numbers") from error
    try:
        return ParameterCovariance(tuple(names), values, covariance,
                                   _real(section["residual_m"], "uncertainty.residual_m", source))
    except InvalidUncertaintyError as error:
        raise InvalidUncertaintyError(f"{source}: {error}", parameter=error.parameter,
                                      value=error.value, allowed=error.allowed) from error


def _real(value: Any, key: str, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InvalidDesignError(f"{source}: {key} = {value!r} is not a finite number",
                                 parameter=key, value=value, allowed="a finite number")
    return float(value)
