"""One parameter spec for the whole package: name, unit, meaning, default and allowed values.

Every parameter (design fields, solver and step settings, marker layout, device configs, scene
keys, node parameters and ``--set`` names) is declared once as a :class:`Spec`. A spec checks a
typed value (:meth:`Spec.check`), parses one given as text or YAML (:meth:`Spec.parse`) and
says what it allows (:meth:`Spec.allowed`); every error names the parameter, the value and the
allowed range with its unit.

A settings dataclass declares each field with :func:`spec_field`; :func:`specs_of` collects the
specs from the class and :func:`check_fields` validates an instance against them (one loop for
every dataclass). Only the standard library and the package's error tree are imported here.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import warnings
from collections.abc import Collection, Container, Iterable, Mapping, Sequence
from typing import Any

from tdcm_ros.errors import (
    InputError,
    exact_number,
    out_of_range,
    reject_unknown,
    shown_value,
)

#: float | int | bool | str (``choices`` optional) | names (distinct non-empty strings) |
#: vector (``size`` numbers) | list (numbers, length >= 1)
KINDS = ("float", "int", "bool", "str", "names", "vector", "list")
_SEQUENCES = ("names", "vector", "list")
#: Longest string value (characters): Linux's PATH_MAX, room for any path, name or frame. A
#: parameter is echoed in every message that carries it (a frame_id in each 50 Hz tension).
MAX_TEXT_CHARS = 4096
#: Most elements of a sequence value.
MAX_ITEMS = 10_000
_TRUE, _FALSE = ("true", "yes", "on", "1"), ("false", "no", "off", "0")
_METADATA_KEY = "tdcm_spec"


class DeprecatedNameWarning(FutureWarning):
    """A key, parameter or option was given by a deprecated name (a ``FutureWarning``: the
    category Python shows end users by default)."""

_SAME: Any = object()  # renamed(): keep the default


@dataclasses.dataclass(frozen=True)
class Spec:
    """One parameter. Numeric bounds (in ``unit``) apply to every element of a sequence kind; a
    ``default`` of ``None`` means "given elsewhere" (a preset, a derived value)."""

    name: str
    unit: str = ""
    description: str = ""
    default: Any = None
    kind: str = "float"
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    size: int = 3
    choices: tuple[str, ...] = ()  # a str value matches one with "-" and "_" alike
    high_open: bool = False
    #: Former names, still read with a :class:`DeprecatedNameWarning` (relative to a group's
    #: prefix, like ``name``).
    formerly: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"spec {self.name!r}: kind {self.kind!r} is not one of {KINDS}")

    @property
    def integer(self) -> bool:
        """Whether the value is an integer."""
        return self.kind == "int"

    @property
    def numeric(self) -> bool:
        """Whether the value (or each element) is a number with bounds."""
        return self.kind in ("float", "int", "vector", "list")

    @property
    def bounds(self) -> tuple[float, float] | None:
        """``(low, high)`` if both are finite (the inclusive range a ROS descriptor shows)."""
        if self.numeric and math.isfinite(self.low) and math.isfinite(self.high):
            return (self.low, self.high)
        return None

    def renamed(self, name: str, *, default: Any = _SAME) -> Spec:
        """This parameter under another name (e.g. a scene file's key ``hold_s`` for the field
        ``hold``), optionally with another default; unit, meaning and range stay the same."""
        return dataclasses.replace(self, name=name,
                                   default=self.default if default is _SAME else default)

    def narrowed(self, *, low: float | None = None, high: float | None = None) -> Spec:
        """This parameter with a tighter range (a closed bound; the other bound is kept). Raises
        :class:`ValueError` if a bound would widen the range, so a narrowed value is always one
        the source allows."""
        if (low is not None and (low < self.low or (low == self.low and self.low_open))) or \
                (high is not None and (high > self.high or (high == self.high and self.high_open))):
            raise ValueError(f"spec {self.name!r}: [{low}, {high}] widens {self._span()}")
        changes: dict[str, Any] = {}
        if low is not None:
            changes.update(low=low, low_open=False)
        if high is not None:
            changes.update(high=high, high_open=False)
        return dataclasses.replace(self, **changes)

    def _span(self) -> str:
        low, high = math.isfinite(self.low), math.isfinite(self.high)
        if low and high:
            return (f"{'(' if self.low_open else '['}{exact_number(self.low)}, "
                    f"{exact_number(self.high)}{')' if self.high_open else ']'}")
        if low:
            return f"{'>' if self.low_open else '>='} {exact_number(self.low)}"
        if high:
            return f"{'<' if self.high_open else '<='} {exact_number(self.high)}"
        return ""

    def allowed(self) -> str:
        """The allowed values as text, e.g. ``(0, 1] m`` or ``an integer in [1, 512]``."""
        if self.choices:
            return " | ".join(self.choices)
        if self.kind == "bool":
            return "true | false"
        if self.kind == "str":
            return "a string"
        if self.kind == "names":
            return "a list of distinct non-empty strings"
        span = self._span()
        interval = span.startswith(("[", "("))
        joined = f" in {span}" if interval else f" {span}".rstrip()
        if self.kind == "vector":
            text = f"{self.size} numbers{joined}"
        elif self.kind == "list":
            text = f"a list of numbers{joined}"
        elif self.kind == "int":
            text = f"an integer{joined}"
        else:
            text = span or "a finite number"
        return f"{text} {self.unit}".rstrip()

    def check(self, value: Any, where: str | None = None, *,
              error: type[InputError] = InputError) -> Any:
        """``value`` normalised (float, int, tuple) if it is of this kind and allowed; strings are
        not numbers here (see :meth:`parse`). Raises ``error`` naming ``where`` (default: name)."""
        return self._normalise(value, where or self.name, error, from_text=False)

    def parse(self, value: Any, where: str | None = None, *,
              error: type[InputError] = InputError) -> Any:
        """Like :meth:`check`, but a value may also be text: a number (YAML 1.1 reads ``1.85e9``
        as a string), ``true``/``false``, or a comma-separated list for sequence kinds."""
        return self._normalise(value, where or self.name, error, from_text=True)

    def _normalise(self, value: Any, where: str, error: type[InputError], from_text: bool) -> Any:
        if self.kind not in _SEQUENCES:
            return self._scalar(value, where, error, from_text, shown_unit="")
        items = value
        if from_text and isinstance(value, str):
            items = [part.strip() for part in value.split(",") if part.strip()]
        if isinstance(items, (str, bytes, Mapping)) or not isinstance(items, Collection):
            raise self._wrong_type(where, value, error)
        items = list(items)
        if len(items) > MAX_ITEMS:
            raise out_of_range(where, value, f"at most {MAX_ITEMS} elements", error=error)
        if not items or (self.kind == "vector" and len(items) != self.size):
            raise out_of_range(where, value, self.allowed(), error=error)
        if self.kind == "names":
            if not all(isinstance(v, str) and v for v in items) or len(set(items)) != len(items):
                raise out_of_range(where, value, self.allowed(), error=error)
            return tuple(items)
        # an element out of range is named with its unit: ``levels = -4.0 N is out of range``
        return tuple(self._scalar(item, where, error, from_text, shown_unit=self.unit)
                     for item in items)

    def _scalar(self, value: Any, where: str, error: type[InputError], from_text: bool,
                shown_unit: str) -> Any:
        if self.kind == "bool":
            if from_text and isinstance(value, str) and value.lower() in _TRUE + _FALSE:
                return value.lower() in _TRUE
            if not isinstance(value, bool):
                raise self._wrong_type(where, value, error)
            return value
        if self.kind == "str":
            if not isinstance(value, str):
                raise self._wrong_type(where, value, error)
            if len(value) > MAX_TEXT_CHARS:
                raise out_of_range(where, value, f"at most {MAX_TEXT_CHARS} characters",
                                   error=error)
            if not self.choices:
                return value
            chosen = spelled_as(value, self.choices)  # '-' and '_' alike: the choice's spelling
            if chosen is None:
                raise out_of_range(where, value, self.allowed(), error=error)
            return chosen
        number = self._number(value, where, error, from_text)
        below = number <= self.low if self.low_open else number < self.low
        above = number >= self.high if self.high_open else number > self.high
        if not math.isfinite(number) or below or above:
            raise out_of_range(where, value, self.allowed(), unit=shown_unit, error=error)
        return number

    def _number(self, value: Any, where: str, error: type[InputError],
                from_text: bool) -> float | int:
        given = value
        if from_text and isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                raise self._wrong_type(where, given, error, number=True) from None
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise self._wrong_type(where, given, error, number=True)
        if self.kind == "float" or self.kind in _SEQUENCES:
            return float(value)
        if isinstance(value, numbers.Integral):
            return int(value)
        number = float(value)
        if from_text and number.is_integer():
            return int(number)
        raise self._wrong_type(where, given, error)

    def _wrong_type(self, where: str, value: Any, error: type[InputError],
                    number: bool = False) -> InputError:
        """The error for ``value`` of the wrong type; ``number``: an element of a list of
        numbers is not a number."""
        noun = {"float": "a number", "int": "an integer", "bool": "true or false",
                "str": "a string"}.get(self.kind, "a number" if number else "a list")
        return error(f"{where} = {shown_value(value)} is not {noun}; allowed: {self.allowed()}",
                     parameter=where, value=value, allowed=self.allowed())


def spec_field(default: Any = dataclasses.MISSING, *, unit: str = "", description: str = "",
               kind: str | None = None, low: float = -math.inf, high: float = math.inf,
               low_open: bool = False, high_open: bool = False, size: int = 3,
               choices: Sequence[str] = (), name: str = "") -> Any:
    """A dataclass field declared with its spec: the parameter is named after the field unless
    ``name`` is given (e.g. ``align.tolerance_s``); ``kind`` is inferred from the default when not
    given. Collect them with :func:`specs_of`."""
    given = None if default is dataclasses.MISSING else default
    spec = Spec(name, unit, description, given, kind or kind_of(given), low, high, low_open, size,
                tuple(choices), high_open)
    return dataclasses.field(default=default, metadata={_METADATA_KEY: spec})


def kind_of(value: Any) -> str:
    """The spec kind of a default value: bool, int, str, names (a tuple of strings), list (a
    tuple of numbers), else float."""
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "int"
    if isinstance(value, str):
        return "str"
    if isinstance(value, tuple) and value and all(isinstance(v, str) for v in value):
        return "names"
    if isinstance(value, tuple):
        return "list"
    return "float"


def specs_of(cls: Any) -> dict[str, Spec]:
    """Specs of the dataclass ``cls`` declared with :func:`spec_field`, by field name, in field
    order (fields declared otherwise, e.g. an object-valued field, are not parameters)."""
    specs = {f.name: f.metadata[_METADATA_KEY] for f in dataclasses.fields(cls)
             if _METADATA_KEY in f.metadata}
    return {field: spec if spec.name else dataclasses.replace(spec, name=field)
            for field, spec in specs.items()}


def spelled_as(name: str, known: Iterable[str]) -> str | None:
    """The name of ``known`` that ``name`` spells, ``-`` and ``_`` being the same character
    (``paper_experiment`` is ``paper-experiment``, as pip treats package names); ``None`` if
    none does."""
    key = name.replace("_", "-")
    return next((k for k in known if k.replace("_", "-") == key), None)


def by_name(*specs: Spec) -> dict[str, Spec]:
    """``specs`` keyed by their names (a group of parameters that are not dataclass fields)."""
    return {spec.name: spec for spec in specs}


def check_fields(instance: Any, specs: Mapping[str, Spec], *, prefix: str = "",
                 error: type[InputError] = InputError) -> None:
    """Check every spec'd field of the (frozen) dataclass ``instance`` and store its normalised
    value; errors name the parameter as ``prefix + spec.name``."""
    for field, spec in specs.items():
        value = spec.check(getattr(instance, field), f"{prefix}{spec.name}", error=error)
        object.__setattr__(instance, field, value)


def as_mapping(where: str, raw: Any, *, error: type[InputError] = InputError
               ) -> Mapping[str, Any]:
    """``raw`` as a mapping (``None`` is empty); anything else raises naming ``where``."""
    if raw is None:
        return {}
    if not isinstance(raw, Mapping):
        raise error(f"{where} = {raw!r} is not a mapping", parameter=where, value=raw,
                    allowed="a mapping of key: value")
    return raw


def former_name_choice(name: str, formerly: Iterable[str], present: Container[str], *,
                       prefix: str = "") -> tuple[str | None, list[str]]:
    """Which of ``name`` and its former names ``formerly`` to take a value from when ``present``
    holds some: the current name first, else the first former one (``None`` if none is there);
    and one deprecation message per former name present (``prefix`` qualifies the names)."""
    names = [n for n in (name, *formerly) if n in present]
    messages = [f"{prefix}{old} is deprecated; use {prefix}{name} (same meaning)"
                + ("" if old == names[0] else f"; ignored, {prefix}{names[0]} is set too")
                for old in names if old != name]
    return (names[0] if names else None), messages


def current_names(where: str, specs: Iterable[Spec], data: Mapping[str, Any]) -> dict[str, Any]:
    """``data`` with each key that is a spec's former name under the spec's name, warned as
    deprecated (:class:`DeprecatedNameWarning`); a former name beside the current one is
    dropped, warned."""
    renamed = dict(data)
    for spec in specs:
        chosen, messages = former_name_choice(spec.name, spec.formerly, data, prefix=f"{where}.")
        for message in messages:
            warnings.warn(message, DeprecatedNameWarning, stacklevel=2)
        for old in spec.formerly:
            renamed.pop(old, None)
        if chosen is not None:
            renamed[spec.name] = data[chosen]
    return renamed


def parse_mapping(where: str, specs: Iterable[Spec], raw: Any, *,
                  error: type[InputError] = InputError) -> dict[str, Any]:
    """Values for every spec from the mapping ``raw`` (keys ``where.name``, or a former name,
    warned; defaults filled in); unknown keys raise listing the valid ones."""
    specs = tuple(specs)
    data = current_names(where, specs, as_mapping(where, raw, error=error))
    by_name = {spec.name: spec for spec in specs}
    reject_unknown(f"key in {where}", data, by_name, error=error)
    return {name: spec.parse(data[name], f"{where}.{name}", error=error) if name in data
            else spec.default for name, spec in by_name.items()}


def spec_table(specs: Iterable[Spec], prefix: str = "") -> list[dict[str, str]]:
    """Rows ``name, unit, default, allowed, description`` for documentation and the CLI."""
    return [{"name": f"{prefix}{s.name}", "unit": s.unit, "default": repr(s.default),
             "allowed": s.allowed(), "description": s.description} for s in specs]
