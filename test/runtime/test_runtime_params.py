"""Parameter specs and store, the ROS parameter YAML reader, names, runtime selection."""

from __future__ import annotations

import math
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.names import resolve_topic
from tdcm_ros.runtime.parameters import ParameterStore, ParamSpec
from tdcm_ros.runtime.params import node_parameters, param_file_text, read_param_file
from tdcm_ros.runtime.run_node import resolve_runtime
from test.runtime.test_params_rcl_table import same

YAML = """
/**:
  ros__parameters:
    rate: 1.0
talker:
  ros__parameters:
    rate: 2.0
    solver: {tol: 1.0e-6}
robot1:
  talker:
    ros__parameters:
      rate: 5.0
/*/model:
  ros__parameters:
    arc_lengths: [0.015, 0.033, 0.053]
"""


@pytest.fixture
def param_file(tmp_path: Path) -> Path:
    path = tmp_path / "params.yaml"
    path.write_text(YAML)
    return path


def test_yaml_wildcards_exact_and_nested(param_file: Path) -> None:
    assert [key for key, _ in read_param_file(param_file)] == [
        "/**", "talker", "robot1/talker", "/*/model"]
    assert node_parameters([param_file], "/talker") == {"rate": 2.0, "solver.tol": 1e-6}
    assert node_parameters([param_file], "/robot1/talker") == {"rate": 5.0}
    assert node_parameters([param_file], "/a/model")["arc_lengths"] == [0.015, 0.033, 0.053]
    assert node_parameters([param_file], "/model") == {"rate": 1.0}
    assert node_parameters([], "/talker") == {}


def test_bad_yaml_is_an_input_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("talker:\n  rate: 1\n")
    with pytest.raises(InputError, match="not under ros__parameters"):
        read_param_file(bad)


def test_spec_types_ranges_and_validators() -> None:
    def positive_list(values: Any) -> None:
        if any(v <= 0 for v in values):
            raise InputError("arc_lengths must be > 0 m", parameter="arc_lengths")

    spec = ParamSpec("tension", 1.0, "N", range=(0.0, 50.0))
    assert spec.coerce(3) == 3.0
    with pytest.raises(InputError, match="out of range"):
        spec.coerce(51.0)
    with pytest.raises(InputError, match="expected float"):
        spec.coerce("x")
    with pytest.raises(InputError, match="not finite"):
        spec.coerce(float("nan"))
    lengths = ParamSpec("arc_lengths", [0.015], validator=positive_list)
    assert lengths.coerce([1, 2]) == [1.0, 2.0]
    with pytest.raises(InputError, match="> 0 m"):
        lengths.coerce([0.01, -1.0])


def test_rejected_change_keeps_old_value_and_reports_reason() -> None:
    store = ParameterStore({"period": 0.2})
    assert store.declare(ParamSpec("period", 0.5, range=(1e-3, 60.0))) == 0.2
    seen: list[Mapping[str, Any]] = []
    store.add_on_set(seen.append)
    result = store.set({"period": -1.0})
    assert not result.successful and "out of range" in result.reason
    assert store.get("period") == 0.2 and seen == []
    assert store.set({"period": 1.0}).successful and store.get("period") == 1.0
    assert seen == [{"period": 1.0}]


def test_node_check_can_reject() -> None:
    store = ParameterStore()
    store.declare(ParamSpec("low", 1.0))

    def refuse(changes: Mapping[str, Any]) -> None:
        raise InputError("low must stay below high", parameter="low")

    store.add_on_set(refuse)
    assert store.set({"low": 2.0}).reason == "low must stay below high"
    assert store.get("low") == 1.0
    with pytest.raises(InputError, match="declared twice"):
        store.declare(ParamSpec("low", 1.0))


@pytest.mark.parametrize(("topic", "namespace", "expected"), [
    ("tension", "/", "/tension"),
    ("tension", "/robot1", "/robot1/tension"),
    ("/abs", "/robot1", "/abs"),
    ("~/set_parameters", "/r", "/r/model/set_parameters"),
])
def test_topic_resolution(topic: str, namespace: str, expected: str) -> None:
    assert resolve_topic(topic, namespace, "model") == expected


def test_invalid_topic_names() -> None:
    for bad in ("a//b", "1abc", "a b", "a/"):
        with pytest.raises(InputError):
            resolve_topic(bad)


