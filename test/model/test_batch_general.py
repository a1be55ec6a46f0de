"""The batch solver takes every design ``solve`` takes: several tendons (a tension per tendon on
a last axis), material laws and axial compression, each member solved as ``solve`` solves it."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.model import (
    InvalidDesignError,
    InvalidTargetError,
    SolverSettings,
    TensionRangeError,
    preset,
    search_designs,
    solve,
)
from tdcm_ros.model.batch import prepare_batch, solve_batch
from tdcm_ros.model.body_file import read_body_file

BODIES = Path(__file__).resolve().parents[2] / "config" / "bodies"
PAIR = read_body_file(BODIES / "antagonistic_pair.yaml").design()
DISK = read_body_file(BODIES / "disk_routed.yaml").design()
NITINOL = read_body_file(BODIES / "nitinol_wrist.yaml").design()
PAPER = preset("paper-experiment")
DEFAULT = SolverSettings()


def assert_member_is_the_solve(batch, index, design, tension, config=DEFAULT) -> None:
    """Member ``index`` of ``batch`` holds ``solve(design, tension)``'s tip, angle and peak
    strain, bit for bit."""
    result = solve(design, tension, settings=config)
    assert batch.status[index] == "ok", batch.message[index]
    assert np.array_equal(batch.tip_position[index], result.tip_position)
    assert batch.tip_angle_rad[index] == result.tip_angle_rad
    assert batch.max_bending_strain[index] == result.notch_peak_strains.max()
    assert batch.iterations[index] == result.iterations
    assert batch.fallback[index]


@settings(max_examples=15, deadline=None)
@given(tensions=st.lists(st.tuples(st.floats(0.0, 30.0), st.floats(0.0, 30.0)), min_size=1,
                         max_size=4))
def test_a_pair_of_tendons_solves_member_by_member_as_solve(tensions) -> None:
    vectors = np.array(tensions)[None, :, :]
    batch = solve_batch([PAIR], vectors)
    assert batch.status.shape == (1, len(tensions))
    assert batch.tensions.shape == (1, len(tensions), 2)
    for k, pair in enumerate(tensions):
        if batch.status[0, k] == "ok":
            assert_member_is_the_solve(batch, (0, k), PAIR, list(pair))
        else:  # a model limit: solve raises the same one
            with pytest.raises(Exception, match=batch.message[0, k].split(":")[0]):
                solve(PAIR, list(pair))


def test_designs_of_several_tendons_pair_with_their_own_vectors() -> None:
    tensions = np.array([[[20.0, 5.0], [10.0, 10.0]], [[1.0, 0.5], [0.0, 2.0]]])
    batch = solve_batch([PAIR, DISK], tensions)
    for d, design in enumerate((PAIR, DISK)):
        for k in range(2):
            assert_member_is_the_solve(batch, (d, k), design, tensions[d, k].tolist())
    # cancelling tensions leave the symmetric pair straight
    straight = solve_batch([PAIR], [[[12.0, 12.0]]])
    assert straight.status[0, 0] == "ok"
    assert straight.tip_deflection_m[0, 0] == pytest.approx(0.0, abs=1e-12)


def test_a_material_law_and_axial_compression_are_solved_as_solve_does() -> None:
    law = solve_batch([NITINOL, PAPER], [1.5, 20.0])
    assert_member_is_the_solve(law, 0, NITINOL, 1.5)
    assert not law.fallback[1]  # the paper's body stays on the compiled iteration
    assert np.array_equal(law.tip_position[1], solve(PAPER, 20.0).tip_position)
    compressible = SolverSettings(axial="compressible")
    shortened = solve_batch([PAPER], [[5.0, 20.0]], settings=compressible)
    for k, tension in enumerate((5.0, 20.0)):
        assert_member_is_the_solve(shortened, (0, k), PAPER, tension, compressible)
    assert shortened.tip_position[0, 1, 2] < solve(PAPER, 20.0).tip_position[2]


def test_a_bad_member_is_marked_and_the_others_are_solved() -> None:
    batch = solve_batch([PAIR], [[[20.0, 5.0], [math.nan, 1.0], [3.0, -1.0]]])
    assert list(batch.status[0]) == ["ok", "invalid", "invalid"]
    assert "tension[0] = nan" in batch.message[0, 1]
    assert "tension[1] = -1" in batch.message[0, 2]
    assert np.all(np.isnan(batch.tip_position[0, 1:]))


def test_a_strain_limit_is_a_member_status() -> None:
    tight = dataclasses.replace(NITINOL, material=dataclasses.replace(
        NITINOL.material, recoverable_strain=1e-4))
    batch = solve_batch([tight], [1.0])
    assert batch.status[0] == "strain_limit"
    assert "recoverable strain" in batch.message[0]


@pytest.mark.parametrize(("designs", "tensions", "error", "message"), [
    ([PAIR, PAPER], [[1.0, 2.0], [3.0, 4.0]], InvalidDesignError,
     r"designs\[1\]\.tendons: 1 tendon\(s\) where designs\[0\] has 2"),
    ([PAIR], [1.0], TensionRangeError, r"shape \(1,\) do not match 1 designs of 2 tendon"),
    ([PAIR], [[1.0, 2.0, 3.0]], TensionRangeError, r"allowed: shape \(len\(designs\), \.\.\., 2\)"),
])
def test_tendon_counts_and_tension_shapes_are_checked(designs, tensions, error, message) -> None:
    with pytest.raises(error, match=message):
        solve_batch(designs, tensions)


def test_prepared_grids_solve_several_tendons_in_rounds() -> None:
    grids = prepare_batch([PAIR, DISK])
    first = grids.solve([[[4.0, 1.0]]], subset=[1])
    again = solve_batch([DISK], [[[4.0, 1.0]]])
    assert np.array_equal(first.tip_position, again.tip_position)
    assert list(grids.single) == [0, 1]


def test_a_design_search_seeks_one_tendon_with_the_others_held() -> None:
    search = search_designs(PAIR, {"w_n": (1e-3, 3e-3)}, tip_angle=0.2, tension_max=20.0,
                            samples=8, tendon="flexor", tensions=[0.0, 5.0])
    assert search.pareto.size >= 1
    for i in np.flatnonzero(search.outcome == "meets"):
        design = search.design(int(i))
        reached = solve(design, [float(search.tension_n[i]), 5.0])
        assert abs(reached.tip_angle_rad - 0.2) <= search.tol
        # the preload counts: without it the same tension bends further
        assert solve(design, [float(search.tension_n[i]), 0.0]).tip_angle_rad > 0.2
    with pytest.raises(InvalidTargetError, match="tendon is missing"):
        search_designs(PAIR, {"w_n": (1e-3, 3e-3)}, tip_angle=0.2, samples=2)
