"""Parameter declarations and the store both runtimes validate against.

A :class:`ParamSpec` fixes the type from its default (``int`` is accepted for ``float``), an
optional inclusive numeric range and an optional validator that raises
:class:`tdcm_ros.errors.InputError`. :class:`ParameterStore` applies a change only if the spec and
every node-level check accept it; otherwise the old value stays and the reason is returned.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Generic, TypeVar, cast

from tdcm_ros.errors import InputError
from tdcm_ros.spec import former_name_choice

ParamValue = bool | int | float | str | list[bool] | list[int] | list[float] | list[str]
#: The type of one parameter: that of its default (a declared value keeps it).
P = TypeVar("P", bound=ParamValue)
Validator = Callable[[Any], None]
SetCallback = Callable[[Mapping[str, Any]], None]
_WIDENING = {("float", "int"), ("list[float]", "list[int]")}


@dataclass(frozen=True)
class SetResult:
    """Outcome of a parameter change: ``successful`` and, when rejected, the ``reason``."""

    successful: bool
    reason: str = ""


def kind_of(value: Any) -> str:
    """``bool``, ``int``, ``float``, ``str``, ``list[<element>]`` or ``list`` (empty) of a value;
    ``InputError`` for anything else."""
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "int"
    if isinstance(value, float):
        return "float"
    if isinstance(value, str):
        return "str"
    if isinstance(value, list | tuple):
        kinds = {kind_of(v) for v in value}
        if kinds <= {"int", "float"} and "float" in kinds:
            return "list[float]"
        if len(kinds) == 1:
            return f"list[{kinds.pop()}]"
        if not kinds:
            return "list"
    raise InputError(f"unsupported parameter value {value!r}; allowed: bool, int, float, str "
                     f"or a homogeneous list of them", value=value)


@dataclass(frozen=True)
class ParamSpec(Generic[P]):
    """A declared parameter. ``range`` is inclusive ``(low, high)`` in the parameter's unit."""

    name: str
    default: P
    description: str = ""
    range: tuple[float, float] | None = None
    validator: Validator | None = None
    read_only: bool = False
    #: Former names (deprecated aliases): a parameter file may still set the value by one.
    formerly: tuple[str, ...] = ()

    @property
    def kind(self) -> str:
        """``bool``, ``int``, ``float``, ``str`` or ``list[...]``."""
        return kind_of(self.default)

    def coerce(self, value: Any) -> P:
        """The value converted to this parameter's type and checked; raises ``InputError``."""
        kind, given = self.kind, kind_of(value)
        compatible = (given == kind or (kind, given) in _WIDENING
                      or (kind.startswith("list") and given == "list"))
        if not compatible:
            raise InputError(f"{self.name} = {value!r} has type {given}; expected {kind}",
                             parameter=self.name, value=value, allowed=kind)
        coerced: ParamValue
        if kind == "float":
            coerced = float(value)
        elif kind == "list[float]":
            coerced = [float(v) for v in value]
        elif kind.startswith("list"):
            coerced = list(value)
        else:
            coerced = value
        for number in (coerced if isinstance(coerced, list) else [coerced]):
            if isinstance(number, float) and not math.isfinite(number):
                raise InputError(f"{self.name} = {value!r} is not finite", parameter=self.name,
                                 value=value, allowed="finite numbers")
            if self.range is not None and isinstance(number, int | float) and not isinstance(
                    number, bool):
                low, high = self.range
                if not low <= number <= high:
                    raise InputError(f"{self.name} = {value!r} is out of range; allowed: "
                                     f"[{low}, {high}]", parameter=self.name, value=value,
                                     allowed=f"[{low}, {high}]")
        if self.validator is not None:
            self.validator(coerced)
        return cast(P, coerced)  # the kind checks above give it the default's type


