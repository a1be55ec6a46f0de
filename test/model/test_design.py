"""Design validation, presets and overrides."""

import math

import numpy as np
import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.model import (
    FIELD_SPECS,
    PRESETS,
    InvalidDesignError,
    InvalidSettingsError,
    SolverSettings,
    preset,
    solve,
)
from tdcm_ros.model.design import parse_field


def test_presets_match_the_paper():
    d = preset("paper-experiment")
    assert d.length == pytest.approx(0.053)
    assert (d.w_n, d.w_t, d.w_d, d.R_c, d.N) == (0.002, 0.004, 0.0014, 0.00275, 8)
    assert d.E == 1.85e9
    for name in ("fig2-wn-1", "fig2-wn-1.9", "fig2-wn-2.5", "fig3-wd-1.2", "fig3-wd-1.52",
                 "fig3-wd-2"):
        sim = PRESETS[name]
        assert sim.length == pytest.approx(0.053)
        assert sim.w_t == pytest.approx(0.006 - sim.w_n)
        assert sim.w_tip == sim.w_t
    assert PRESETS["fig2-wn-1.9"].w_n == pytest.approx(1.9e-3)
    assert PRESETS["fig3-wd-1.52"].w_d == pytest.approx(1.52e-3)


@pytest.mark.parametrize("name", list(FIELD_SPECS))
@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf, 1e13, "x"])
def test_every_field_rejects_bad_values_with_its_name_and_range(name, bad):
    if name == "N" and isinstance(bad, float) and bad == 1e13:
        bad = 10**6
    with pytest.raises(InvalidDesignError) as info:
        preset("paper-experiment").with_overrides(**{name: bad})
    assert info.value.parameter == name
    assert name in str(info.value) and "allowed" in str(info.value)
    assert isinstance(info.value, InputError)


def test_dependent_ranges_and_unknown_names():
    with pytest.raises(InvalidDesignError, match="r_inner"):
        preset("paper-experiment").with_overrides(r_inner=0.004)
    with pytest.raises(InvalidDesignError, match="unknown design field"):
        preset("paper-experiment").with_overrides(w_x=1.0)
    with pytest.raises(InvalidDesignError, match="preset"):
        preset("nope")
    with pytest.raises(InvalidDesignError, match="N = 2.5"):
        preset("paper-experiment").with_overrides(N=2.5)


def test_settings_validation():
    with pytest.raises(InvalidSettingsError, match="routing"):
        SolverSettings(routing="tight")
    with pytest.raises(InvalidSettingsError, match="tol"):
        SolverSettings(tol=0.0)
    with pytest.raises(InvalidSettingsError, match="cells_per_notch"):
        SolverSettings(cells_per_notch=0)


def test_to_dict_is_si_and_complete():
    data = preset("paper-experiment").to_dict()
    assert set(FIELD_SPECS) <= set(data)
    assert data["profile"] == "circular" and data["L"] == pytest.approx(0.053)


@pytest.mark.parametrize(("field", "value", "allowed"), [
    ("R_c", 3.92e-3, "(0, R_outer = 0.00392) m"),
    ("R_c", 5e-3, "(0, R_outer = 0.00392) m"),
    ("w_d", 2 * 3.92e-3, "(0, 2 R_outer = 0.00784) m"),
    ("w_d", 0.01, "(0, 2 R_outer = 0.00784) m"),
    ("w_t", 1e-30, "0 (no segment) or [1e-06, 1] m"),
    ("w_base", 1e-9, "0 (no segment) or [1e-06, 1] m"),
    ("w_tip", 5e-7, "0 (no segment) or [1e-06, 1] m"),
    ("w_n", 1e-30, "[1e-06, 1] m"),
])
def test_cross_field_limits_name_the_field_value_and_range(field, value, allowed):
    """Issue 13: the tendon inside the tube, the backbone narrower than it, no negligible cell."""
    with pytest.raises(InvalidDesignError) as info:
        preset("paper-experiment").with_overrides(**{field: value})
    error = info.value
    assert (error.parameter, error.value, error.allowed) == (field, value, allowed)
    assert field in str(error) and allowed in str(error)


