"""The rcl_interfaces parameter services' answers (rclpy's Jazzy semantics) and their CDR, and
``/parameter_events`` of an embedded node's declarations."""

from __future__ import annotations

import logging
import math
import threading
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.bagio import deserialize, from_dict, serialize
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.param_services import (
    ParameterServices,
    descriptor,
    from_value,
    to_value,
)
from tdcm_ros.runtime.parameters import ParameterStore, ParamSpec
from tdcm_ros.runtime.port import QoS
from test.support.waiting import eventually


def services() -> tuple[ParameterServices, ParameterStore, list[Any]]:
    store = ParameterStore()
    events: list[Any] = []
    answers = ParameterServices(store, "/ns/node", logging.getLogger("test"), lambda: 7_000_000_123,
                                events.append)
    store.declare(ParamSpec("solver.tol", 1e-6, "m", (1e-12, 1e-2)))
    store.declare(ParamSpec("solver.deep.iterations", 50, "count", (1, 1000)))
    store.declare(ParamSpec("frame_id", "base", "frame", read_only=True))
    store.declare(ParamSpec("notches", [15.0, 33.0], "deg"))
    return answers, store, events


def request(type_name: str, fields: dict[str, Any]) -> Any:
    """Through CDR, as a request arrives."""
    name = f"rcl_interfaces/srv/{type_name}_Request"
    return deserialize(serialize(from_dict(name, fields)), name)


def double(value: float) -> dict[str, Any]:
    return {"type": 3, "double_value": value}


values = st.one_of(
    st.booleans(), st.integers(-2**63, 2**63 - 1), st.floats(allow_nan=False),
    st.text(), st.lists(st.booleans(), min_size=1), st.lists(st.integers(-2**63, 2**63 - 1),
                                                             min_size=1),
    st.lists(st.floats(allow_nan=False), min_size=1), st.lists(st.text(), min_size=1))


@given(values)
def test_values_cross_as_parameter_value_and_back(value: Any) -> None:
    message = to_value(value)
    data = serialize(message, "rcl_interfaces/msg/ParameterValue")
    assert from_value(deserialize(data, "rcl_interfaces/msg/ParameterValue")) == value


def test_unknown_and_unset_type_codes_are_refused() -> None:
    for code in (0, 10, 255):
        with pytest.raises(InputError, match=f"type = {code} is not a value"):
            from_value(from_dict("rcl_interfaces/msg/ParameterValue", {"type": code}))


def test_get_answers_every_value_or_none_as_rclpy() -> None:
    answers, _, _ = services()
    got = answers.get_parameters(request("GetParameters", {"names": ["solver.tol", "notches"]}))
    assert [from_value(v) for v in got.values] == [1e-6, [15.0, 33.0]]
    assert [v.type for v in got.values] == [3, 8]
    assert answers.get_parameters(request("GetParameters", {"names": ["solver.tol", "x"]})
                                  ).values == []
    types = answers.get_parameter_types(request("GetParameterTypes", {
        "names": ["frame_id", "solver.deep.iterations"]}))
    assert list(types.types) == [4, 2]


def test_descriptors_carry_type_range_and_read_only() -> None:
    answers, _, _ = services()
    [tol, iterations, frame] = answers.describe_parameters(request("DescribeParameters", {
        "names": ["solver.tol", "solver.deep.iterations", "frame_id"]})).descriptors
    assert (tol.type, tol.description, tol.read_only) == (3, "m", False)
    assert [(r.from_value, r.to_value, r.step) for r in tol.floating_point_range] == [
        (1e-12, 1e-2, 0.0)] and tol.integer_range == []
    assert [(r.from_value, r.to_value) for r in iterations.integer_range] == [(1, 1000)]
    assert frame.read_only and not frame.floating_point_range and not frame.integer_range
    assert descriptor(ParamSpec("x", 1.0)).floating_point_range == []


@pytest.mark.parametrize(("prefixes", "depth", "names", "groups"), [
    ([], 0, ["solver.tol", "solver.deep.iterations", "frame_id", "notches"],
     ["solver", "solver.deep"]),
    ([], 1, ["frame_id", "notches"], []),
    ([], 2, ["solver.tol", "frame_id", "notches"], ["solver"]),
    (["solver"], 0, ["solver.tol", "solver.deep.iterations"], ["solver", "solver.deep"]),
    (["solver"], 1, ["solver.tol"], ["solver"]),
    (["frame_id"], 1, ["frame_id"], []),
])
def test_list_filters_by_prefix_and_depth_as_rclpy(prefixes: list[str], depth: int,
                                                   names: list[str], groups: list[str]) -> None:
    answers, _, _ = services()
    result = answers.list_parameters(request("ListParameters", {"prefixes": prefixes,
                                                                "depth": depth})).result
    assert (list(result.names), list(result.prefixes)) == (names, groups)


