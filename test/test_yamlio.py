"""The bounded YAML loader: hostile texts fail fast with a typed error naming the problem."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.errors import InputError
from tdcm_ros.yamlio import MAX_DEPTH_LEVELS, MAX_INPUT_BYTES, YamlInputError, load_yaml

Stopwatch = Callable[[str], AbstractContextManager[None]]


def test_hostile_yaml_is_a_typed_error_naming_source_and_limit(
        hostile_yaml: tuple[str, str, str], stopwatch: Stopwatch) -> None:
    name, text, phrase = hostile_yaml
    with stopwatch(f"load_yaml {name} ({len(text)} chars)"), \
            pytest.raises(YamlInputError, match=phrase) as caught:
        load_yaml(text, "cfg.yaml", parameter="params_file")
    message = str(caught.value)
    assert message.startswith("cfg.yaml: ") and "\n" not in message
    assert caught.value.parameter == "params_file" and caught.value.value == "cfg.yaml"
    assert caught.value.allowed


def test_limits_name_the_line() -> None:
    deep = "a:\n" + "".join("  " * i + "- \n" for i in range(1, MAX_DEPTH_LEVELS + 2))
    with pytest.raises(YamlInputError, match=f"cfg: line {MAX_DEPTH_LEVELS + 1}: nesting"):
        load_yaml(deep, "cfg")
    with pytest.raises(YamlInputError, match="cfg: line 2: anchors and aliases"):
        load_yaml("a: 1\nb: &x 2\n", "cfg")
    with pytest.raises(YamlInputError, match="at line 3$"):
        load_yaml("a\nb\n" + "c" * MAX_INPUT_BYTES, "cfg")


def test_bounds_are_inclusive_and_plain_yaml_loads_as_safe_load() -> None:
    nested = "[" * MAX_DEPTH_LEVELS + "]" * MAX_DEPTH_LEVELS
    assert load_yaml(nested, "cfg") == yaml.safe_load(nested)
    text = "a: [1, {b: 2.5e+0}]\nc: ~\n<<: {d: x}\nt: 2020-01-02\n"
    assert load_yaml(text, "cfg") == yaml.safe_load(text)
    assert load_yaml("", "cfg") is None


def test_bad_scalars_and_syntax_are_typed_errors() -> None:
    for text, phrase in (("d: 2020-13-01", "line 1: .*month"), ("n: " + "9" * 5000, "digits"),
                         ("a: [1, 2\n", "not valid YAML"), ("a: !!python/name:os.system x",
                                                             "constructor"),
                         ("a: 1\n---\nb: 2\n", "single document"),
                         ("a: !!float ", "line 1: .*build tag:yaml.org,2002:float"),
                         ("a: !!bool x", "line 1: .*bool .KeyError: 'x'"),
                         ("a: !!timestamp x", "line 1: .*AttributeError")):
        with pytest.raises(YamlInputError, match=phrase):
            load_yaml(text, "cfg")


def test_error_class_is_chosen_by_the_caller_and_is_a_yaml_error() -> None:
    class SceneLikeError(InputError):
        pass

    with pytest.raises(SceneLikeError, match="duplicate key"):
        load_yaml("a: 1\na: 2\n", "scene.yaml", error=SceneLikeError)
    assert issubclass(YamlInputError, yaml.YAMLError) and issubclass(YamlInputError, InputError)


_TOKENS = st.sampled_from(["[", "]", "{", "}", ",", ": ", "- ", "\n", "  ", "a", "1", "&x ",
                           "*x", "? ", "!!str ", "'", '"', "#", "---\n", "<<: ", "2020-13-01"])


@settings(max_examples=300)
@given(st.one_of(st.text(max_size=200), st.lists(_TOKENS, max_size=80).map("".join),
                 st.tuples(st.sampled_from(["[", "{a: ", "- ", "a:\n  "]),
                           st.integers(0, 3000)).map(lambda pair: pair[0] * pair[1])))
def test_any_text_gives_a_value_or_a_typed_error(text: str) -> None:
    try:
        load_yaml(text, "cfg")
    except YamlInputError as error:
        assert str(error).startswith("cfg")


@pytest.mark.parametrize("text", ["1e9", "1.0e9", "-2E-3", "+.5e3", "1.e9", "7e+0", "1.0e+9"])
def test_a_number_with_an_exponent_is_a_float_as_in_yaml_1_2(text: str) -> None:
    """YAML 1.1 (``yaml.safe_load``) reads ``1.0e9`` as a string; ``tdcm param set X E 1.0e9``
    must set a float."""
    value = load_yaml(text, "cfg")
    assert isinstance(value, float) and value == float(text)
    assert load_yaml(f"E: {text}\nlist: [{text}]", "cfg") == {"E": float(text), "list": [float(text)]}


@pytest.mark.parametrize("text", ["1e", "e9", "1e9x", "1_000e3", "'1e9'", "0x1e9", "1e9.5"])
def test_near_exponent_strings_keep_their_yaml_1_1_reading(text: str) -> None:
    assert load_yaml(text, "cfg") == yaml.safe_load(text)


@settings(max_examples=200)
@given(st.floats(allow_nan=False, allow_infinity=False), st.sampled_from(["e", "E"]),
       st.sampled_from(["", "+", "-"]))
def test_exponent_spellings_of_any_float_read_back_exactly(x: float, e: str, sign: str) -> None:
    mantissa, _, exponent = f"{x:.17e}".partition("e")
    text = f"{mantissa}{e}{sign}{exponent.lstrip('+-')}"
    assert load_yaml(text, "cfg") == float(text)
