"""``-p name:=value`` values of the rclpy runtime are read through the bounded YAML loader
(``RclpyContext.file_overrides`` needs no rclpy, so this runs without ROS)."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.rclpy_runtime import RclpyContext

Stopwatch = Callable[[str], AbstractContextManager[None]]


def _context(cli_params: list[str]) -> RclpyContext:
    """A context holding only ``-p`` values (``__init__`` would start rclpy)."""
    context = object.__new__(RclpyContext)
    context.params_files = []
    context.cli_params = cli_params
    return context


def test_hostile_dash_p_value_is_an_input_error_naming_it(
        hostile_yaml: tuple[str, str, str], stopwatch: Stopwatch) -> None:
    name, text, phrase = hostile_yaml
    context = _context([f"talker:rate:={text}"])
    with stopwatch(f"-p talker:rate:= {name}"), pytest.raises(InputError, match=phrase) as caught:
        context.file_overrides("/talker", "talker")
    assert str(caught.value).startswith("-p talker:rate: ")
