"""Parameter files and YAML parameter values are read through the bounded YAML loader."""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from contextlib import AbstractContextManager
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.params import CliParam, node_parameters, read_param_file
from test.conftest import HOSTILE_YAML

Stopwatch = Callable[[str], AbstractContextManager[None]]
#: the hostile texts that exceed a bound (a repeated key is not one for rcl: it merges)
BOUNDS = sorted(name for name in HOSTILE_YAML if not name.startswith("duplicate"))


@pytest.mark.parametrize("name", BOUNDS)
def test_hostile_parameter_file_is_an_input_error_naming_file_and_limit(
        tmp_path: Path, name: str, stopwatch: Stopwatch) -> None:
    text, phrase = HOSTILE_YAML[name]
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    with stopwatch(f"read_param_file {name}"), pytest.raises(InputError, match=phrase) as caught:
        read_param_file(path)
    assert str(caught.value).startswith(f"{path}: ") and caught.value.parameter == "params_file"


@pytest.mark.parametrize("name", BOUNDS)
def test_hostile_dash_p_value_is_an_input_error_naming_it(name: str, stopwatch: Stopwatch) -> None:
    text, phrase = HOSTILE_YAML[name]
    with stopwatch(f"-p talker:rate:= {name}"), pytest.raises(InputError, match=phrase) as caught:
        node_parameters([CliParam(f"talker:rate:={text}")], "/talker")
    assert str(caught.value).startswith("-p talker:rate: ")


def test_a_repeated_parameter_takes_the_later_value_as_rcl_does(tmp_path: Path) -> None:
    path = tmp_path / "params.yaml"
    path.write_text("talker:\n  ros__parameters:\n    rate: 1.0\n    rate: 2.0\n")
    assert read_param_file(path) == [("talker", {"rate": 2.0})]


def test_non_utf8_parameter_file_is_an_input_error(tmp_path: Path) -> None:
    path = tmp_path / "params.yaml"
    path.write_bytes(b"talker:\n  ros__parameters:\n    name: \xff\n")
    with pytest.raises(InputError, match="cannot read parameter file"):
        read_param_file(path)


_PARAM_TOKENS = st.sampled_from(["/**:\n", "talker:\n", "  ros__parameters:\n", "    rate: ",
                                 "    ", "  ", "- ", "[", "]", "{", "}", ", ", "&a ", "*a", "1.0",
                                 "x", "~", "2020-13-01", "\n", "a: ", "? "])


@settings(max_examples=150)
@given(st.one_of(st.binary(max_size=200).map(lambda b: b.decode("latin-1")),
                 st.lists(_PARAM_TOKENS, max_size=60).map("".join),
                 st.tuples(st.sampled_from(["[", "{a: ", "- "]), st.integers(0, 3000))
                 .map(lambda pair: "talker:\n  ros__parameters:\n    x: " + pair[0] * pair[1])))
def test_parameter_file_reader_returns_entries_or_an_input_error(text: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "params.yaml"
        path.write_text(text, encoding="utf-8")
        try:
            assert isinstance(read_param_file(path), list)
        except InputError:
            pass
