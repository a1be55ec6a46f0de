"""The Pareto filter keeps exactly the points no other point dominates."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tdcm_ros.model import pareto
from tdcm_ros.model.pareto import non_dominated


def brute_force(points: np.ndarray) -> list[int]:
    """Indices of the rows no other row dominates, by comparing every pair."""
    keep = []
    for i, p in enumerate(points):
        dominated = np.any(np.all(points <= p, axis=1) & np.any(points < p, axis=1))
        if not dominated:
            keep.append(i)
    return keep


# Few distinct values, so ties and duplicates are common.
POINTS = st.integers(1, 3).flatmap(lambda d: arrays(
    np.float64, st.tuples(st.integers(0, 60), st.just(d)),
    elements=st.sampled_from([0.0, 0.5, 1.0, 1.5, 2.0, -1.0, 3.25])))


@settings(max_examples=300)
@given(points=POINTS, block=st.sampled_from([1, 2, 7, 256]))
def test_front_is_exactly_the_non_dominated_points(points, block):
    original = pareto.BLOCK
    pareto.BLOCK = block  # small blocks exercise the front-so-far comparison
    try:
        front = non_dominated(points)
    finally:
        pareto.BLOCK = original
    assert list(front) == brute_force(points)


def test_continuous_points_three_objectives():
    points = np.random.default_rng(4).normal(size=(700, 3))
    front = non_dominated(points)
    assert list(front) == brute_force(points)
    assert 5 < front.size < 700


@pytest.mark.parametrize("bad", [np.ones(3), np.array([[np.nan, 1.0]]), np.array([[np.inf]])])
def test_bad_objectives_raise(bad):
    with pytest.raises(ValueError, match="objectives"):
        non_dominated(bad)
