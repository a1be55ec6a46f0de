"""The batch solver gives the single solve's answers and statuses, member by member."""

import numpy as np
import pytest

from tdcm_ros.model import (
    CustomProfile,
    InvalidDesignError,
    ModelError,
    RectangularProfile,
    SolverSettings,
    TensionRangeError,
    batch,
    preset,
    solve,
)
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.section import notched_moment

STATUS_OF_KIND = {"tendon_singularity": "singularity", "notch_closure": "closure",
                  "non_convergence": "non_convergence"}


def random_designs(seed: int, count: int) -> list:
    """Paper-like designs over wide ranges, several cell layouts (N, empty segments); about a
    third per notch (each notch its own width and backbone, half of them also their own
    profile, each gap its own tube, some repeated, some none)."""
    rng = np.random.default_rng(seed)
    base = preset("paper-experiment")
    designs = []
    for _ in range(count):
        n = int(rng.choice([2, 5, 8]))
        w_n = rng.uniform(0.4e-3, 3e-3)
        w_t = float(rng.choice([0.0, rng.uniform(1e-3, 5e-3)]))
        w_d = rng.uniform(0.5e-3, 2.5e-3)
        profile = RectangularProfile() if rng.random() < 0.3 else base.profile
        if rng.random() < 0.35:
            w_n = rng.choice([w_n, rng.uniform(0.4e-3, 3e-3)], n).tolist()
            w_d = rng.choice([w_d, rng.uniform(0.5e-3, 2.5e-3)], n).tolist()
            w_t = rng.choice([0.0, w_t, rng.uniform(1e-3, 5e-3)], n - 1).tolist()
            if rng.random() < 0.5:
                profile = rng.choice(["circular", "rectangular"], n).tolist()
        designs.append(base.with_overrides(
            N=n, w_n=w_n, w_t=w_t, w_d=w_d,
            w_tip=float(rng.choice([0.0, rng.uniform(1e-3, 5e-3)])), w_base=rng.uniform(0, 6e-3),
            R_c=rng.uniform(1.5e-3, 3.5e-3), E=rng.uniform(0.8e9, 2.5e9), profile=profile))
    return designs


def single(design, tension, settings):
    """(status, tip position or None, iterations) of the single solve."""
    try:
        result = solve(design, tension, settings=settings)
    except ModelError as error:
        return STATUS_OF_KIND[error.kind], None
    return "ok", result.tip_position


SETTINGS = [
    SolverSettings(),
    SolverSettings(routing="free"),
    SolverSettings(acceleration="none", max_iter=40),
    SolverSettings(acceleration="relaxation"),
    SolverSettings(acceleration="anderson"),
    SolverSettings(cells_per_notch=3, quad_order=2, tol=1e-8),
]


@pytest.mark.parametrize("settings", SETTINGS, ids=lambda s: f"{s.routing}-{s.acceleration}")
def test_batch_equals_single_solves_on_random_designs(settings):
    designs = random_designs(seed=7, count=30)
    tensions = np.random.default_rng(3).uniform(0.0, 60.0, (30, 4))
    result = solve_batch(designs, tensions, settings=settings)
    statuses = set()
    for i, design in enumerate(designs):
        for k in range(tensions.shape[1]):
            status, tip = single(design, tensions[i, k], settings)
            assert result.status[i, k] == status, (i, k, result.message[i, k])
            statuses.add(status)
            if tip is None:
                assert np.all(np.isnan(result.tip_position[i, k]))
            else:
                np.testing.assert_allclose(result.tip_position[i, k], tip, rtol=0, atol=1e-12)
    assert "ok" in statuses and len(statuses) >= 2  # the sample reaches a model limit too
    assert sum(not d.is_uniform for d in designs) >= 5   # and holds per-notch designs


CONVERGED = SolverSettings(cells_per_notch=32, cells_per_tube=8, quad_order=12, tol=1e-13,
                           max_iter=1000)


@pytest.mark.parametrize("settings", [SETTINGS[0], SETTINGS[1], SETTINGS[-1]],
                         ids=["paper", "free", "coarse"])
def test_interpolated_partials_stay_within_the_grids_accuracy_of_single_solves(settings):
    # Default quadrature: within 2e-9 m of the single solve (nested partial integrals); a
    # coarse one (order 2): the interpolated rule (degree 10) errs no more, worst member.
    designs = random_designs(seed=7, count=12)
    tensions = np.random.default_rng(3).uniform(0.0, 60.0, (12, 2))
    result = solve_batch(designs, tensions, settings=settings, partials="interpolated")
    errors: dict[str, list[float]] = {"batch": [], "single": []}
    for i, design in enumerate(designs):
        for k in range(tensions.shape[1]):
            status, tip = single(design, tensions[i, k], settings)
            assert result.status[i, k] == status, (i, k, result.message[i, k])
            if tip is None:
                continue
            if settings.quad_order == SolverSettings().quad_order:
                np.testing.assert_allclose(result.tip_position[i, k], tip, rtol=0, atol=2e-9)
            else:
                fine = solve(design, tensions[i, k], settings=CONVERGED).tip_position
                errors["batch"].append(float(np.linalg.norm(result.tip_position[i, k] - fine)))
                errors["single"].append(float(np.linalg.norm(tip - fine)))
    if errors["batch"]:  # the worst member: no farther from the converged tip than the single
        assert max(errors["batch"]) <= max(errors["single"]), errors


