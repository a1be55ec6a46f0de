"""The ``rcl_interfaces`` parameter services and ``/parameter_events`` of a node, as rclpy's.

Every ROS 2 node serves six services under its name (``~/describe_parameters``,
``~/get_parameters``, ``~/get_parameter_types``, ``~/list_parameters``, ``~/set_parameters``,
``~/set_parameters_atomically``) and publishes an ``rcl_interfaces/msg/ParameterEvent`` on
``/parameter_events`` for each declaration and accepted change; ``ros2 param`` speaks them.
:class:`ParameterServices` answers them from a node's :class:`ParameterStore` (its specs, ranges,
read-only flags and node checks: one implementation with the YAML path), with rclpy's (Jazzy,
``rclpy/parameter_service.py``, ``Node.list_parameters``) semantics: an undeclared name in a get,
describe or type request empties the whole answer; ``set_parameters`` applies each parameter on
its own, ``set_parameters_atomically`` all or none; a refused change is ``successful=false`` with
the node's reason. Messages are rosbags objects; values cross as ``ParameterValue``
(:func:`to_value`, :func:`from_value`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from tdcm_ros.bagio import from_dict, to_dict
from tdcm_ros.errors import InputError
from tdcm_ros.runtime.parameters import (
    ParameterStore,
    ParamSpec,
    ParamValue,
    SetResult,
    kind_of,
)
from tdcm_ros.runtime.port import Logger, QoS

PARAMETER_EVENTS_TOPIC = "/parameter_events"
PARAMETER_EVENT_TYPE = "rcl_interfaces/msg/ParameterEvent"
#: rclpy's ``qos_profile_parameter_events`` (reliable, volatile, keep-last 1000).
PARAMETER_EVENTS_QOS = QoS(depth=1000)
#: rclpy's ``qos_profile_parameters`` for the six services (reliable, volatile, keep-last 1000).
PARAMETER_SERVICES_QOS = QoS(depth=1000)
#: ``rcl_interfaces/msg/ParameterType`` by the port's value kinds, and the ``ParameterValue``
#: field holding each.
_TYPES = {"bool": 1, "int": 2, "float": 3, "str": 4, "list": 5, "list[bool]": 6,
          "list[int]": 7, "list[float]": 8, "list[str]": 9}
_FIELDS = {1: "bool_value", 2: "integer_value", 3: "double_value", 4: "string_value",
           5: "byte_array_value", 6: "bool_array_value", 7: "integer_array_value",
           8: "double_array_value", 9: "string_array_value"}
#: ``ParameterType`` codes as ``ros2 param describe`` names them.
TYPE_NAMES = ("not set", "boolean", "integer", "double", "string", "byte array",
              "boolean array", "integer array", "double array", "string array")
#: ``ListParameters`` request depth meaning "every level".
DEPTH_RECURSIVE = 0
SEPARATOR = "."
#: Service name (under the node) -> ``rcl_interfaces`` service type.
SERVICES = {
    "describe_parameters": "rcl_interfaces/srv/DescribeParameters",
    "get_parameters": "rcl_interfaces/srv/GetParameters",
    "get_parameter_types": "rcl_interfaces/srv/GetParameterTypes",
    "list_parameters": "rcl_interfaces/srv/ListParameters",
    "set_parameters": "rcl_interfaces/srv/SetParameters",
    "set_parameters_atomically": "rcl_interfaces/srv/SetParametersAtomically",
}
#: The services of :data:`SERVICES` that change nothing (open to observers: access_control).
READ_ONLY_SERVICES = ("describe_parameters", "get_parameters", "get_parameter_types",
                      "list_parameters")


def type_of(value: ParamValue, spec: ParamSpec[Any] | None = None) -> int:
    """The ``ParameterType`` of ``value`` (an empty list takes the spec's element type)."""
    kind = kind_of(value)
    if kind == "list" and spec is not None:
        kind = spec.kind
    return _TYPES[kind]


def type_name(code: int) -> str:
    """The name of a ``ParameterType`` code (``unknown <code>`` outside 0..9)."""
    return TYPE_NAMES[code] if 0 <= code < len(TYPE_NAMES) else f"unknown {code}"


def to_value(value: ParamValue, spec: ParamSpec[Any] | None = None) -> Any:
    """``rcl_interfaces/msg/ParameterValue`` of a port value; ``InputError`` if unsupported."""
    code = type_of(value, spec)
    return from_dict("rcl_interfaces/msg/ParameterValue",
                     {"type": code, _FIELDS[code]: list(value) if isinstance(value, list | tuple)
                      else value})


def from_value(message: Any) -> ParamValue:
    """The plain Python value of a ``ParameterValue``; ``InputError`` for ``NOT_SET`` (0) or an
    unknown type code."""
    code = int(message.type)
    if code not in _FIELDS:
        raise InputError(f"parameter value type = {code} is not a value; allowed: 1..9 "
                         f"(rcl_interfaces/msg/ParameterType)", parameter="type", value=code,
                         allowed="1..9")
    plain = to_dict(getattr(message, _FIELDS[code]))
    return list(plain) if isinstance(plain, list | tuple) else plain


def descriptor(spec: ParamSpec[Any]) -> Any:
    """``rcl_interfaces/msg/ParameterDescriptor`` of a spec: type, description, read-only flag
    and its inclusive range (step 0 = any value in range) as rclpy reports it."""
    fields: dict[str, Any] = {"name": spec.name, "type": type_of(spec.default, spec),
                              "description": spec.description, "read_only": spec.read_only}
    if spec.range is not None and spec.kind in ("float", "list[float]"):
        fields["floating_point_range"] = [{"from_value": float(spec.range[0]),
                                           "to_value": float(spec.range[1]), "step": 0.0}]
    elif spec.range is not None and spec.kind in ("int", "list[int]"):
        fields["integer_range"] = [{"from_value": int(spec.range[0]),
                                    "to_value": int(spec.range[1]), "step": 0}]
    return from_dict("rcl_interfaces/msg/ParameterDescriptor", fields)


def _listed(name: str, prefixes: list[str], depth: int) -> bool:
    """rclpy's ``Node.list_parameters`` filter."""
    if not prefixes and depth == DEPTH_RECURSIVE:
        return True
    if not prefixes and name.count(SEPARATOR) < depth:
        return True
    return any(name == prefix or (name.startswith(prefix + SEPARATOR) and (
        depth == DEPTH_RECURSIVE or name[len(prefix) + 1:].count(SEPARATOR) < depth))
        for prefix in prefixes)


class ParameterServices:
    """Answers of one node's six parameter services and its parameter events.

    ``publish_event`` sends a ``ParameterEvent`` on ``/parameter_events``; ``now_ns`` is the node
    clock (ns since the epoch) that stamps it.
    """

    def __init__(self, store: ParameterStore, node_fqn: str, logger: Logger,
                 now_ns: Callable[[], int], publish_event: Callable[[Any], None]) -> None:
        self._store, self._fqn, self._logger = store, node_fqn, logger
        self._now_ns, self._publish_event = now_ns, publish_event

    def handlers(self) -> dict[str, tuple[str, Callable[[Any], Any]]]:
        """Service name under the node -> (service type, request handler)."""
        answers: dict[str, Callable[[Any], Any]] = {
            "describe_parameters": self.describe_parameters,
            "get_parameters": self.get_parameters,
            "get_parameter_types": self.get_parameter_types,
            "list_parameters": self.list_parameters,
            "set_parameters": self.set_parameters,
            "set_parameters_atomically": self.set_parameters_atomically,
        }
        return {name: (SERVICES[name], answer) for name, answer in answers.items()}

    def _declared(self, names: list[str]) -> list[ParamSpec[Any]] | None:
        specs = self._store.specs
        return None if any(n not in specs for n in names) else [specs[n] for n in names]

    def get_parameters(self, request: Any) -> Any:
        """Values of the named parameters (none if one is undeclared, as rclpy)."""
        specs = self._declared(list(request.names)) or []
        return from_dict("rcl_interfaces/srv/GetParameters_Response", {"values": [
            to_dict(to_value(self._store.get(s.name), s)) for s in specs]})

    def get_parameter_types(self, request: Any) -> Any:
        """``ParameterType`` codes of the named parameters (none if one is undeclared)."""
        specs = self._declared(list(request.names)) or []
        return from_dict("rcl_interfaces/srv/GetParameterTypes_Response", {"types": [
            type_of(self._store.get(s.name), s) for s in specs]})

    def describe_parameters(self, request: Any) -> Any:
        """Descriptors of the named parameters (none if one is undeclared)."""
        specs = self._declared(list(request.names)) or []
        return from_dict("rcl_interfaces/srv/DescribeParameters_Response", {"descriptors": [
            to_dict(descriptor(s)) for s in specs]})

    def list_parameters(self, request: Any) -> Any:
        """Names matching the prefixes and depth, and their prefixes, as rclpy lists them."""
        prefixes, depth = [str(p) for p in request.prefixes], int(request.depth)
        names = [n for n in self._store.specs if _listed(n, prefixes, depth)]
        groups = list(dict.fromkeys(n.rpartition(SEPARATOR)[0] for n in names if SEPARATOR in n))
        return from_dict("rcl_interfaces/srv/ListParameters_Response",
                         {"result": {"names": names, "prefixes": groups}})

    def set_parameters(self, request: Any) -> Any:
        """Each parameter set on its own; one result per parameter."""
        return from_dict("rcl_interfaces/srv/SetParameters_Response", {"results": [
            self._result(self.apply([p])) for p in request.parameters]})

    def set_parameters_atomically(self, request: Any) -> Any:
        """Every parameter set, or none."""
        return from_dict("rcl_interfaces/srv/SetParametersAtomically_Response",
                         {"result": self._result(self.apply(list(request.parameters)))})

    @staticmethod
    def _result(result: SetResult) -> dict[str, Any]:
        return {"successful": result.successful, "reason": result.reason}

    def apply(self, parameters: list[Any]) -> SetResult:
        """Apply ``rcl_interfaces/msg/Parameter`` messages through the store's checks; an
        accepted change is logged and published as changed parameters."""
        try:
            changes = {str(p.name): from_value(p.value) for p in parameters}
        except InputError as error:
            return self._refused(SetResult(False, str(error)))
        result = self._store.set(changes)
        if not result.successful:
            return self._refused(result)
        for name in changes:
            self._logger.info("parameter %s set to %r", name, self._store.get(name))
        self.publish(changed=list(changes))
        return result

    def _refused(self, result: SetResult) -> SetResult:
        self._logger.warning("parameter change rejected: %s", result.reason)
        return result

    def publish(self, *, new: Sequence[str] = (), changed: Sequence[str] = ()) -> None:
        """Send the ``ParameterEvent`` of declared (``new``) or changed parameters."""
        specs = self._store.specs

        def entries(names: Sequence[str]) -> list[dict[str, Any]]:
            return [{"name": n, "value": to_dict(to_value(self._store.get(n), specs[n]))}
                    for n in names]

        stamp = self._now_ns()
        self._publish_event(from_dict(PARAMETER_EVENT_TYPE, {
            "stamp": {"sec": stamp // 1_000_000_000, "nanosec": stamp % 1_000_000_000},
            "node": self._fqn, "new_parameters": entries(new),
            "changed_parameters": entries(changed)}))

