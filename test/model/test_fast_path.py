"""The single solve's fast path (one compiled call, a lazy result) is the general path bit for
bit: every field of every result, across presets, tensions, routings and warm starts; the
result is immutable and its lazy fields equal the eager ones; clearing the grid cache
forgets the fast path's grid too."""

from __future__ import annotations

import dataclasses
from time import perf_counter
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.model import PRESETS, SolverSettings, preset, solve
from tdcm_ros.model import solver as solver_module
from tdcm_ros.model.grid import build_grid, clear_grid_cache
from tdcm_ros.model.result import FIELDS, SolveResult

COMPARED = tuple(name for name in FIELDS if name != "solve_time_s")


def general(design, tension, config=solver_module.DEFAULT_SETTINGS, warm_start=None):
    """The general path of :func:`solve` (strategies, models, eager result), skipping the
    fast one."""
    return solver_module._solve(design, float(tension), config, warm_start, True, None,
                                perf_counter())


def outcome(call) -> Any:
    """``call()``'s result, or the type and message of what it raised."""
    try:
        return call()
    except Exception as error:  # noqa: BLE001 - the two paths must raise alike
        return type(error), str(error)


def assert_same(fast: Any, slow: Any) -> None:
    """Equal outcomes: the same error, or every field equal to the bit (dtype and shape)."""
    if not isinstance(fast, SolveResult) or not isinstance(slow, SolveResult):
        assert fast == slow
        return
    for name in COMPARED:
        a, b = getattr(fast, name), getattr(slow, name)
        if isinstance(b, np.ndarray):
            assert isinstance(a, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, name
            np.testing.assert_array_equal(a, b, err_msg=name, strict=True)
        else:
            assert a == b, name
    assert fast.summary() | {"solve_time_s": 0} == slow.summary() | {"solve_time_s": 0}


@settings(max_examples=40, deadline=None)
@given(name=st.sampled_from(sorted(PRESETS)), tension=st.floats(0.0, 30.0),
       previous=st.none() | st.floats(0.0, 30.0), routing=st.sampled_from(["paper", "free"]))
def test_the_fast_path_is_the_general_path_bit_for_bit(name, tension, previous, routing):
    design = preset(name)
    config = SolverSettings(routing=routing)
    warm = None if previous is None else outcome(lambda: solve(design, previous, settings=config))
    warm = warm if isinstance(warm, SolveResult) else None
    fast = outcome(lambda: solve(design, tension, settings=config, warm_start=warm))
    assert_same(fast, outcome(lambda: general(design, tension, config, warm)))


@pytest.mark.parametrize("name", ["paper-experiment", "fig2-wn-1", "fig3-wd-2"])
def test_presets_at_the_papers_tensions_take_the_fast_path(name):
    """At 4, 12 and 20 N the presets converge in the first compiled call: the fast path's
    result (kernel buffer kept), equal to the general path's."""
    design = preset(name)
    for tension in (4.0, 12.0, 20.0):
        fast = solve(design, tension)
        assert "_out" in vars(fast) and "positions" not in vars(fast)
        assert_same(fast, general(design, tension))


def test_equal_settings_that_are_other_objects_give_the_same_result():
    design = preset("paper-experiment")
    first = solve(design, 20.0, settings=SolverSettings())
    assert_same(solve(design, 20.0, settings=SolverSettings()), first)
    assert_same(solve(design, 20.0), first)


def test_a_result_is_immutable_and_its_lazy_fields_are_the_eager_ones():
    design = preset("paper-experiment")
    fast = solve(design, 20.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.positions = np.zeros((1, 3))  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del fast.theta
    slow = general(design, 20.0)
    eager = SolveResult(*(getattr(slow, name) for name in FIELDS))
    assert_same(fast, eager)
    assert repr(fast).startswith("SolveResult(design=")


def test_clearing_the_grid_cache_forgets_the_fast_paths_grid():
    design = preset("paper-experiment")
    before = solve(design, 20.0).grid
    clear_grid_cache()
    after = solve(design, 20.0).grid
    assert after is not before
    assert after is build_grid(design, solver_module.DEFAULT_SETTINGS)
