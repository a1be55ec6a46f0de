"""``tdcm up``'s plan from its options: ``-p NODE:NAME:=VALUE`` and ``--use-sim-time`` become
the nodes' parameter overrides (over ``--params``); bad ones are typed errors naming them."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from tdcm_ros.cli.up import plan, register
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.graph import merged_params
from tdcm_ros.runtime.params import node_parameters


def up_args(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    return parser.parse_args(["up", *argv])


def test_p_sets_one_nodes_parameter_read_as_yaml() -> None:
    nodes, overrides, _ = plan(up_args("--nodes", "model_node,metrics_node", "-p",
                                       "model_node:input.max_age_s:=2.0", "-p",
                                       "metrics_node:markers.arc_lengths:=[0.02, 0.05]"), 1)
    assert nodes == ["model_node", "metrics_node"]
    assert overrides == {"model_node": {"input.max_age_s": 2.0},
                         "metrics_node": {"markers.arc_lengths": [0.02, 0.05]}}


def test_use_sim_time_sets_it_on_every_node_and_reaches_the_parameter_file(tmp_path) -> None:
    nodes, overrides, _ = plan(up_args("--twin", "--use-sim-time"), 1)
    assert all(overrides[node]["use_sim_time"] is True for node in nodes)
    written = merged_params(tmp_path, "model_node", None, overrides["model_node"])
    assert "use_sim_time: true" in Path(written).read_text()


@pytest.mark.parametrize(("item", "message"), [
    ("model_node:input.max_age_s=2.0", "is not [NODE:]NAME:=VALUE"),
    ("shape_controller:mode:=feedback", "names node 'shape_controller', which is not started"),
    ("input.max_age_s:=2.0", "names no node"),
])
def test_a_bad_p_is_an_input_error_naming_it(item: str, message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)) as error:
        plan(up_args("-p", item), 1)
    assert error.value.parameter == "-p"


def test_namespace_is_checked_and_reaches_the_merged_parameter_file(tmp_path) -> None:
    args = up_args("--namespace", "robot2/", "-p", "model_node:input.max_age_s:=2.0")
    nodes, overrides, _ = plan(args, 1)
    assert nodes == ["model_node"]
    assert args.namespace == "/robot2"
    written = merged_params(tmp_path, "model_node", None, overrides["model_node"], args.namespace)
    assert node_parameters([written], "/robot2/model_node") == {"input.max_age_s": 2.0}
    assert node_parameters([written], "/model_node") == {}
    with pytest.raises(InputError, match="--namespace") as error:
        plan(up_args("--namespace", "/2nd"), 1)
    assert error.value.parameter == "--namespace"


def test_frame_prefix_reaches_every_node_that_names_a_frame_and_p_wins() -> None:
    nodes, overrides, _ = plan(up_args(
        "--twin", "--nodes", "model_node,talker,metrics_node", "--frame-prefix", "robot2/",
        "-p", "metrics_node:frame_prefix:=bench/"), 1)
    assert {n: overrides.get(n, {}).get("frame_prefix") for n in nodes} == {
        "device_twin": "robot2/", "tension_driver": "robot2/", "model_node": "robot2/",
        "talker": None, "metrics_node": "bench/"}
    with pytest.raises(InputError, match=re.escape("--frame-prefix = '/robot2/' is not a frame "
                                                   "prefix")) as error:
        plan(up_args("--frame-prefix", "/robot2/"), 1)
    assert error.value.parameter == "--frame-prefix"
