"""Model files: a body file with friction and a calibration's covariance, written and read back
bit for bit; each bad section an error naming its key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tdcm_ros.model import (
    InvalidUncertaintyError,
    ModelSpec,
    ParameterCovariance,
    body_file_text,
    named_design,
    preset,
    read_model,
)
from tdcm_ros.model.errors import InvalidDesignError

DESIGN = preset("paper-experiment").with_overrides(E=7.0123456789e8)
COVARIANCE = ParameterCovariance(("E", "mu"), np.array([7.0123456789e8, 0.3012]),
                                 np.array([[1.1e14, -2.0e5], [-2.0e5, 3.3e-5]]), 1.234e-5)


def written(tmp_path: Path, text: str) -> str:
    path = tmp_path / "model.yaml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_a_model_reads_back_bit_for_bit(tmp_path: Path) -> None:
    path = written(tmp_path, ModelSpec(DESIGN, 0.3012, COVARIANCE).text())
    model = read_model(path)
    assert model.design == DESIGN and model.friction_mu == 0.3012
    got = model.uncertainty
    assert got is not None and got.names == ("E", "mu") and got.residual_m == 1.234e-5
    assert np.array_equal(got.values, COVARIANCE.values)
    assert np.array_equal(got.covariance, COVARIANCE.covariance)
    # the body part is a body file: the design alone reads it too
    assert named_design(path) == DESIGN


def test_a_body_file_and_a_preset_are_models_without_friction_or_band(tmp_path: Path) -> None:
    path = written(tmp_path, body_file_text(DESIGN))
    for model in (read_model(path), read_model("paper-experiment")):
        assert model.friction_mu == 0.0 and model.uncertainty is None
    assert ModelSpec(DESIGN).text() == body_file_text(DESIGN)


@pytest.mark.parametrize(("section", "error", "parameter"), [
    ("friction: 0.3", InvalidDesignError, "friction"),
    ("friction: {mu: -0.1}", InvalidDesignError, "friction.mu"),
    ("friction: {mu: .nan}", InvalidDesignError, "friction.mu"),
    ("friction: {mu: 0.1, nu: 2}", InvalidDesignError, "nu"),
    ("uncertainty: {parameters: [E]}", InvalidDesignError, "uncertainty"),
    ("uncertainty: {parameters: E, values: [1], covariance: [[1]], residual_m: 0}",
     InvalidDesignError, "uncertainty.parameters"),
    ("uncertainty: {parameters: [E], values: [x], covariance: [[1]], residual_m: 0}",
     InvalidDesignError, "uncertainty"),
    ("uncertainty: {parameters: [E], values: [1.0e9], covariance: [[-1.0]], residual_m: 0}",
     InvalidUncertaintyError, "uncertainty.covariance"),
    ("uncertainty: {parameters: [E], values: [1.0e9], covariance: [[1.0]], residual_m: -1}",
     InvalidDesignError, "uncertainty.residual_m"),
])
def test_a_bad_section_names_its_key(tmp_path: Path, section: str, error: type,
                                     parameter: str) -> None:
    path = written(tmp_path, body_file_text(DESIGN) + section + "\n")
    with pytest.raises(error) as caught:
        read_model(path)
    assert parameter in (caught.value.parameter or "") + str(caught.value)
    # the file is named, except in an unknown key's message (as for the body file's keys)
    assert str(caught.value).startswith(path) or str(caught.value).startswith("unknown")
