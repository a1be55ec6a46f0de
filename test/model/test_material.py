"""Material laws: a bilinear law whose plateau is out of reach is the linear model bit for bit;
in the plateau a uniform body bends as the law integrated over its section by scipy here; a
recoverable strain is a typed limit; bad laws name their key."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from tdcm_ros.model import (
    InvalidDesignError,
    SolverSettings,
    body_file_text,
    preset,
    read_body_file,
    solve,
)
from tdcm_ros.model.errors import StrainLimitError
from tdcm_ros.model.material import Material

PAPER = preset("paper-experiment")


def nitinol(design, onset: float = 0.015, ratio: float = 0.08, **more: float):
    return dataclasses.replace(design, material=Material("bilinear", onset, ratio * design.E,
                                                         **more))


@pytest.mark.parametrize("tension", [1.0, 12.0, 20.0])
@pytest.mark.parametrize("routing", ["paper", "free"])
def test_a_plateau_out_of_reach_is_the_linear_model_bit_for_bit(tension: float,
                                                                 routing: str) -> None:
    """Issue 28's target (peak strain 1.87 % at 20 N, the plateau at 5 %)."""
    settings = SolverSettings(routing=routing)
    linear = solve(PAPER, tension, settings=settings)
    law = solve(nitinol(PAPER, onset=0.05), tension, settings=settings)
    assert np.array_equal(law.positions, linear.positions)
    assert np.array_equal(law.theta, linear.theta)
    assert np.array_equal(law.notch_peak_strains, linear.notch_peak_strains)


def section_moment(kappa: float, design, half: float, onset: float, plateau: float) -> float:
    """``M(kappa)`` (N m) of the band ``|x| <= half`` of the annulus: the bilinear stress
    integrated over the chord widths by scipy's quad, written here."""
    r_o, r_i, modulus = design.R_outer, design.r_inner, design.E

    def width(x: float) -> float:
        return 2.0 * (math.sqrt(max(r_o**2 - x * x, 0.0)) - math.sqrt(max(r_i**2 - x * x, 0.0)))

    def stress(strain: float) -> float:
        if abs(strain) <= onset:
            return modulus * strain
        return math.copysign(modulus * onset + plateau * (abs(strain) - onset), strain)

    edge = min(half, r_o)
    points = [p for p in (-r_i, r_i, -onset / kappa, onset / kappa) if -edge < p < edge]
    return quad(lambda x: stress(kappa * x) * x * width(x), -edge, edge, points=points,
                epsabs=0.0, epsrel=1e-12, limit=400)[0]


def test_a_uniform_body_in_the_plateau_bends_as_the_law_integrated_over_its_section() -> None:
    """A body of identical rectangular notches end to end, its tendon following the body
    everywhere (moment ``R_c T`` exactly): an arc of the curvature solving ``M(kappa) = R_c T``
    (scipy's brentq on the quadrature above), its tip in closed form."""
    body = PAPER.with_overrides(w_base=0.0, w_t=0.0, w_tip=0.0, profile="rectangular")
    tension, onset, plateau = 20.0, 0.012, 0.08 * PAPER.E
    result = solve(nitinol(body, onset=onset), tension)
    moment = body.R_c * tension
    kappa = brentq(lambda k: section_moment(k, body, body.w_d / 2.0, onset, plateau) - moment,
                   1e-6, 1e4, xtol=1e-14, rtol=1e-14)
    linear = solve(body, tension)
    assert kappa > 1.05 * linear.tip_angle_rad / body.length  # the plateau is reached
    length = body.length
    assert result.tip_angle_rad == pytest.approx(kappa * length, rel=1e-9)
    assert result.tip_position[0] == pytest.approx((1.0 - math.cos(kappa * length)) / kappa,
                                                   rel=1e-9)
    assert result.tip_position[2] == pytest.approx(math.sin(kappa * length) / kappa, rel=1e-9)
    assert result.notch_peak_strains == pytest.approx(kappa * body.w_d / 2.0, rel=1e-9)


def test_the_plateau_bends_the_paper_body_further_and_converges() -> None:
    linear = solve(PAPER, 20.0)
    law = solve(nitinol(PAPER), 20.0)
    assert law.converged and law.tip_position[0] > linear.tip_position[0]
    assert law.notch_peak_strains.max() > 0.015
    again = solve(nitinol(PAPER), 20.0)
    assert np.array_equal(law.positions, again.positions)


def test_a_strain_past_the_recoverable_strain_is_a_typed_limit() -> None:
    design = nitinol(PAPER, recoverable_strain=0.02)
    assert solve(design, 10.0).converged
    with pytest.raises(StrainLimitError, match=r"notch \d strains .* past the material's "
                                               r"recoverable strain 2 %") as info:
        solve(design, 20.0)
    assert info.value.strain > 0.02 and info.value.kind == "strain_limit"
    linear = dataclasses.replace(PAPER, material=Material(recoverable_strain=0.01))
    with pytest.raises(StrainLimitError):
        solve(linear, 20.0)


@pytest.mark.parametrize(("material", "message"), [
    (Material("elastic"), r"material\.law = 'elastic'"),
    (Material("bilinear", 0.0, 1e8), r"material\.plateau_strain = 0\.0"),
    (Material("bilinear", 0.02, 2e9), r"material\.E_plateau = 2000000000\.0 Pa .*\(0, E = 1\.85e\+09\]"),
    (Material("bilinear", 0.02, math.nan), r"material\.E_plateau = nan"),
    (Material("linear", 0.02), r"material\.plateau_strain and material\.E_plateau go with"),
    (Material(recoverable_strain=-1.0), r"material\.recoverable_strain = -1\.0"),
])
def test_bad_laws_name_their_key(material: Material, message: str) -> None:
    with pytest.raises(InvalidDesignError, match=message):
        dataclasses.replace(PAPER, material=material)


def test_a_law_round_trips_through_a_body_file(tmp_path: Path) -> None:
    design = nitinol(PAPER, recoverable_strain=0.08)
    path = tmp_path / "nitinol.yaml"
    path.write_text(body_file_text(design), encoding="utf-8")
    assert "law: bilinear" in path.read_text(encoding="utf-8")
    assert read_body_file(path).design() == design


def test_the_json_summary_names_the_law_in_finite_numbers() -> None:
    import json

    summary = solve(nitinol(PAPER), 5.0).summary()
    text = json.dumps(summary, allow_nan=False)
    assert json.loads(text)["design"]["material"] == {"law": "bilinear", "plateau_strain": 0.015,
                                                      "E_plateau": 0.08 * PAPER.E}
    assert "material" not in solve(PAPER, 5.0).summary()["design"]
