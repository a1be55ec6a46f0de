"""The one parameter spec: check, parse and allowed over ranges and kinds; the dataclass helpers."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.errors import InputError
from tdcm_ros.model import InvalidSettingsError
from tdcm_ros.spec import (
    MAX_ITEMS,
    MAX_TEXT_CHARS,
    Spec,
    check_fields,
    kind_of,
    parse_mapping,
    spec_field,
    spec_table,
    specs_of,
)

FINITE = st.floats(-1e9, 1e9, allow_nan=False)


@st.composite
def ranges(draw: st.DrawFn) -> Spec:
    """A float spec with finite bounds ``low < high`` and random open ends."""
    low = draw(FINITE)
    high = draw(FINITE.filter(lambda v: v > low + 1e-6 * max(1.0, abs(low))))
    return Spec("x", "m", "", 0.0, low=low, high=high, low_open=draw(st.booleans()),
                high_open=draw(st.booleans()))


def inside(spec: Spec, value: float) -> bool:
    above = value > spec.low if spec.low_open else value >= spec.low
    below = value < spec.high if spec.high_open else value <= spec.high
    return above and below


@given(spec=ranges(), value=st.floats(allow_nan=True, allow_infinity=True))
def test_a_number_is_accepted_exactly_when_it_is_finite_and_in_range(spec: Spec,
                                                                      value: float) -> None:
    if math.isfinite(value) and inside(spec, value):
        assert spec.check(value) == value
        assert spec.parse(repr(value)) == value  # text round trip
        return
    with pytest.raises(InputError) as caught:
        spec.check(value, "group.x")
    error = caught.value
    assert (error.parameter, error.allowed) == ("group.x", spec.allowed())
    assert error.value == value or math.isnan(value)
    assert str(error).startswith("group.x = ") and spec.allowed() in str(error)


@given(spec=ranges())
def test_the_allowed_text_shows_the_bounds_their_ends_and_the_unit(spec: Spec) -> None:
    text = spec.allowed()
    assert text[0] == ("(" if spec.low_open else "[")
    assert text.endswith((")" if spec.high_open else "]") + " m")
    low, high = text[1:].rsplit(" ", 1)[0][:-1].split(", ")
    assert (float(low), float(high)) == (spec.low, spec.high)  # the true bounds, not rounded


@pytest.mark.parametrize(("spec", "allowed"), [
    (Spec("a", "m", low=0.0, high=1.0, low_open=True), "(0, 1] m"),
    (Spec("a", "N", low=0.0), ">= 0 N"),
    (Spec("a", "s", low=0.0, low_open=True), "> 0 s"),
    (Spec("a", "N"), "a finite number N"),
    (Spec("a", kind="int", low=1, high=512), "an integer in [1, 512]"),
    (Spec("a", kind="int", low=1), "an integer >= 1"),
    (Spec("a", "deg", kind="vector"), "3 numbers deg"),
    (Spec("a", "m", kind="list", low=0.0, high=2.0), "a list of numbers in [0, 2] m"),
    (Spec("a", kind="str", choices=("x", "y")), "x | y"),
    (Spec("a", kind="bool"), "true | false"),
    (Spec("a", kind="names"), "a list of distinct non-empty strings"),
])
def test_allowed_text_by_kind(spec: Spec, allowed: str) -> None:
    assert spec.allowed() == allowed


@given(low=st.integers(-1000, 1000), span=st.integers(0, 1000), value=st.integers(-3000, 3000))
def test_integers_check_their_range_and_refuse_fractions(low: int, span: int, value: int) -> None:
    spec = Spec("n", kind="int", low=low, high=low + span)
    if low <= value <= low + span:
        assert spec.check(value) == value and isinstance(spec.check(np.int64(value)), int)
        assert spec.parse(str(value)) == value == spec.parse(f"{value}.0")
        with pytest.raises(InputError, match="is not an integer"):
            spec.check(value + 0.5)
        with pytest.raises(InputError, match="is not an integer"):
            spec.parse(f"{value}.5")
    else:
        with pytest.raises(InputError, match="is out of range"):
            spec.check(value)


@pytest.mark.parametrize("kind", ["float", "int"])
@pytest.mark.parametrize("bad", [True, "1.0", None, [1.0]])
def test_check_refuses_non_numbers_and_strings(kind: str, bad: object) -> None:
    with pytest.raises(InputError, match="is not an? "):
        Spec("v", kind=kind).check(bad)


def test_parse_reads_text_as_cli_and_yaml_give_it() -> None:
    assert Spec("E", "Pa").parse("1.85e9") == 1.85e9  # YAML 1.1 leaves this a string
    flag = Spec("f", kind="bool")
    assert [flag.parse(t) for t in ("true", "False", "1", "no", "on")] == [
        True, False, True, False, True]
    with pytest.raises(InputError, match="f = 'maybe' is not true or false"):
        flag.parse("maybe")
    with pytest.raises(InputError):
        flag.check("true")  # check takes typed values only
    assert Spec("s", kind="list").parse("0.1, 0.2,0.3") == (0.1, 0.2, 0.3)
    assert Spec("l", kind="names").parse("m1,m2") == ("m1", "m2")


def test_choices_and_strings() -> None:
    spec = Spec("routing", kind="str", choices=("paper", "free"))
    assert spec.check("free") == "free"
    with pytest.raises(InputError) as caught:
        spec.check("tight")
    assert str(caught.value) == "routing = 'tight' is out of range; allowed: paper | free"
    with pytest.raises(InputError, match="is not a string"):
        spec.check(3)


@given(values=st.lists(st.floats(-10.0, 10.0), min_size=1, max_size=6))
def test_sequences_check_every_element_and_name_the_bad_one(values: list[float]) -> None:
    spec = Spec("levels", "N", kind="list", low=0.0)
    bad = [v for v in values if v < 0.0]
    if not bad:
        assert spec.check(values) == tuple(values)
        assert spec.check(np.asarray(values)) == tuple(values)
        return
    with pytest.raises(InputError) as caught:
        spec.check(values)
    assert caught.value.value == bad[0]
    assert f"levels = {bad[0]!r} N is out of range" in str(caught.value)


def test_vectors_and_names_check_their_shape() -> None:
    vector = Spec("rpy", "deg", kind="vector", size=3)
    assert vector.check([1, 2, 3]) == (1.0, 2.0, 3.0)
    for bad in ([1.0, 2.0], [], "1,2,3", {"x": 1}):
        with pytest.raises(InputError):
            vector.check(bad)
    names = Spec("labels", kind="names")
    assert names.check(["a", "b"]) == ("a", "b")
    for bad in (["a", "a"], ["a", ""], [], ["a", 1]):
        with pytest.raises(InputError):
            names.check(bad)


def test_a_spec_refuses_an_unknown_kind() -> None:
    with pytest.raises(ValueError, match="kind 'complex'"):
        Spec("z", kind="complex")


@pytest.mark.parametrize(("default", "kind"), [
    (True, "bool"), (3, "int"), (0.5, "float"), ("x", "str"), (("a", "b"), "names"),
    ((0.1, 0.2), "list"), (None, "float")])
def test_kind_of_a_default(default: object, kind: str) -> None:
    assert kind_of(default) == kind


@dataclass(frozen=True)
class _Settings:
    """A settings dataclass as the package declares them."""

    tol: float = spec_field(1e-3, unit="m", low=0.0, high=1.0, low_open=True, description="tol")
    steps: int = spec_field(4, low=1, high=10)
    mode: str = spec_field("a", choices=("a", "b"))
    align: float = spec_field(0.0, name="align.tolerance_s", unit="s", low=0.0)
    extra: list[int] = field(default_factory=list)  # not a parameter

    def __post_init__(self) -> None:
        check_fields(self, specs_of(_Settings), prefix="opt.", error=InvalidSettingsError)


def test_specs_of_collects_the_declared_fields_with_their_defaults() -> None:
    specs = specs_of(_Settings)
    assert list(specs) == ["tol", "steps", "mode", "align"]
    assert [s.name for s in specs.values()] == ["tol", "steps", "mode", "align.tolerance_s"]
    assert [s.kind for s in specs.values()] == ["float", "int", "str", "float"]
    assert specs["tol"].default == 1e-3 and specs["mode"].choices == ("a", "b")
    assert spec_table(specs.values(), "opt.")[0] == {
        "name": "opt.tol", "unit": "m", "default": "0.001", "allowed": "(0, 1] m",
        "description": "tol"}


def test_check_fields_validates_normalises_and_names_with_the_prefix() -> None:
    assert _Settings(tol=1).tol == 1.0 and isinstance(_Settings(tol=1).tol, float)
    with pytest.raises(InvalidSettingsError) as caught:
        _Settings(align=-1.0)
    assert caught.value.parameter == "opt.align.tolerance_s"
    with pytest.raises(InvalidSettingsError, match="opt.steps = 0 is out of range"):
        _Settings(steps=0)


def test_parse_mapping_fills_defaults_and_refuses_unknown_keys() -> None:
    specs = specs_of(_Settings).values()
    values = parse_mapping("solver", specs, {"tol": "1e-4", "steps": 3})
    assert values == {"tol": 1e-4, "steps": 3, "mode": "a", "align.tolerance_s": 0.0}
    assert parse_mapping("solver", specs, None)["steps"] == 4
    with pytest.raises(InvalidSettingsError, match="unknown key in solver 'tolx'"):
        parse_mapping("solver", specs, {"tolx": 1.0}, error=InvalidSettingsError)
    with pytest.raises(InputError, match="solver.steps = 11 is out of range"):
        parse_mapping("solver", specs, {"steps": 11})
    with pytest.raises(InputError, match="is not a mapping"):
        parse_mapping("solver", specs, [1, 2])


@given(spec=ranges())
def test_bounds_are_the_finite_range_a_ros_descriptor_shows(spec: Spec) -> None:
    assert spec.bounds == (spec.low, spec.high)
    assert Spec("x", low=0.0).bounds is None and Spec("s", kind="str").bounds is None


def _settings_classes() -> list[type]:
    from tdcm_ros.device.driver import DriverConfig
    from tdcm_ros.device.plant import PlantConfig
    from tdcm_ros.device.schedule import StepSchedule
    from tdcm_ros.metrics.geometry import MarkerLayout
    from tdcm_ros.metrics.options import EvaluateOptions
    from tdcm_ros.metrics.steps import StepSettings
    from tdcm_ros.model import Design, SolverSettings
    return [Design, SolverSettings, StepSettings, MarkerLayout, EvaluateOptions, DriverConfig,
            PlantConfig, StepSchedule]


#: Fields that hold objects or groups, not parameters.
NOT_PARAMETERS = {"profile", "tendons", "material", "design", "solver", "steps", "layout",
                  "uncertainty"}


@pytest.mark.parametrize("cls", _settings_classes(), ids=lambda c: c.__name__)
def test_every_settings_field_is_declared_with_a_spec(cls: type) -> None:
    """A field added without ``spec_field`` would be unchecked and unknown to nodes and --set."""
    from dataclasses import fields

    missing = {f.name for f in fields(cls)} - set(specs_of(cls)) - NOT_PARAMETERS
    assert not missing, f"{cls.__name__}: declare {sorted(missing)} with spec_field"
    instance_defaults = {name: spec.default for name, spec in specs_of(cls).items()
                         if spec.default is not None}
    for name, default in instance_defaults.items():
        specs_of(cls)[name].check(default)  # every default is allowed by its own spec


@given(ranges(), st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_a_narrowed_spec_allows_only_values_its_source_allows(spec: Spec, a: float, b: float
                                                             ) -> None:
    span = spec.high - spec.low
    low, high = sorted((spec.low + (0.01 + 0.49 * a) * span, spec.low + (0.5 + 0.49 * b) * span))
    narrow = spec.narrowed(low=low, high=high)
    assert (narrow.low, narrow.high, narrow.unit, narrow.name) == (low, high, "m", "x")
    for value in np.linspace(spec.low, spec.high, 41):
        if inside(narrow, float(value)):
            assert inside(spec, float(value))


@pytest.mark.parametrize("bounds", [{"low": -1.0}, {"high": 11.0}, {"low": 0.0}])
def test_narrowing_may_not_widen_a_range(bounds: dict[str, float]) -> None:
    source = Spec("lag", "s", low=0.0, low_open=True, high=10.0)
    with pytest.raises(ValueError, match="'lag'.*widens"):
        source.narrowed(**bounds)
    assert source.narrowed(high=10.0) == source  # the same closed bound is no widening


def test_a_renamed_spec_keeps_unit_meaning_and_range() -> None:
    source = Spec("hold", "s", "hold time", 5.0, low=0.01, high=86_400.0)
    renamed = source.renamed("hold_s")
    assert renamed.name == "hold_s" and renamed.default == 5.0
    assert source.renamed("hold_s", default=None).default is None
    assert renamed.renamed("hold", default=5.0) == source
    with pytest.raises(InputError, match=r"hold_s = 0.0 is out of range; allowed: \[0.01, 86400\] s"):
        renamed.check(0.0)


def test_a_choice_matches_with_hyphen_and_underscore_alike_and_keeps_its_spelling() -> None:
    from tdcm_ros.nodes.model_node import PARAMETERS

    preset_spec = PARAMETERS["design.preset"]
    assert preset_spec.check("paper_experiment") == "paper-experiment"
    assert preset_spec.parse("fig2_wn_1.9") == "fig2-wn-1.9"
    snake = Spec("axis", kind="str", choices=("tip_marker", "body"))
    assert snake.check("tip-marker") == "tip_marker"
    with pytest.raises(InputError) as refused:
        snake.check("tip marker")
    assert "allowed: tip_marker | body" in str(refused.value)


@pytest.mark.parametrize("kind", ["str", "names", "list", "vector"])
def test_strings_and_sequences_are_bounded_and_the_error_stays_short(kind: str) -> None:
    """A parameter's value is echoed in messages (a frame_id in every tension): at most
    MAX_TEXT_CHARS characters and MAX_ITEMS elements; the refusal names the parameter and the
    limit and shows only the value's start and length."""
    spec = Spec("frame_id", kind=kind, size=MAX_ITEMS + 1)
    fits = "f" * MAX_TEXT_CHARS if kind == "str" else \
        [f"n{i}" if kind == "names" else float(i) for i in range(MAX_ITEMS)]
    too_long = fits + "f" if kind == "str" else [*fits, "extra" if kind == "names" else 1.0]
    if kind != "vector":
        assert len(spec.check(fits)) == len(fits)
    with pytest.raises(InputError) as caught:
        spec.check(too_long)
    unit = "characters" if kind == "str" else "elements"
    limit = MAX_TEXT_CHARS if kind == "str" else MAX_ITEMS
    assert f"allowed: at most {limit} {unit}" in str(caught.value)
    assert str(caught.value).startswith("frame_id = ")
    assert f"({len(too_long)} {unit})" in str(caught.value)
    assert len(str(caught.value)) < 200


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_a_printed_bound_reads_back_as_the_bound(value: float) -> None:
    """exact_number is ``:g`` when that is the same float, else every digit needed."""
    from tdcm_ros.errors import exact_number

    shown = exact_number(value)
    assert float(shown) == value
    assert len(shown) <= len(repr(value)) or shown == f"{value:g}"


def test_a_bound_that_g_would_round_is_printed_whole() -> None:
    from tdcm_ros.errors import exact_number

    assert exact_number(0.08) == "0.08" and exact_number(20.0) == "20"
    assert exact_number(0.0799999999997) == "0.0799999999997"
    assert Spec("x", "m", "", 0.01, low=0.0, high=0.0799999999997).allowed() == \
        "[0, 0.0799999999997] m"
