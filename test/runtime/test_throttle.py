"""Throttled warnings: the first of a kind at once, then one per period with the count held."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.runtime.throttle import Throttled, template


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_one_warning_per_key_and_period_and_the_count_of_those_held() -> None:
    clock = Clock()
    throttled = Throttled(period_s=2.0, clock=clock)
    admitted = [throttled.admit("a") for _ in range(5)]
    assert throttled.admit("b") == ""  # another key is not held back
    clock.now = 1.999
    assert throttled.admit("a") is None
    clock.now = 2.0
    assert throttled.admit("a") == " (5 more like it in the last 2.0 s)"
    assert throttled.admit("a") is None
    assert admitted == ["", None, None, None, None]
    assert throttled.counts == {"a": 8, "b": 1}


@given(a=st.floats(allow_nan=True, allow_infinity=True), b=st.floats(allow_nan=True))
def test_a_template_is_the_same_whatever_the_numbers(a: float, b: float) -> None:
    assert template(f"setpoint = {a!r} N is out of range [0, {b:g}] N") == \
        template("setpoint = 1 N is out of range [0, 2] N")
    assert template("device link lost: eof") != template("device refused command 3: busy")
