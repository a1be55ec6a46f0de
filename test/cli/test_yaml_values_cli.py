"""YAML values on the command line (``tdcm param set``, ``tdcm topic pub``) are bounded:
hostile ones are one-line input errors (exit status 2) before any node is contacted."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager

import pytest

from tdcm_ros.cli.main import main

Stopwatch = Callable[[str], AbstractContextManager[None]]


@pytest.mark.parametrize("argv", [["param", "set", "model_node", "design.E"],
                                  ["topic", "pub", "tension", "std_msgs/msg/Float64"]],
                         ids=["param_set", "topic_pub"])
def test_hostile_yaml_value_is_a_one_line_input_error(
        argv: list[str], hostile_yaml: tuple[str, str, str],
        capsys: pytest.CaptureFixture[str], stopwatch: Stopwatch) -> None:
    name, text, phrase = hostile_yaml
    with stopwatch(f"tdcm {' '.join(argv[:2])} {name}"):
        status = main([*argv, text])
    captured = capsys.readouterr()
    with capsys.disabled():
        print(captured.out.strip())  # the stopwatch's line
    err = captured.err.strip()
    assert status == 2 and len(err.splitlines()) == 1, err
    source = argv[-1] if argv[0] == "param" else "values"
    assert phrase in err and f"{source}: " in err
