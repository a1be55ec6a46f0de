"""A client of one node's ``rcl_interfaces`` parameter services, on either runtime.

It calls the six services the way ``ros2 param`` does, through a context's ``call_service``
(:class:`tdcm_ros.runtime.zenoh_runtime.ZenohContext` speaks rmw_zenoh's service format,
:class:`tdcm_ros.runtime.rclpy_runtime.RclpyContext` rclpy's clients), so ``tdcm param`` has one
code path whatever runtime the node runs on.
"""

from __future__ import annotations

from typing import Any, Protocol

from tdcm_ros.bagio import from_dict, to_dict
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.param_services import SERVICES, from_value, to_value
from tdcm_ros.runtime.parameters import ParamValue, SetResult

#: Default time (s) to wait for a node's parameter services to appear and answer.
PARAM_TIMEOUT_S = 5.0


class ServiceCaller(Protocol):
    """What a runtime context offers a client: a blocking service call."""

    def call_service(self, name: str, type_name: str, request: Any = None,
                     timeout: float = ...) -> Any:
        """Call service ``name`` of ``type_name``; the decoded response."""


class ParameterClient:
    """The parameter services of node ``node_fqn`` (``/ns/name``); ``timeout`` in s per call."""

    def __init__(self, context: ServiceCaller, node_fqn: str,
                 timeout: float = PARAM_TIMEOUT_S) -> None:
        self.context, self.node = context, "/" + node_fqn.strip("/")
        self.timeout = timeout

    def _call(self, service: str, request: dict[str, Any]) -> Any:
        type_name = SERVICES[service]
        return self.context.call_service(f"{self.node}/{service}", type_name,
                                         from_dict(f"{type_name}_Request", request), self.timeout)

    def _undeclared(self, names: list[str], found: int) -> None:
        if found != len(names):
            raise InputError(f"{self.node}: parameter(s) {names} not all declared; see "
                             f"'tdcm param list {self.node}'", parameter=", ".join(names))

    def names(self) -> list[str]:
        """Every parameter name, sorted."""
        return sorted(self._call("list_parameters", {}).result.names)

    def get_values(self, names: list[str]) -> dict[str, ParamValue]:
        """Current values by name; ``InputError`` if one is not declared."""
        values = self._call("get_parameters", {"names": names}).values
        self._undeclared(names, len(values))
        return {name: from_value(value) for name, value in zip(names, values, strict=True)}

    def get(self, name: str) -> ParamValue:
        """Current value of ``name``."""
        return self.get_values([name])[name]

    def describe(self, names: list[str]) -> list[Any]:
        """``rcl_interfaces/msg/ParameterDescriptor`` of each name; ``InputError`` if one is not
        declared."""
        descriptors = list(self._call("describe_parameters", {"names": names}).descriptors)
        self._undeclared(names, len(descriptors))
        return descriptors

    def set(self, name: str, value: Any) -> SetResult:
        """Ask the node to set ``name`` to ``value``; its verdict and reason."""
        parameter = {"name": name, "value": to_dict(to_value(value))}
        result = self._call("set_parameters", {"parameters": [parameter]}).results[0]
        return SetResult(bool(result.successful), str(result.reason))
