"""Typed, range-checked parameters of scene sections and effects (SI units).

A :class:`Param` declares one value: its unit, default and allowed range. :func:`parse_params`
checks a YAML mapping against a tuple of them, rejecting unknown keys with the list of valid
ones. Every message names the full key (e.g. ``effects.tendon_friction.mu``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from tdcm_ros.errors import reject_unknown
from tdcm_ros.scenes.errors import InvalidSceneError

KINDS = ("float", "int", "bool", "str", "names", "vector", "list")


@dataclass(frozen=True)
class Param:
    """One parameter: ``kind`` is float | int | bool | str | names (a list of distinct
    non-empty strings) | vector (``size`` floats) | list (floats, length >= 1); numeric bounds
    apply to every element. A default of ``None`` means "derived", documented per parameter."""

    name: str
    unit: str
    description: str
    default: Any
    kind: str = "float"
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    size: int = 3
    choices: tuple[str, ...] = ()

    def allowed(self) -> str:
        """The allowed values as text, e.g. ``[0, 1] m``."""
        if self.choices:
            return " | ".join(self.choices)
        if self.kind == "bool":
            return "true | false"
        if self.kind == "str":
            return "a string"
        if self.kind == "names":
            return "a list of distinct non-empty strings"
        bracket = "(" if self.low_open else "["
        span = f"{bracket}{self.low:g}, {self.high:g}]"
        if self.kind == "vector":
            span = f"{self.size} numbers in {span}"
        elif self.kind == "list":
            span = f"a list of numbers in {span}"
        elif self.kind == "int":
            span = f"an integer in {span}"
        return f"{span} {self.unit}".rstrip()

    def parse(self, where: str, value: Any) -> Any:
        """Check ``value`` for the key ``where``; returns it normalised (floats, tuples)."""
        if self.kind == "bool":
            if not isinstance(value, bool):
                raise self._error(where, value)
            return value
        if self.kind == "str":
            if not isinstance(value, str) or (self.choices and value not in self.choices):
                raise self._error(where, value)
            return value
        if self.kind == "names":
            ok = isinstance(value, Sequence) and not isinstance(value, str) and value and all(
                isinstance(v, str) and v for v in value) and len(set(value)) == len(value)
            if not ok:
                raise self._error(where, value)
            return tuple(value)
        if self.kind in ("vector", "list"):
            if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Sequence):
                raise self._error(where, value)
            if (self.kind == "vector" and len(value) != self.size) or not value:
                raise self._error(where, value)
            return tuple(self._number(where, value, item) for item in value)
        return self._number(where, value, value)

    def _number(self, where: str, whole: Any, value: Any) -> float | int:
        if isinstance(value, str):  # YAML 1.1 reads 1.85e9 (no exponent sign) as a string
            try:
                value = float(value)
            except ValueError:
                raise self._error(where, whole) from None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self._error(where, whole)
        if self.kind == "int":
            if float(value) != int(value):
                raise self._error(where, whole)
            value = int(value)
        below = value <= self.low if self.low_open else value < self.low
        if not math.isfinite(value) or below or value > self.high:
            raise self._error(where, whole)
        return value if self.kind == "int" else float(value)

    def _error(self, where: str, value: Any) -> InvalidSceneError:
        return InvalidSceneError(f"{where} = {value!r} is invalid; allowed: {self.allowed()}",
                                 parameter=where, value=value, allowed=self.allowed())


def as_mapping(where: str, raw: Any) -> Mapping[str, Any]:
    """``raw`` as a mapping (``None`` is empty); anything else raises naming ``where``."""
    if raw is None:
        return {}
    if not isinstance(raw, Mapping):
        raise InvalidSceneError(f"{where} = {raw!r} is not a mapping", parameter=where, value=raw,
                                allowed="a mapping of key: value")
    return raw


def parse_params(where: str, specs: Sequence[Param], raw: Any) -> dict[str, Any]:
    """Values for every spec from ``raw`` (defaults filled in); unknown keys raise."""
    data = as_mapping(where, raw)
    by_name = {spec.name: spec for spec in specs}
    reject_unknown(f"key in {where}", data, by_name, error=InvalidSceneError)
    return {name: spec.parse(f"{where}.{name}", data[name]) if name in data else spec.default
            for name, spec in by_name.items()}


def param_table(specs: Sequence[Param]) -> list[dict[str, str]]:
    """Rows ``name, unit, default, allowed, description`` for documentation and the CLI."""
    return [{"name": s.name, "unit": s.unit, "default": repr(s.default), "allowed": s.allowed(),
             "description": s.description} for s in specs]