def test_set_applies_each_parameter_on_its_own_and_publishes_the_accepted() -> None:
    answers, store, events = services()
    response = answers.set_parameters(request("SetParameters", {"parameters": [
        {"name": "solver.tol", "value": double(1e-3)},
        {"name": "solver.tol", "value": double(1.0)},
        {"name": "frame_id", "value": {"type": 4, "string_value": "tip"}},
        {"name": "nope", "value": double(1.0)},
        {"name": "solver.deep.iterations", "value": double(2.5)},
        {"name": "notches", "value": {"type": 7, "integer_array_value": [10, 20]}}]}))
    results = [(r.successful, r.reason) for r in response.results]
    assert results[0] == (True, "")
    assert not results[1][0] and "solver.tol" in results[1][1] and "out of range" in results[1][1]
    assert results[2] == (False, "parameter 'frame_id' is read-only")
    assert not results[3][0] and "'nope' is not declared" in results[3][1]
    assert not results[4][0] and "expected int" in results[4][1]
    assert results[5] == (True, "")  # integers widen to a float list, as the YAML path
    assert store.get("solver.tol") == 1e-3 and store.get("notches") == [10.0, 20.0]
    assert [(e.node, [(p.name, from_value(p.value)) for p in e.changed_parameters])
            for e in events] == [("/ns/node", [("solver.tol", 1e-3)]),
                                 ("/ns/node", [("notches", [10.0, 20.0])])]
    assert (events[0].stamp.sec, events[0].stamp.nanosec) == (7, 123)


def test_set_atomically_applies_all_or_none() -> None:
    answers, store, events = services()
    refused = answers.set_parameters_atomically(request("SetParametersAtomically", {
        "parameters": [{"name": "solver.tol", "value": double(1e-4)},
                       {"name": "solver.deep.iterations", "value": {"type": 2,
                                                                    "integer_value": 0}}]}))
    assert not refused.result.successful and "iterations" in refused.result.reason
    assert store.get("solver.tol") == 1e-6 and events == []
    done = answers.set_parameters_atomically(request("SetParametersAtomically", {
        "parameters": [{"name": "solver.tol", "value": double(1e-4)},
                       {"name": "solver.deep.iterations", "value": {"type": 2,
                                                                    "integer_value": 9}}]}))
    assert done.result.successful and store.get("solver.deep.iterations") == 9
    assert [p.name for p in events[0].changed_parameters] == ["solver.tol",
                                                              "solver.deep.iterations"]


def test_a_non_finite_value_is_refused_with_the_reason() -> None:
    answers, store, _ = services()
    response = answers.set_parameters(request("SetParameters", {"parameters": [
        {"name": "solver.tol", "value": double(math.nan)}]}))
    assert not response.results[0].successful and "not finite" in response.results[0].reason
    assert store.get("solver.tol") == 1e-6


def test_an_embedded_node_serves_the_six_services_and_announces_declarations() -> None:
    """In one process: the port's services through the runtime's own client, and its events."""
    zenoh_runtime = pytest.importorskip("tdcm_ros.runtime.zenoh_runtime")
    import zenoh

    from tdcm_ros.runtime.param_client import ParameterClient

    config = zenoh.Config()
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    context = zenoh_runtime.ZenohContext(zenoh.open(config))
    try:
        events: list[Any] = []
        listener = context.create_port("listener")
        listener.create_subscription("/parameter_events", "rcl_interfaces/msg/ParameterEvent",
                                     events.append, QoS(depth=1000))
        port = context.create_port("node", "/ns")
        port.declare_parameter("gain", 2.0, description="1", range=(0.0, 10.0))

        def declared() -> list[tuple[str, list[str]]]:
            return [(e.node, [p.name for p in e.new_parameters]) for e in events
                    if e.node == "/ns/node"]

        eventually(lambda: len(declared()) >= 2, 10.0, "two parameter events of /ns/node",
                   spin=context, detail=declared)
        assert sorted(declared()) == [("/ns/node", ["gain"]), ("/ns/node", ["use_sim_time"])]

        def names() -> list[str]:
            return sorted(n for n, _ in context.service_names(0.5) if n.startswith("/ns/node/"))

        eventually(lambda: len(names()) >= 6, 10.0, "the six parameter services listed",
                   detail=names)
        assert names() == [f"/ns/node/{s}" for s in (
            "describe_parameters", "get_parameter_types", "get_parameters", "list_parameters",
            "set_parameters", "set_parameters_atomically")]
        client = ParameterClient(context, "/ns/node")
        worker = threading.Thread(target=context.spin)
        worker.start()
        try:
            assert client.set("gain", 3).successful and client.get("gain") == 3.0
            assert client.describe(["gain"])[0].floating_point_range[0].to_value == 10.0
            with pytest.raises(InputError, match="not all declared"):
                client.get("nope")
        finally:
            context.request_stop()
            worker.join()
    finally:
        context.close()