class ParameterStore:
    """Declared parameters of one node, their current values and the change checks.

    ``overrides`` are the parameter file's values; ``warn`` (the node's log at WARN) hears of
    a value set by a deprecated name."""

    def __init__(self, overrides: Mapping[str, Any] | None = None, *,
                 warn: Callable[[str], None] | None = None) -> None:
        self._overrides = dict(overrides or {})
        self._warn = warn
        self._taken: set[str] = set()
        self._specs: dict[str, ParamSpec[Any]] = {}
        self._values: dict[str, ParamValue] = {}
        self._callbacks: list[SetCallback] = []

    def override(self, spec: ParamSpec[Any]) -> tuple[bool, Any]:
        """``(found, value)``: the parameter file's value for ``spec``, by its name, else by a
        former name (warned as deprecated); a former name set beside the current one is
        ignored, warned."""
        chosen, messages = former_name_choice(spec.name, spec.formerly, self._overrides)
        if chosen is None:
            return False, None
        self._taken.update(n for n in (spec.name, *spec.formerly) if n in self._overrides)
        for message in messages:
            if self._warn is not None:
                self._warn(f"parameter {message}")
        return True, self._overrides[chosen]

    def unused_overrides(self) -> list[str]:
        """Names the parameter file sets that no declared parameter took (sorted)."""
        return sorted(set(self._overrides) - self._taken)

    def declare(self, spec: ParamSpec[P], value: Any = None) -> P:
        """Declare ``spec``; its value is ``value`` if given (a runtime resolved it), else the
        override (YAML) if any, else the default; checked against the spec."""
        if spec.name in self._specs:
            raise InputError(f"parameter {spec.name!r} is declared twice", parameter=spec.name)
        spec.coerce(spec.default)
        if value is None:
            found, value = self.override(spec)
            value = value if found else spec.default
        value = spec.coerce(value)
        self._specs[spec.name] = spec
        self._values[spec.name] = value
        return value

    def add_on_set(self, callback: SetCallback) -> None:
        """Add a node-level check run on every change with ``{name: new value}``.

        It raises ``InputError`` to reject the change (the old values stay); otherwise the node
        treats it as the notification that the values are about to apply.
        """
        self._callbacks.append(callback)

    @property
    def specs(self) -> Mapping[str, ParamSpec[Any]]:
        """Declared specs by name."""
        return dict(self._specs)

    def get(self, name: str) -> ParamValue:
        """Current value of a declared parameter."""
        if name not in self._values:
            raise InputError(f"parameter {name!r} is not declared; declared: "
                             f"{sorted(self._values)}", parameter=name)
        return self._values[name]

    def values(self) -> dict[str, ParamValue]:
        """All current values."""
        return dict(self._values)

    def validate(self, changes: Mapping[str, Any]) -> dict[str, ParamValue]:
        """The coerced changes if every spec and node check accepts them; raises ``InputError``."""
        coerced: dict[str, ParamValue] = {}
        for name, value in changes.items():
            spec = self._specs.get(name)
            if spec is None:
                raise InputError(f"parameter {name!r} is not declared", parameter=name)
            if spec.read_only:
                raise InputError(f"parameter {name!r} is read-only", parameter=name)
            coerced[name] = spec.coerce(value)
        for callback in self._callbacks:
            try:
                callback(coerced)
            except InputError:
                raise
            except Exception as error:  # a failing node check rejects the change
                raise InputError(f"change of {', '.join(coerced)} rejected: the node's check "
                                 f"failed with {type(error).__name__}: {error}",
                                 parameter=", ".join(coerced)) from error
        return coerced

    def set(self, changes: Mapping[str, Any]) -> SetResult:
        """Apply ``changes`` atomically if valid; a rejection keeps every old value."""
        try:
            coerced = self.validate(changes)
        except InputError as error:
            return SetResult(False, str(error))
        self._values.update(coerced)
        return SetResult(True)

    def commit(self, changes: Mapping[str, ParamValue]) -> None:
        """Record changes already validated (used by the rclpy adapter after its callback)."""
        self._values.update(changes)

