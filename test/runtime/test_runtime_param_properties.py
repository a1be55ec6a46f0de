"""Parameter requests with random and hostile content never break a node's parameters.

On zenoh the request is any ``rcl_interfaces`` parameter-service request (any names, any
``ParameterValue``: every type code, every field), crossed through CDR and answered in-process by the
handlers the node's services call; on rclpy any value rclpy can carry, through
``Node.set_parameters`` (what rclpy's parameter services call). Either way: an answer, never an exception; a value outside the spec is
never committed; every current value still passes its own spec.
"""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.parameters import ParamSpec
from test.support.graph import private_domain_id, require_rclpy

JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=20),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner,
                                                                 max_size=4),
    max_leaves=12)
NAMES = st.sampled_from(["period", "gain", "labels", "mode", "nope", ""]) | st.text(max_size=10)
SETTINGS = settings(max_examples=150,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


def declare(port: Any) -> None:
    """A float with a range, an int list, a string choice and a cross-parameter check."""
    port.declare_parameter("period", 0.5, range=(0.001, 60.0))
    port.declare_parameter("labels", [1, 2, 3])
    port.declare_parameter("mode", "a", validator=lambda v: _one_of(v, ("a", "b")))
    port.declare_parameter("gain", 2.0, range=(0.0, 10.0))

    def gain_below_period_times_100(changes: Any) -> None:
        gain = changes.get("gain", port.get_parameter("gain"))
        period = changes.get("period", port.get_parameter("period"))
        if gain > period * 100:
            raise InputError("gain must stay below 100 x period", parameter="gain")

    port.add_on_set_parameters(gain_below_period_times_100)


def _one_of(value: Any, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise InputError(f"mode = {value!r}; allowed: {allowed}", parameter="mode")


SPECS = {"period": ParamSpec("period", 0.5, range=(0.001, 60.0)),
         "labels": ParamSpec("labels", [1, 2, 3]),
         "mode": ParamSpec("mode", "a", validator=lambda v: _one_of(v, ("a", "b"))),
         "gain": ParamSpec("gain", 2.0, range=(0.0, 10.0))}


def assert_consistent(get: Any) -> None:
    for name, spec in SPECS.items():
        assert spec.coerce(get(name)) == get(name)
    assert get("gain") <= get("period") * 100


PARAMETER_VALUES = st.fixed_dictionaries({
    "type": st.integers(0, 255), "bool_value": st.booleans(),
    "integer_value": st.integers(-2**63, 2**63 - 1), "double_value": st.floats(),
    "string_value": st.text(max_size=20),
    "bool_array_value": st.lists(st.booleans(), max_size=4),
    "integer_array_value": st.lists(st.integers(-2**63, 2**63 - 1), max_size=4),
    "double_array_value": st.lists(st.floats(), max_size=4),
    "string_array_value": st.lists(st.text(max_size=5), max_size=4)})


def test_zenoh_parameter_requests_of_any_shape(context: Any) -> None:
    from tdcm_ros.bagio import deserialize, from_dict, serialize
    from tdcm_ros.runtime.param_services import SERVICES

    port = context.create_port("props")
    declare(port)
    handlers = port._parameter_services.handlers()

    def request(service: str, fields: dict[str, Any]) -> Any:
        name = f"{SERVICES[service]}_Request"
        return deserialize(serialize(from_dict(name, fields)), name)

    @SETTINGS
    @given(service=st.sampled_from(sorted(SERVICES)), names=st.lists(NAMES, max_size=3),
           values=st.lists(PARAMETER_VALUES, max_size=3), depth=st.integers(0, 2**64 - 1))
    def check(service: str, names: list[str], values: list[dict[str, Any]], depth: int) -> None:
        fields: dict[str, Any] = {"names": names}
        if service == "list_parameters":
            fields = {"prefixes": names, "depth": depth}
        elif service.startswith("set_parameters"):
            fields = {"parameters": [{"name": n, "value": v}
                                     for n, v in zip(names, values, strict=False)]}
        type_name, handler = handlers[service]
        answer = handler(request(service, fields))
        assert answer.__msgtype__ == f"{type_name}_Response"
        serialize(answer)
        assert_consistent(port.get_parameter)

    check()


@pytest.mark.rclpy
def test_rclpy_parameter_sets_of_any_value(monkeypatch: pytest.MonkeyPatch) -> None:
    require_rclpy()
    monkeypatch.setenv("ROS_DOMAIN_ID", str(private_domain_id()))
    from rclpy.parameter import Parameter

    from tdcm_ros.runtime.rclpy_runtime import RclpyContext, plain_value

    values = (st.none() | st.booleans() | st.integers(-2**63, 2**63 - 1) | st.floats()
              | st.text(max_size=20) | st.lists(st.integers(-2**63, 2**63 - 1), max_size=4)
              | st.lists(st.floats(), max_size=4) | st.lists(st.text(max_size=5), max_size=4))
    context = RclpyContext()
    try:
        port = context.create_port("props")
        declare(port)

        @SETTINGS
        @given(name=NAMES, value=values)
        def check(name: str, value: Any) -> None:
            try:
                parameter = Parameter(name, value=value)
            except (TypeError, ValueError):
                return  # rclpy itself cannot carry it: nothing reaches the node
            try:
                port.node.set_parameters([parameter])
            except Exception as error:  # noqa: BLE001 - only rclpy's own refusals may raise
                assert type(error).__module__.startswith("rclpy"), error
            assert_consistent(port.get_parameter)
            assert_consistent(lambda n: plain_value(port.node.get_parameter(n).value))

        check()
    finally:
        context.close()