def test_runtime_selection(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("TDCM_RUNTIME", "zenoh")
    assert resolve_runtime("auto") == "zenoh"
    assert resolve_runtime("rclpy") == "rclpy"
    monkeypatch.setenv("TDCM_RUNTIME", "bogus")
    with pytest.raises(InputError, match="TDCM_RUNTIME"):
        resolve_runtime("auto")
    monkeypatch.delenv("TDCM_RUNTIME")
    assert resolve_runtime("auto") in ("zenoh", "rclpy")


def test_a_former_name_in_the_file_sets_the_parameter_and_warns() -> None:
    heard: list[str] = []
    store = ParameterStore({"markers.radius": 0.002}, warn=heard.append)
    value = store.declare(ParamSpec("markers.ball_radius", 0.001, formerly=("markers.radius",)))
    assert value == 0.002 and store.get("markers.ball_radius") == 0.002
    assert heard == [("parameter markers.radius is deprecated; use markers.ball_radius "
                     "(same meaning)")]
    assert store.unused_overrides() == []


def test_the_current_name_wins_over_a_former_one_which_is_warned_as_ignored() -> None:
    heard: list[str] = []
    store = ParameterStore({"markers.radius": 0.003, "markers.ball_radius": 0.002},
                           warn=heard.append)
    assert store.declare(ParamSpec("markers.ball_radius", 0.001,
                                   formerly=("markers.radius",))) == 0.002
    assert len(heard) == 1 and "ignored, markers.ball_radius is set too" in heard[0]


def test_unused_overrides_are_what_no_declared_parameter_took() -> None:
    store = ParameterStore({"rate": 2.0, "rtae": 3.0, "other.x": 1})
    store.declare(ParamSpec("rate", 1.0))
    assert store.unused_overrides() == ["other.x", "rtae"]


def test_a_node_warns_of_names_its_own_entry_sets_but_not_of_wildcard_ones(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    from tdcm_ros.runtime.memory_port import MemoryPort
    from tdcm_ros.runtime.run_node import warn_unused_overrides

    path = tmp_path / "params.yaml"
    path.write_text("/**:\n  ros__parameters:\n    shared_by_others: 1\n"
                    "talker:\n  ros__parameters:\n    rate: 2.0\n    rtae: 3.0\n"
                    "/**/talker:\n  ros__parameters:\n    prefx: x\n")
    port = MemoryPort(node_parameters([path], "/talker"), name="talker")
    port.declare_parameter("rate", 1.0)
    with caplog.at_level("WARNING"):
        warn_unused_overrides(port, [str(path)])
    warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert warned == [f"parameter file {path} sets {name} for /talker, which does not declare "
                      "it: ignored" for name in ("prefx", "rtae")]


_SCALARS = st.one_of(st.booleans(), st.integers(-(2**63), 2**63 - 1), st.floats(),
                     st.text(max_size=12), st.sampled_from(["y", "n", "1e9", "~", "0x1F", "", "null"]))


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(st.from_regex(r"[a-z][a-z0-9_]{0,8}(\.[a-z][a-z0-9_]{0,8})?", fullmatch=True),
                       st.one_of(_SCALARS, st.lists(st.booleans(), min_size=1, max_size=4),
                                 st.lists(st.floats(), min_size=1, max_size=4),
                                 st.lists(st.text(max_size=6), min_size=1, max_size=4)),
                       max_size=6))
@example({"tiny": 5e-324, "tinies": [-2.2e-308, 1e-310], "nan": math.nan, "inf": [-math.inf],
          "words": ["y", "~", "1e9", "0x1F", "", "\x85", "a\nb", " lead", "'\"\\"],
          "big": 2**63 - 1, "true": False})
def test_a_written_parameter_file_reads_back_to_the_same_values(values: dict[str, Any]) -> None:
    if any(a.startswith(b + ".") for a in values for b in values):
        return  # a name and a dotted child of it cannot both be parameters of one node
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "params.yaml"
        path.write_text(param_file_text({"/lab/talker": values}), encoding="utf-8")
        read = node_parameters([path], "/lab/talker")
    assert same(read, values)


@pytest.mark.parametrize("value", [None, [], [1, 2.5], [[1]], {"a": 1}])
def test_a_value_rcl_cannot_hold_is_not_written(value: Any) -> None:
    with pytest.raises(InputError, match="cannot be written as an rcl parameter"):
        param_file_text({"/talker": {"x": value}})


def test_the_embedded_runtime_takes_params_files_and_p_but_refuses_other_ros_arguments(
        tmp_path: Path) -> None:
    from tdcm_ros.runtime.run_node import embedded_sources

    path = tmp_path / "p.yaml"
    path.write_text("/**:\n  ros__parameters:\n    rate: 1.0\n    period: 2.0\n")
    sources = embedded_sources(None, ["--ros-args", "--params-file", str(path), "-p", "rate:=3.0"])
    assert node_parameters(sources, "/talker") == {"rate": 3.0, "period": 2.0}
    for flag, value in [("-r", "chatter:=talk"), ("--remap", "__ns:=/x"), ("--log-level", "debug"),
                        ("--enclave", "/e")]:
        with pytest.raises(InputError, match=f"ROS argument '{flag}' is not supported by the "
                                             "embedded runtime") as caught:
            embedded_sources(str(path), ["--ros-args", flag, value])
        assert caught.value.parameter == "--ros-args"
    with pytest.raises(InputError, match="-p has no value"):
        embedded_sources(None, ["--ros-args", "-p"])
