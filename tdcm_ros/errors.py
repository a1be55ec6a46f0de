"""The package's error tree.

``TdcmError`` is the root. Two categories cross all subpackages and decide how the
CLI exits:

- :class:`InputError` (exit status 2): a bad parameter, value or file; the message names the
  parameter, the value and the allowed range.
- :class:`PhysicsError` (exit status 3): a physical limit of the model or a numerical failure.

Each subpackage defines one ``XxxError`` of its own (e.g. ``tdcm_ros.model.ModelError``) and
its specific errors derive from it and from one of the categories.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sized
from typing import Any


class TdcmError(Exception):
    """Root of every error raised on purpose by tdcm_ros."""

    kind: str = "error"
    exit_code: int = 1


class InputError(TdcmError, ValueError):
    """Bad input: names the parameter, the value and the allowed range."""

    kind = "input"
    exit_code = 2

    def __init__(self, message: str, *, parameter: str | None = None, value: Any = None,
                 allowed: str | None = None) -> None:
        super().__init__(message)
        self.parameter = parameter
        self.value = value
        self.allowed = allowed


class PhysicsError(TdcmError):
    """A physical limit of the model was reached, or the numerics did not converge."""

    kind = "physics"
    exit_code = 3


#: Longest ``repr`` of a value an error message shows whole.
SHOWN_CHARS = 80


def exact_number(value: float) -> str:
    """``value`` as short as ``:g`` shows it when that reads back as the same float, else with
    every digit it needs (``repr``): a printed bound is the true bound."""
    short = f"{value:g}"
    if float(short) == value:
        return short
    if float(value).is_integer() and abs(value) < 2**53:
        return str(int(value))
    return repr(float(value))


def shown_value(value: Any) -> str:
    """``repr(value)``, or its first :data:`SHOWN_CHARS` characters and the value's length."""
    text = repr(value)
    if len(text) <= SHOWN_CHARS:
        return text
    if isinstance(value, str):
        size = f"{len(value)} characters"
    elif isinstance(value, Sized):
        size = f"{len(value)} elements"
    else:
        size = f"{len(text)} characters"
    return f"{text[:SHOWN_CHARS]}... ({size})"


def out_of_range(parameter: str, value: Any, allowed: str, *, unit: str = "",
                 error: type[InputError] = InputError) -> InputError:
    """Build an :class:`InputError` (or subclass) with the standard one-line message (a long
    value is shown by its start and its length)."""
    shown = f"{shown_value(value)} {unit}".rstrip()
    return error(f"{parameter} = {shown} is out of range; allowed: {allowed}",
                 parameter=parameter, value=value, allowed=allowed)


def reject_unknown(what: str, names: Mapping[str, Any], known: Iterable[str], *,
                   error: type[InputError] = InputError) -> None:
    """Raise ``error`` for the first key of ``names`` not in ``known``, listing the allowed ones."""
    known_set = set(known)
    allowed = ", ".join(sorted(known_set))
    for name, value in names.items():
        if name not in known_set:
            raise error(f"unknown {what} {name!r}; allowed: {allowed}", parameter=name,
                        value=value, allowed=allowed)
