"""Free variables of a shape design: laws along the body against NumPy's polynomial fits, a
one-sided cut's depth against the body file's ``cut`` path, and the typed errors."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.model import Tendon, preset
from tdcm_ros.model.body_file import named_design
from tdcm_ros.model.design_variables import Variable, VariableSet
from tdcm_ros.model.errors import InvalidDesignError
from test.support.examples import REPO

PAPER = preset("paper-experiment")


def test_a_quadratic_law_is_the_parabola_through_its_three_values() -> None:
    variable = Variable("w_d", 0.2e-3, 2.0e-3, "quadratic")
    ends = np.array([1.4e-3, 0.9e-3, 1.2e-3])
    values = np.array(variable.values(ends, 7))
    u = np.linspace(0.0, 1.0, 7)
    reference = np.polyval(np.polyfit([0.0, 0.5, 1.0], ends, 2), u)
    assert values == pytest.approx(reference, rel=1e-12)
    assert values[[0, 3, 6]] == pytest.approx(ends, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.floats(0.3e-3, 1.8e-3), st.floats(0.3e-3, 1.8e-3), st.integers(2, 12))
def test_a_linear_law_is_monotone_and_inside_its_range(first: float, last: float,
                                                       notches: int) -> None:
    values = np.array(Variable("w_d", 0.3e-3, 1.8e-3, "linear").values(
        np.array([first, last]), notches))
    assert values[0] == pytest.approx(first) and values[-1] == pytest.approx(last)
    steps = np.diff(values)
    assert np.all(steps * np.sign(last - first) >= -1e-18)
    assert np.all((values >= 0.3e-3) & (values <= 1.8e-3))


def test_each_uniform_and_scalar_variables_set_their_fields() -> None:
    variables = VariableSet(PAPER, (Variable("w_d", 0.3e-3, 2e-3, "each"),
                                    Variable("w_t", 1e-3, 6e-3, "uniform"),
                                    Variable("R_c", 1e-3, 3e-3), Variable("E", 1e9, 3e9)))
    assert variables.size == 8 + 1 + 1 + 1
    assert variables.names()[:2] == ("w_d[0]", "w_d[1]") and variables.names()[8] == "w_t~uniform[0]"
    x = np.r_[np.linspace(0.6e-3, 1.3e-3, 8), 3e-3, 2.5e-3, 1.2e9]
    design = variables.design(x)
    assert design.per_notch("w_d") == pytest.approx(x[:8])
    assert design.per_notch("w_t") == pytest.approx(np.full(7, 3e-3))
    assert (design.R_c, design.E) == (2.5e-3, 1.2e9)
    assert variables.bounds().shape == (11, 2)


def test_a_cut_depth_gives_the_body_files_one_sided_cut() -> None:
    """The body file's ``cut`` (its own parser) and the variable ``cut`` make the same notches."""
    wrist = named_design(str(REPO / "config" / "bodies" / "tip_first_wrist.yaml"))
    flat = VariableSet(wrist, (Variable("cut", 0.5e-3, 1.5e-3, "uniform"),)).design([1.0e-3])
    variables = VariableSet(flat, (Variable("cut", 0.5e-3, 1.5e-3, "each"),))
    design = variables.design([1.36e-3, 1.39e-3, 1.42e-3, 1.45e-3])
    assert design.per_notch("w_d") == pytest.approx(wrist.per_notch("w_d"), rel=1e-12)
    assert design.per_notch("w_o") == pytest.approx(wrist.per_notch("w_o"), rel=1e-12)
    # the material left reaches from the -x surface to R_outer - cut
    edge = design.per_notch("w_o") + design.per_notch("w_d") / 2
    assert edge == pytest.approx(wrist.R_outer - np.array([1.36e-3, 1.39e-3, 1.42e-3, 1.45e-3]))


def test_the_tendon_offset_follows_R_c_on_its_side() -> None:
    base = replace(PAPER, tendons=(Tendon(-2.75e-3, name="t"),))
    design = VariableSet(base, (Variable("R_c", 1e-3, 3e-3),)).design([2.0e-3])
    assert design.R_c == 2.0e-3 and design.tendons[0].offset == -2.0e-3


@pytest.mark.parametrize(("variable", "parameter"), [
    ({"field": "w_x", "low": 0.0, "high": 1.0}, "vary.field"),
    ({"field": "R_outer", "low": 1e-3, "high": 2e-3, "law": "linear"}, "vary[R_outer].law"),
    ({"field": "w_d", "low": 1e-3, "high": 2e-3, "law": "cubic"}, "vary[w_d].law"),
    ({"field": "w_d", "low": 2e-3, "high": 1e-3}, "vary[w_d].high"),
    ({"field": "w_d", "low": -1e-3, "high": 1e-3}, "vary[w_d].low"),
    ({"field": "E", "low": 1e9, "high": math.inf}, "vary[E].high"),
])
def test_a_bad_variable_names_its_key(variable: dict, parameter: str) -> None:
    with pytest.raises(InvalidDesignError) as caught:
        Variable(**variable)
    assert caught.value.parameter == parameter


def test_a_bad_variable_set_is_refused() -> None:
    with pytest.raises(InvalidDesignError, match="each field once"):
        VariableSet(PAPER, (Variable("w_d", 1e-4, 1e-3), Variable("cut", 1e-4, 1e-3)))
    with pytest.raises(InvalidDesignError, match="2 or more notches"):
        VariableSet(preset("paper-experiment").with_overrides(N=1),
                    (Variable("w_t", 1e-4, 1e-3),))
    with pytest.raises(InvalidDesignError, match="shape"):
        VariableSet(PAPER, (Variable("w_d", 1e-4, 1e-3, "linear"),)).design([1e-3])
    with pytest.raises(InvalidDesignError):  # a cut deeper than the tube: no design
        VariableSet(PAPER, (Variable("cut", 1e-4, 9e-3),)).design([8.5e-3])
