"""Design-space sweeps: surfaces, design curves, coupling and feasibility flags."""

import numpy as np
import pytest

from tdcm_ros.model import (
    InvalidDesignError,
    InvalidSettingsError,
    ModelError,
    TensionRangeError,
    preset,
    solve,
)
from tdcm_ros.model.design_space import (
    DEFAULT_ALLOWABLE_STRAIN,
    design_curves,
    sweep,
)

MM = 1e-3
TENSIONS = np.linspace(0.0, 20.0, 21)
KIND_TO_STATUS = {"tendon_singularity": "singularity", "notch_closure": "closure",
                  "non_convergence": "non_convergence"}


@pytest.fixture(scope="module")
def fig2_space():
    return sweep(preset("fig2-wn-1.9"), {"w_n": np.linspace(0.5, 3.0, 11) * MM}, TENSIONS,
                 coupling="fixed-pitch")


def test_fixed_pitch_coupling_keeps_the_paper_length(fig2_space):
    for design in fig2_space.designs:
        assert design.length == pytest.approx(53 * MM, abs=1e-15)
        assert design.w_t == design.w_tip == pytest.approx(6 * MM - design.w_n, abs=1e-15)


@pytest.mark.parametrize("base, field, values", [
    ("fig2-wn-1.9", "w_n", np.linspace(0.5, 3.0, 11) * MM),
    ("fig3-wd-1.52", "w_d", np.linspace(0.6, 2.5, 11) * MM),
])
def test_surface_is_monotone_in_tension(base, field, values):
    space = sweep(preset(base), {field: values}, TENSIONS,
                  coupling="fixed-pitch" if field == "w_n" else "none")
    surface = space.masked("tip_deflection_m")
    assert surface.count() > 0.8 * surface.size
    steps = np.diff(surface, axis=-1)
    assert np.all(steps.compressed() > 0.0)
    assert np.all(surface[:, 0].compressed() == 0.0)


def test_deflection_grows_with_notch_width_and_falls_with_backbone_width(fig2_space):
    at_20 = fig2_space.tip_deflection_m[:, -1]
    assert np.all(np.diff(at_20) > 0.0)
    space = sweep(preset("fig3-wd-1.52"), {"w_d": np.linspace(1.0, 2.5, 7) * MM}, [20.0])
    assert np.all(np.diff(space.tip_deflection_m[:, 0]) < 0.0)


def test_design_curves_lie_on_the_surface(fig2_space):
    curves = design_curves({f"w_n = {w:g} mm": preset(f"fig2-wn-{w:g}") for w in (1.0, 2.5)},
                           TENSIONS)
    for w in (1.0, 2.5):
        row = int(np.argmin(np.abs(fig2_space.values[0] - w * MM)))
        assert fig2_space.values[0][row] == pytest.approx(w * MM)
        np.testing.assert_allclose(curves[f"w_n = {w:g} mm"].tip_deflection_m,
                                   fig2_space.tip_deflection_m[row], rtol=0, atol=1e-12)
        one = solve(preset(f"fig2-wn-{w:g}"), 20.0)
        assert curves[f"w_n = {w:g} mm"].tip_deflection_m[-1] == pytest.approx(
            one.tip_deflection_m, abs=1e-12)


def test_feasibility_flags_match_single_solve_errors_point_by_point():
    base = preset("paper-experiment").with_overrides(E=0.5e9, w_d=1.0 * MM)
    tensions = np.linspace(0.0, 40.0, 9)
    space = sweep(base, {"w_n": np.linspace(0.05, 0.6, 6) * MM, "R_c": [2.0 * MM, 2.75 * MM]},
                  tensions)
    assert space.status.shape == (6, 2, 9)
    seen = set()
    for i, j, k in np.ndindex(*space.status.shape):
        design = space.designs[i * 2 + j]
        assert design.w_n == space.values[0][i] and design.R_c == space.values[1][j]
        try:
            result = solve(design, tensions[k])
        except ModelError as error:
            expected = KIND_TO_STATUS[error.kind]
            assert np.isnan(space.tip_deflection_m[i, j, k])
        else:
            strain = space.max_bending_strain[i, j, k]
            expected = "strain" if strain > DEFAULT_ALLOWABLE_STRAIN else "ok"
            assert space.tip_deflection_m[i, j, k] == pytest.approx(result.tip_deflection_m,
                                                                    abs=1e-12)
        assert space.status[i, j, k] == expected, (i, j, k, space.message[i, j, k])
        seen.add(expected)
    assert seen == {"ok", "strain", "closure", "singularity"}
    assert space.masked("tip_deflection_m").mask.sum() == np.sum(space.status != "ok")


def test_allowable_strain_moves_the_strain_boundary():
    base = preset("fig3-wd-1.52")
    values = {"w_d": np.linspace(0.8, 1.6, 5) * MM}
    strict = sweep(base, values, TENSIONS, allowable_strain=0.02)
    loose = sweep(base, values, TENSIONS, allowable_strain=0.11)
    assert np.sum(strict.status == "strain") > np.sum(loose.status == "strain")
    flagged = strict.status == "strain"
    assert np.all(strict.max_bending_strain[flagged] > 0.02)
    assert np.all(strict.max_bending_strain[strict.feasible] <= 0.02)


def test_bad_sweeps_raise_typed_errors():
    base = preset("fig2-wn-1.9")
    with pytest.raises(InvalidDesignError, match="profile"):
        sweep(base, {"profile": [1.0]}, TENSIONS)
    with pytest.raises(InvalidDesignError, match="w_n"):
        sweep(base, {"w_n": [7 * MM]}, TENSIONS, coupling="fixed-pitch")
    with pytest.raises(InvalidDesignError, match="w_t"):
        sweep(base, {"w_t": [1 * MM]}, TENSIONS, coupling="fixed-pitch")
    with pytest.raises(InvalidDesignError, match="w_d"):
        sweep(base, {"w_d": [-1 * MM]}, TENSIONS)
    with pytest.raises(InvalidDesignError, match="N"):
        sweep(base, {"N": [2.5]}, TENSIONS)
    with pytest.raises(InvalidDesignError, match="coupling"):
        sweep(base, {"w_n": [1 * MM]}, TENSIONS, coupling="golden")
    with pytest.raises(InvalidDesignError, match="axes"):
        sweep(base, {"w_n": [1 * MM], "w_d": [1 * MM], "E": [1e9]}, TENSIONS)
    with pytest.raises(TensionRangeError, match="tension"):
        sweep(base, {"w_n": [1 * MM]}, [1.0, -2.0])
    with pytest.raises(InvalidSettingsError, match="allowable_strain"):
        sweep(base, {"w_n": [1 * MM]}, TENSIONS, allowable_strain=0.0)


def test_integer_field_sweep():
    space = sweep(preset("paper-experiment"), {"N": [2, 4, 8]}, [10.0])
    assert [d.N for d in space.designs] == [2, 4, 8]
    assert np.all(np.diff(space.tip_deflection_m[:, 0]) > 0.0)