def test_literal_loads_fall_back_to_single_solves():
    designs = [preset("paper-experiment"), preset("fig3-wd-1.2")]
    settings = SolverSettings(loads="literal")
    result = solve_batch(designs, [4.0, 12.0], settings=settings)
    assert result.fallback.all() and result.ok.all()
    for i, (design, tension) in enumerate(zip(designs, [4.0, 12.0])):
        tip = solve(design, tension, settings=settings).tip_position
        np.testing.assert_allclose(result.tip_position[i], tip, rtol=0, atol=1e-12)


def test_chunking_and_grouping_do_not_change_answers(monkeypatch):
    designs = random_designs(seed=11, count=12)
    tensions = np.linspace(0.0, 25.0, 12 * 9).reshape(12, 9)
    whole = solve_batch(designs, tensions)
    monkeypatch.setattr(batch, "CHUNK", 5)
    chunked = solve_batch(designs, tensions)
    np.testing.assert_array_equal(whole.status, chunked.status)
    np.testing.assert_allclose(whole.tip_position, chunked.tip_position, rtol=0, atol=1e-15)
    pairs = solve_batch(designs[::-1], tensions[::-1, 4])
    np.testing.assert_allclose(pairs.tip_deflection_m, whole.tip_deflection_m[::-1, 4],
                               rtol=0, atol=1e-15)


def test_outputs_match_single_result_fields():
    design = preset("fig2-wn-1.9")
    result = solve_batch([design], [[5.0, 20.0]])
    assert result.tip_position.shape == (1, 2, 3)
    one = solve(design, 20.0)
    assert result.tip_angle_rad[0, 1] == pytest.approx(one.tip_angle_rad, abs=1e-13)
    assert result.tip_deflection_m[0, 1] == pytest.approx(one.tip_deflection_m, abs=1e-13)
    assert result.iterations[0, 1] == one.iterations
    assert not result.fallback.any()


def test_max_bending_strain_closed_form_for_rectangular_notch():
    # Paper routing: the moment in a notch is exactly R_c T; a rectangular notch has
    # h1 = w_d/2 and a uniform section, so the strain is R_c T (w_d/2) / (E I(w_d/2)).
    design = preset("paper-experiment").with_overrides(profile=RectangularProfile())
    tension = 12.0
    result = solve_batch([design], [tension])
    inertia = float(notched_moment(design.w_d / 2, design.R_outer, design.r_inner))
    expected = design.R_c * tension * (design.w_d / 2) / (design.E * inertia)
    assert result.max_bending_strain[0] == pytest.approx(expected, rel=1e-12)


def test_max_bending_strain_bounds_curvature_profile():
    design = preset("fig3-wd-1.2")
    result = solve_batch([design], [20.0])
    s, kappa = solve(design, 20.0).curvature_profile
    left, right = design.notch_bounds()
    inside = np.zeros_like(s, dtype=bool)
    for lo, hi in zip(left, right):
        inside |= (s >= lo) & (s <= hi)
    # The smallest fibre distance in a notch is w_d/2 at its centre, which is a sample.
    centre_strain = np.max(np.abs(kappa[inside])) * design.w_d / 2
    assert result.max_bending_strain[0] == pytest.approx(centre_strain, rel=1e-9)


def test_invalid_members_are_marked_not_raised():
    design = preset("paper-experiment")
    result = solve_batch([design, design, design], [-1.0, np.nan, 3.0])
    assert list(result.status) == ["invalid", "invalid", "ok"]
    assert "tension" in result.message[0] and np.isnan(result.tip_deflection_m[0])
    bad_profile = design.with_overrides(profile=CustomProfile(lambda s: -1.0 + 0.0 * s))
    result = solve_batch([bad_profile, design], [2.0, 2.0])
    assert list(result.status) == ["invalid", "ok"]
    assert "h1(s)" in result.message[0]


def test_bad_arguments_raise_typed_errors():
    design = preset("paper-experiment")
    with pytest.raises(TensionRangeError, match="tensions"):
        solve_batch([design, design], [1.0, 2.0, 3.0])
    with pytest.raises(TensionRangeError, match="tensions"):
        solve_batch([design], "abc")
    with pytest.raises(InvalidDesignError, match=r"designs\[1\]"):
        solve_batch([design, "paper-experiment"], [1.0, 2.0])


