"""Node parameters declared from :class:`~tdcm_ros.spec.Spec` groups, one call per group.

A group is a mapping ``key -> Spec`` (e.g. :data:`tdcm_ros.model.SOLVER_SPECS`, keyed by the
settings field); each spec is declared as ``prefix + spec.name`` with the spec's default (or the
one given for its key), its finite bounds as the ROS range, its description and unit, and the
spec's own check as validator; a parameter file may still set it by a former name
(``spec.formerly``, warned). Both runtimes see the same names, types and defaults.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import partial
from typing import Any

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.parameters import ParamValue
from tdcm_ros.runtime.port import CLOCK_TOPIC, NodePort
from tdcm_ros.spec import Spec, by_name

#: Parameters every node has, whatever its own (the runtime declares them; rclpy its own).
NODE_COMMON = by_name(
    Spec("use_sim_time", description=f"take the time from {CLOCK_TOPIC} instead of the system "
         "clock (0 until the first message), as ROS nodes do; fixed at start", default=False,
         kind="bool"))


def grouped(specs: Mapping[str, Spec], prefix: str = "") -> dict[str, Spec]:
    """A group's specs by full parameter name (``prefix + spec.name``)."""
    return {f"{prefix}{spec.name}": spec for spec in specs.values()}


def description(spec: Spec) -> str:
    """The parameter description shown over ROS: the spec's, with its unit."""
    return f"{spec.description} ({spec.unit})" if spec.unit else spec.description


def ros_value(spec: Spec, value: Any) -> ParamValue:
    """``value`` as a ROS parameter value: tuples become lists, a float spec's number a float."""
    if isinstance(value, tuple | list):
        return [float(v) for v in value] if spec.numeric else list(value)
    return float(value) if spec.kind == "float" else value


def checked(spec: Spec, prefix: str, value: Any) -> Any:
    """``value`` checked and normalised by ``spec``; in a group (``prefix`` given) the error
    names the full parameter before the field's own message, e.g. ``steps.zero_n: zero_n = ...``."""
    try:
        return spec.check(value)
    except InputError as error:
        if not prefix:
            raise
        name = f"{prefix}{spec.name}"
        raise InputError(f"{name}: {error}", parameter=name, value=error.value,
                         allowed=error.allowed) from error


def declare_specs(port: NodePort, specs: Mapping[str, Spec], *, prefix: str = "",
                  defaults: Mapping[str, Any] | None = None, read_only: bool = False
                  ) -> dict[str, Any]:
    """Declare every spec of the group as ``prefix + spec.name``; returns the values (checked
    and normalised by the spec) by the group's keys. ``defaults`` replaces spec defaults by key."""
    values: dict[str, Any] = {}
    for key, spec in specs.items():
        name = f"{prefix}{spec.name}"
        default = (defaults or {}).get(key, spec.default)
        value = port.declare_parameter(name, ros_value(spec, default), description=description(spec),
                                       range=spec.bounds, validator=partial(checked, spec, prefix),
                                       read_only=read_only,
                                       formerly=tuple(prefix + old for old in spec.formerly))
        values[key] = checked(spec, prefix, value)
    return values


def read_specs(port: NodePort, specs: Mapping[str, Spec], *, prefix: str = "",
               changes: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Current values of a declared group by key, with pending ``changes`` (by full parameter
    name) applied, each checked and normalised by its spec."""
    pending = changes or {}
    values: dict[str, Any] = {}
    for key, spec in specs.items():
        name = f"{prefix}{spec.name}"
        values[key] = checked(spec, prefix, pending[name] if name in pending
                              else port.get_parameter(name))
    return values
