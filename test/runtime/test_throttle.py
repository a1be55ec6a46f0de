"""Throttled warnings: the first of a kind at once, then one per period with the count held."""

from __future__ import annotations

import logging

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.runtime.throttle import Throttled, template


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_one_warning_per_key_and_period_and_the_count_of_those_held(
        caplog: pytest.LogCaptureFixture) -> None:
    clock = Clock()
    throttled = Throttled(logging.getLogger("throttle_test"), period_s=2.0, clock=clock)
    with caplog.at_level(logging.WARNING, "throttle_test"):
        shown = [throttled.warn("a", f"a {i}") for i in range(5)]
        assert throttled.warn("b", "b 0")  # another key is not held back
        clock.now = 1.999
        assert not throttled.warn("a", "a 5")
        clock.now = 2.0
        assert throttled.warn("a", "a 6")
    assert shown == [True, False, False, False, False]
    assert [r.getMessage() for r in caplog.records] == [
        "a 0", "b 0", "a 6 (5 more like it in the last 2.0 s)"]
    assert throttled.counts == {"a": 7, "b": 1}


@given(a=st.floats(allow_nan=True, allow_infinity=True), b=st.floats(allow_nan=True))
def test_a_template_is_the_same_whatever_the_numbers(a: float, b: float) -> None:
    assert template(f"setpoint = {a!r} N is out of range [0, {b:g}] N") == \
        template("setpoint = 1 N is out of range [0, 2] N")
    assert template("device link lost: eof") != template("device refused command 3: busy")