def test_segments_at_their_floor_or_absent_are_valid():
    design = preset("paper-experiment").with_overrides(w_base=0.0, w_t=1e-6, w_tip=0.0, w_n=1e-6)
    assert design.length == pytest.approx(8e-6 + 7e-6)


def test_a_list_of_equal_values_is_the_uniform_design_bit_for_bit():
    design = preset("paper-experiment")
    listed = design.with_overrides(w_n=[design.w_n] * 8, w_d=(design.w_d,) * 8,
                                   w_t=np.full(7, design.w_t))
    assert listed == design and hash(listed) == hash(design) and listed.is_uniform
    assert np.array_equal(solve(listed, 20.0).positions, solve(design, 20.0).positions)


def test_per_notch_values_give_each_notch_its_bounds_and_the_length():
    design = preset("paper-experiment").with_overrides(
        N=3, w_n=[1e-3, 2e-3, 3e-3], w_d=[1.4e-3, 1.2e-3, 1.0e-3], w_t=[0.0, 4e-3])
    left, right = design.notch_bounds()
    assert not design.is_uniform
    assert left.tolist() == pytest.approx([5e-3, 6e-3, 12e-3], abs=1e-15)
    assert right[0] == left[1]   # no tube between: the next notch starts where this one ends
    assert design.length == pytest.approx(5e-3 + 6e-3 + 4e-3 + 4e-3, abs=1e-15)
    assert design.per_notch("w_d").tolist() == [1.4e-3, 1.2e-3, 1.0e-3]
    assert design.to_dict()["w_n"] == [1e-3, 2e-3, 3e-3]


@pytest.mark.parametrize(("overrides", "message"), [
    ({"w_n": [1e-3, 2e-3]}, (r"w_n = \[0.001, 0.002\] is out of range; allowed: one number, or "
                            r"8 numbers \(one per notch: N = 8\)")),
    ({"w_t": [4e-3] * 8}, (r"w_t = .* allowed: one number, or 7 numbers \(one per gap between "
                          r"notches: N = 8\)")),
    ({"w_d": [1e-3] * 7 + [9e-3]}, r"w_d\[7\] = 0.009 is out of range; allowed: \(0, 2 R_outer"),
    ({"w_t": [4e-3] * 6 + [1e-7]}, r"w_t\[6\] = 1e-07 is out of range; allowed: 0 \(no segment\)"),
    ({"w_n": [2e-3] * 7 + [float("nan")]}, r"w_n = .*nan.* is out of range"),
    ({"w_n": [2e-3] * 7 + ["x"]}, r"w_n = 'x' is not a number; allowed: a list of numbers"),
])
def test_bad_per_notch_values_name_the_field_the_notch_and_the_range(overrides, message):
    with pytest.raises(InvalidDesignError, match=message):
        preset("paper-experiment").with_overrides(**overrides)


def test_a_profile_per_notch_is_checked_and_a_list_of_one_profile_is_that_profile():
    design = preset("paper-experiment")
    assert design.with_overrides(profile=["circular"] * 8) == design
    mixed = design.with_overrides(profile=["circular", "rectangular"] * 4)
    assert [p.name for p in mixed.notch_profiles()][:2] == ["circular", "rectangular"]
    assert mixed.to_dict()["profile"] == ["circular", "rectangular"] * 4
    with pytest.raises(InvalidDesignError, match=r"profile = \['circular', 'rectangular'\] is "
                                                 r"out of range; allowed: one profile, or 8"):
        design.with_overrides(profile=["circular", "rectangular"])
    with pytest.raises(InvalidDesignError, match=r"profile = 'oval' is out of range"):
        design.with_overrides(profile=["circular"] * 7 + ["oval"])
    with pytest.raises(InvalidDesignError, match=r"profile\[1\] = 3 is not a notch profile"):
        design.with_overrides(profile=["circular", 3] + ["circular"] * 6)
    assert parse_field("profile", "[circular, rectangular]") == ["circular", "rectangular"]


def test_a_per_notch_override_is_parsed_from_a_bracketed_list():
    assert parse_field("w_d", "[0.0014, 0.0012]") == (0.0014, 0.0012)
    assert parse_field("w_d", "0.0014") == 0.0014
    with pytest.raises(InvalidDesignError, match="w_d"):
        parse_field("w_d", "[0.0014, wide]")
