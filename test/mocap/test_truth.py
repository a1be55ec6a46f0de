"""The simulated truth as a time series: interpolation against numpy's, and the frame grid."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.mocap.truth import FrameClock, TruthTrack


@given(steps=st.lists(st.integers(1, 10**9), min_size=1, max_size=40),
       values=st.lists(st.floats(-1e3, 1e3), min_size=40, max_size=40),
       queries=st.lists(st.integers(-10**9, 5 * 10**10), min_size=1, max_size=20))
def test_at_interpolates_as_numpy_does(steps: list[int], values: list[float],
                                       queries: list[int]) -> None:
    stamps = np.cumsum(steps)
    track = TruthTrack()
    for stamp, value in zip(stamps, values, strict=False):
        track.add(int(stamp), value)
    expected = np.interp(queries, stamps, values[:len(stamps)])
    got = [track.at(q) for q in queries]
    assert np.allclose(got, expected, rtol=1e-12, atol=1e-9)
    assert track.newest_ns == stamps[-1]


def test_a_sample_older_than_the_newest_is_dropped_and_a_repeat_replaces() -> None:
    track = TruthTrack()
    track.add(100, 1.0)
    track.add(200, 2.0)
    track.add(150, 9.0)      # late and out of order: the track keeps increasing stamps
    track.add(200, 3.0)      # the same stamp again: the newer value
    assert track.newest_ns == 200 and track.at(150) == 2.0 and track.at(200) == 3.0
    assert not TruthTrack()


def test_the_frame_grid_starts_at_the_first_call_and_hands_each_time_out_once() -> None:
    clock = FrameClock(50.0)
    assert list(clock.until(1_000)) == [1_000]
    assert list(clock.until(1_000 + 19_999_999)) == []
    assert list(clock.until(1_000 + 70_000_000)) == [1_000 + k * 20_000_000 for k in (1, 2, 3)]
    assert list(clock.until(0)) == []        # a clock behind the grid hands nothing out again
