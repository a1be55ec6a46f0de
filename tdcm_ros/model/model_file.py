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

from dataclasses import dataclass

from tdcm_ros.model.body_file import (
    body_file_text,
    is_body_file,
    read_body_file,
    yaml_number,
)
from tdcm_ros.model.design import Design, preset
from tdcm_ros.model.uncertainty import ParameterCovariance


@dataclass(frozen=True, eq=False)
class ModelSpec:
    """A design with its tendon friction ``friction_mu`` and, after a calibration, its
    parameters' covariance."""

    design: Design
    friction_mu: float = 0.0
    uncertainty: ParameterCovariance | None = None

    def text(self) -> str:
        """The model file: the design's body file with ``friction`` and ``uncertainty``."""
        lines = [body_file_text(self.design).rstrip("\n")]
        if self.friction_mu:
            lines.append(f"friction: {{mu: {yaml_number(self.friction_mu)}}}")
        if self.uncertainty is not None:
            u = self.uncertainty
            rows = ", ".join("[" + ", ".join(yaml_number(v) for v in row) + "]"
                             for row in u.covariance.tolist())
            lines += ["uncertainty:", f"  parameters: [{', '.join(u.names)}]",
                      f"  values: [{', '.join(yaml_number(v) for v in u.values.tolist())}]",
                      f"  covariance: [{rows}]", f"  residual_m: {yaml_number(u.residual_m)}"]
        return "\n".join(lines) + "\n"


def read_model(name: str) -> ModelSpec:
    """The model ``name`` names: a model (or body) file if it is one, else a preset."""
    if not is_body_file(name):
        return ModelSpec(preset(name))
    body = read_body_file(name)
    return ModelSpec(body.design(), body.friction_mu, body.uncertainty)
