"""The type and value rcl gives one YAML scalar of a parameter file or a ``-p`` value.

rcl (``rcl_yaml_param_parser``, ``get_value``) does not use YAML's schemas: a scalar tagged
``!!str`` or written in quotes is a string; a plain or block scalar is a bool when it is one of
:data:`TRUE_WORDS` / :data:`FALSE_WORDS`, else an integer when C's ``strtoll(text, base 0)``
reads all of it without overflow (so ``0x1F`` is 31 and ``010`` is 8), else a double when it is
one of YAML's ``.inf``/``.nan`` spellings or C's ``strtod`` reads all of it without a range
error (so ``1e9``, ``inf`` and ``0x1p3`` are doubles, ``1e999`` and ``1e-310`` strings), else a
string (``~``, ``null``, ``1_000``, ``1:30``, ``0b11`` and dates stay text).

:func:`strtoll` and :func:`strtod` reproduce glibc's functions on whole strings; the tests check
them against the C library itself.
"""

from __future__ import annotations

import math
import re
import sys
from collections.abc import Callable
from fractions import Fraction

TRUE_WORDS = frozenset({"Y", "y", "yes", "Yes", "YES", "true", "True", "TRUE", "on", "On", "ON"})
FALSE_WORDS = frozenset({"N", "n", "no", "No", "NO", "false", "False", "FALSE", "off", "Off",
                         "OFF"})
#: YAML's infinity and NaN spellings that rcl reads as doubles before trying ``strtod``
YAML_SPECIAL_FLOATS = frozenset({".nan", ".NaN", ".NAN", ".inf", ".Inf", ".INF", "+.inf", "+.Inf",
                                 "+.INF", "-.inf", "-.Inf", "-.INF"})

_C_SPACE = " \t\n\v\f\r"
_INT64 = (-(2**63), 2**63 - 1)
_STRTOLL = re.compile(r"(?P<sign>[+-]?)(?:0[xX](?P<hex>[0-9a-fA-F]+)|(?P<oct>0[0-7]*)"
                      r"|(?P<dec>[1-9][0-9]*))")
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_HEX_FLOAT = re.compile(r"(?P<sign>[+-]?)0[xX](?P<int>[0-9a-fA-F]*)\.?(?P<frac>[0-9a-fA-F]*)"
                        r"(?:[pP](?P<exp>[+-]?[0-9]+))?")
_INF_NAN = re.compile(r"[+-]?(?:inf(?:inity)?|nan(?:\([0-9A-Za-z_]*\))?)", re.IGNORECASE)


def strtoll(text: str) -> int | None:
    """What C's ``strtoll(text, &end, 0)`` returns when it reads all of ``text`` with no range
    error; ``None`` when it stops early, reads nothing or overflows a signed 64-bit integer."""
    found = _STRTOLL.fullmatch(text.lstrip(_C_SPACE))
    if found is None:
        return None
    if found["hex"] is not None:
        magnitude = int(found["hex"], 16)
    elif found["oct"] is not None:
        magnitude = int(found["oct"], 8)
    else:
        magnitude = int(found["dec"])
    value = -magnitude if found["sign"] == "-" else magnitude
    return value if _INT64[0] <= value <= _INT64[1] else None


def strtod(text: str) -> float | None:
    """What glibc's ``strtod(text, &end)`` returns when it reads all of ``text`` with no range
    error; ``None`` when it stops early, overflows, or underflows inexactly (to zero or a
    subnormal that is not the written value)."""
    body = text.lstrip(_C_SPACE)
    if _INF_NAN.fullmatch(body):
        return float(body.partition("(")[0])
    if _DECIMAL.fullmatch(body):
        mantissa = re.split("[eE]", body)[0]
        return _in_range(float(body), written_zero=not mantissa.strip("+-.0"),
                         exact=lambda: Fraction(body))
    hexa = _HEX_FLOAT.fullmatch(body)
    if hexa is None or not (hexa["int"] or hexa["frac"]):
        return None
    digits = int(hexa["int"] + hexa["frac"], 16)
    shift = int(hexa["exp"] or 0) - 4 * len(hexa["frac"])
    sign = -1 if hexa["sign"] == "-" else 1
    if digits == 0:
        return math.copysign(0.0, sign)
    top = digits.bit_length() + shift  # 2**(top - 1) <= |value| < 2**top
    if top > 1024:
        return None
    if top < -1074:
        return None  # below half the smallest subnormal: rounds to zero, inexactly
    exact = sign * Fraction(digits) * Fraction(2) ** shift
    return _in_range(_nearest_float(exact), written_zero=False, exact=lambda: exact)


def _in_range(value: float, *, written_zero: bool, exact: Callable[[], Fraction]
              ) -> float | None:
    """``value``, or ``None`` where glibc sets ``ERANGE``: an overflow to infinity, or a result
    below the smallest normal double that differs from the written number ``exact()``."""
    if math.isinf(value):
        return None
    if abs(value) < sys.float_info.min and not written_zero and Fraction(value) != exact():
        return None
    return value


def _nearest_float(exact: Fraction) -> float:
    """``exact`` rounded to the nearest double, ties to even (Python's int division is);
    ``inf`` past the largest."""
    try:
        return exact.numerator / exact.denominator
    except OverflowError:
        return math.inf if exact > 0 else -math.inf


def rcl_scalar(text: str, *, quoted: bool, str_tag: bool) -> bool | int | float | str:
    """The value rcl gives a scalar: ``quoted`` for ``'...'``/``"..."`` styles, ``str_tag`` when
    it is tagged ``!!str`` (see the module docstring for the rules, in rcl's order)."""
    if str_tag or quoted:
        return text
    if text in TRUE_WORDS:
        return True
    if text in FALSE_WORDS:
        return False
    if text and (integer := strtoll(text)) is not None:
        return integer
    if text in YAML_SPECIAL_FLOATS:
        magnitude = float(text.lstrip("+-."))
        return -magnitude if text.startswith("-") else magnitude
    if text and (double := strtod(text)) is not None:
        return double
    return text