def test_members_that_slow_down_are_handed_to_the_single_solve():
    # A thin, soft tube under free routing: Picard contracts by 0.96 on its second step, so
    # ``solve`` switches to Anderson; the batch must hand that member over, not keep going.
    slow = preset("paper-experiment").with_overrides(
        w_n=3.630792315e-3, w_t=0.0, w_d=1.5174998e-3, N=7, R_outer=1.0534322645e-3,
        r_inner=0.8736510869e-3, R_c=0.5435634725e-3, E=1.0907326125e9)
    settings = SolverSettings(routing="free")
    fast = preset("paper-experiment")
    result = solve_batch([slow, fast], [166.53792605525183, 5.0], settings=settings)
    one = solve(slow, 166.53792605525183, settings=settings)
    assert one.strategy == "picard+anderson" and one.iterations > 3
    assert list(result.fallback) == [True, False]
    assert result.iterations[0] == one.iterations
    np.testing.assert_allclose(result.tip_position[0], one.tip_position, rtol=0, atol=1e-12)


def test_threads_give_the_same_answers(monkeypatch):
    designs = random_designs(seed=5, count=10)
    tensions = np.linspace(0.0, 30.0, 10 * 7).reshape(10, 7)
    monkeypatch.setattr(batch, "CHUNK", 4)  # many chunks for the threads to share
    one = solve_batch(designs, tensions)
    two = solve_batch(designs, tensions, workers=2)
    np.testing.assert_array_equal(one.status, two.status)
    np.testing.assert_array_equal(one.tip_position, two.tip_position)
    np.testing.assert_array_equal(one.iterations, two.iterations)
    np.testing.assert_array_equal(one.max_bending_strain, two.max_bending_strain)


@pytest.mark.parametrize("workers", [0, 1.5, True, 65])
def test_bad_worker_counts_raise_typed_errors(workers):
    with pytest.raises(batch.InvalidSettingsError, match="workers"):
        solve_batch([preset("paper-experiment")], [1.0], workers=workers)


def test_stacked_designs_equal_designs_solved_alone():
    # Grids of many designs are built at once and padded per cell count: each member's tip and
    # strain equal those of a batch of its design alone.
    designs = random_designs(seed=5, count=16)
    tensions = np.random.default_rng(9).uniform(0.0, 30.0, 16)
    together = solve_batch(designs, tensions)
    for i, design in enumerate(designs):
        alone = solve_batch([design], tensions[i:i + 1])
        assert together.status[i] == alone.status[0]
        np.testing.assert_allclose(together.tip_position[i], alone.tip_position[0], rtol=0,
                                   atol=1e-12)
        np.testing.assert_allclose(together.max_bending_strain[i], alone.max_bending_strain[0],
                                   rtol=1e-12, atol=0)


def test_a_layout_group_larger_than_a_chunk_gathers_per_chunk_with_the_same_answers():
    # 300 designs of one cell count (only E differs): more than CHUNK designs, so each chunk
    # gathers its own designs' kernel arrays; every member must still equal its single solve.
    from tdcm_ros.model.batch import CHUNK

    base = preset("paper-experiment")
    designs = [base.with_overrides(E=base.E * (1.0 + 0.002 * k)) for k in range(CHUNK + 44)]
    tensions = np.linspace(1.0, 20.0, len(designs))[::-1].copy()
    result = solve_batch(designs, tensions)
    assert np.all(result.ok)
    for k in range(0, len(designs), 23):
        single = solve(designs[k], float(tensions[k]))
        assert np.max(np.abs(single.tip_position - result.tip_position[k])) <= 1e-12
    alone = solve_batch(designs[-3:], tensions[-3:])
    np.testing.assert_array_equal(alone.max_bending_strain, result.max_bending_strain[-3:])


def test_prepared_grids_solve_any_subset_as_solve_batch_does():
    # A search solves the same designs in rounds: grids built once, any distinct subset in any
    # order, an invalid design marked in every round that includes it.
    designs = random_designs(seed=13, count=9)
    designs[4] = designs[4].with_overrides(profile=CustomProfile(lambda s: -1.0 + 0.0 * s))
    prepared = batch.prepare_batch(designs)
    tensions = np.random.default_rng(2).uniform(0.0, 30.0, (9, 3))
    whole = solve_batch(designs, tensions)
    subset = np.array([8, 4, 0, 5])
    part = prepared.solve(tensions[subset], subset=subset)
    np.testing.assert_array_equal(part.status, whole.status[subset])
    np.testing.assert_array_equal(part.tip_position, whole.tip_position[subset])
    np.testing.assert_array_equal(part.max_bending_strain, whole.max_bending_strain[subset])
    assert list(part.status[1]) == ["invalid"] * 3
    again = prepared.solve(tensions[:, 0])
    np.testing.assert_array_equal(again.tip_position, whole.tip_position[:, 0])


@pytest.mark.parametrize("subset", [[0, 0], [-1], [3], [0.5], [[0]]])
def test_bad_subsets_raise_typed_errors(subset):
    prepared = batch.prepare_batch([preset("paper-experiment")] * 3)
    with pytest.raises(batch.InvalidSettingsError, match="subset"):
        prepared.solve(np.ones(len(subset)), subset=subset)
