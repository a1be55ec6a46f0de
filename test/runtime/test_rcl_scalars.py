"""rcl's scalar rules: ``strtoll``/``strtod`` against the C library itself (ctypes), and the
type order of ``get_value`` (bool, integer, YAML special float, double, string)."""

from __future__ import annotations

import ctypes
import ctypes.util
import math

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tdcm_ros.runtime.rcl_scalars import rcl_scalar, strtod, strtoll

_LIBC = ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True)
_LIBC.strtod.restype = ctypes.c_double
_LIBC.strtod.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_char_p)]
_LIBC.strtoll.restype = ctypes.c_longlong
_LIBC.strtoll.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_char_p), ctypes.c_int]


def c_reads_whole(function: str, text: str) -> float | int | None:
    """``function`` (``strtod`` or ``strtoll`` in base 0) of libc on ``text``: its value when
    it consumed every character with errno 0, else ``None`` (rcl's acceptance test)."""
    data = ctypes.create_string_buffer(text.encode("ascii"))
    end = ctypes.c_char_p()
    ctypes.set_errno(0)
    if function == "strtod":
        value: float | int = _LIBC.strtod(data, ctypes.byref(end))
    else:
        value = _LIBC.strtoll(data, ctypes.byref(end), 0)
    consumed = ctypes.cast(end, ctypes.c_void_p).value - ctypes.addressof(data)  # type: ignore[operator]
    if ctypes.get_errno() != 0 or consumed == 0 or consumed != len(text):
        return None
    return value


NUMBERISH = st.text(alphabet="0123456789+-.eExXpPabcdfABCDF _:infINFtyn()", max_size=14)
EDGES = ["0x1F", "010", "08", "0b11", "1_000", "1:30", "9223372036854775807",
         "9223372036854775808", "-9223372036854775808", "1e999", "1e-310", "4.9e-324",
         "0x1p-1074", "0x1p-1075", "0x1.8p3", "0x.8", "0x", "5.", ".5", "inf", "-Infinity",
         "nan", "nan(x1)", "1e", "+", "-0", " 7", "7 ", "2.2250738585072011e-308",
         "0x1.fffffffffffff8p1023", "1.7976931348623158e308"]


@pytest.mark.parametrize("text", EDGES)
def test_edge_spellings_read_as_the_c_library_reads_them(text: str) -> None:
    assert strtoll(text) == c_reads_whole("strtoll", text)
    expected = c_reads_whole("strtod", text)
    got = strtod(text)
    if expected is not None and math.isnan(expected):
        assert got is not None and math.isnan(got)
    else:
        assert got == expected and (got is None or math.copysign(1, got) == math.copysign(1, expected))


@settings(max_examples=400, deadline=None)
@given(NUMBERISH)
@example("0x10p-2")
def test_any_number_like_text_reads_as_the_c_library_reads_it(text: str) -> None:
    assert strtoll(text) == c_reads_whole("strtoll", text)
    expected = c_reads_whole("strtod", text)
    got = strtod(text)
    assert (got is None) == (expected is None)
    if got is not None and expected is not None and not math.isnan(expected):
        assert got == expected


@settings(max_examples=200, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False, allow_subnormal=False))
def test_every_normal_double_python_writes_reads_back_exactly(value: float) -> None:
    assert strtod(repr(value)) == value


@settings(max_examples=100, deadline=None)
@given(st.floats(min_value=-2.2e-308, max_value=2.2e-308).filter(lambda v: v != 0.0))
def test_a_subnormal_reads_back_in_hex_but_not_in_decimal(value: float) -> None:
    assert strtod(value.hex()) == value  # exact: no range error
    assert strtod(repr(value)) is None   # glibc: ERANGE for an inexact tiny result


@pytest.mark.parametrize(("text", "expected"), [
    ("y", True), ("Yes", True), ("ON", True), ("n", False), ("Off", False), ("FALSE", False),
    ("42", 42), ("0x1F", 31), ("010", 8), ("-7", -7), ("08", 8.0), ("1e9", 1e9),
    ("1.85e+9", 1.85e9), (".5", 0.5), ("-.inf", -math.inf), (".INF", math.inf),
    ("inf", math.inf), ("9223372036854775808", 9223372036854775808.0),
    ("~", "~"), ("null", "null"), ("1_000", "1_000"), ("1:30", "1:30"), ("0b11", "0b11"),
    ("2020-01-01", "2020-01-01"), ("1e999", "1e999"), (".Nan", ".Nan"), ("", ""),
    ("yes please", "yes please"),
])
def test_plain_scalars_take_rcls_type_in_its_order(text: str, expected: object) -> None:
    value = rcl_scalar(text, quoted=False, str_tag=False)
    assert value == expected and type(value) is type(expected)


@pytest.mark.parametrize("text", ["y", "42", "1e9", ".nan"])
def test_quoted_or_str_tagged_scalars_stay_strings(text: str) -> None:
    assert rcl_scalar(text, quoted=True, str_tag=False) == text
    assert rcl_scalar(text, quoted=False, str_tag=True) == text


def test_yaml_nan_is_a_double() -> None:
    assert math.isnan(rcl_scalar(".NaN", quoted=False, str_tag=False))  # type: ignore[arg-type]
