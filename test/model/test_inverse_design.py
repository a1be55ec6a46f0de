"""Inverse design: every reported design really meets the target inside the limits, the
tensions agree with solve_inverse, the Pareto set is the non-dominated one, bad input errs."""

import numpy as np
import pytest

from tdcm_ros.model import (
    InvalidDesignError,
    InvalidSettingsError,
    InvalidTargetError,
    ModelError,
    preset,
    solve,
    solve_inverse,
)
from tdcm_ros.model.batch import solve_batch
from tdcm_ros.model.inverse_design import (
    NoDesignMeetsTargetError,
    search_designs,
)

MM = 1e-3
BASE = preset("paper-experiment")
FREE = {"w_n": (0.5 * MM, 3.0 * MM), "w_d": (0.6 * MM, 2.2 * MM), "N": (3, 12)}
STRAIN = 0.03  # low enough that some designs hit it before the target or the budget's top


@pytest.fixture(scope="module")
def angle_search():
    return search_designs(BASE, FREE, tip_angle=0.45, samples=400, allowable_strain=STRAIN)


@pytest.fixture(scope="module")
def deflection_search():
    return search_designs(BASE, {**FREE, "w_t": (1.0 * MM, 6.0 * MM)}, tip_deflection=0.012,
                          samples=400, ladder=3, allowable_strain=STRAIN)


def tip_of(result, kind):
    return result.tip_deflection_m if kind == "tip_deflection" else result.tip_angle_rad


def strain_at(design, tension):
    return float(solve_batch([design], [tension]).max_bending_strain[0])


@pytest.mark.parametrize("name", ["angle_search", "deflection_search"])
def test_every_design_that_meets_reaches_the_target_inside_the_limits(name, request):
    search = request.getfixturevalue(name)
    counts = search.counts()
    assert counts["meets"] > 20 and counts["short"] > 20 and counts["strain"] > 0, counts
    meets = np.flatnonzero(search.outcome == "meets")
    for i in [*search.pareto, *meets[::7]]:
        design, tension = search.design(int(i)), float(search.tension_n[i])
        assert 0.0 < tension <= search.tension_max_n
        result = solve(design, tension)  # raises on closure or singularity
        tip = tip_of(result, search.target_kind)
        assert tip == search.tip_value[i]
        assert abs(tip - search.target) <= search.tol
        assert strain_at(design, tension) == pytest.approx(search.peak_strain[i], rel=1e-12)
        assert search.peak_strain[i] <= search.allowable_strain
        for below in np.linspace(0.0, tension, 4)[1:-1]:  # no limit on the way there
            solve(design, float(below))


@pytest.mark.parametrize("name", ["angle_search", "deflection_search"])
def test_tension_agrees_with_solve_inverse(name, request):
    search = request.getfixturevalue(name)
    meets = np.flatnonzero(search.outcome == "meets")
    for i in meets[:: meets.size // 6]:
        reference = solve_inverse(search.design(int(i)), tension_max=search.tension_max_n,
                                  **{search.target_kind: search.target})
        assert search.tension_n[i] == pytest.approx(reference.tension_n, rel=1e-6)


@pytest.mark.parametrize("name", ["angle_search", "deflection_search"])
def test_pareto_set_is_the_non_dominated_set_of_designs_that_meet(name, request):
    search = request.getfixturevalue(name)
    meets = np.flatnonzero(search.outcome == "meets")
    objectives = np.column_stack([-search.reach, search.peak_strain, search.tension_n])

    def dominates(a, b):
        return np.all(objectives[a] <= objectives[b]) and np.any(objectives[a] < objectives[b])

    front = set(search.pareto.tolist())
    assert front and front <= set(meets.tolist())
    for i in meets:
        dominated = any(dominates(j, i) for j in meets)
        assert dominated == (i not in front)
    assert list(search.tension_n[search.pareto]) == sorted(search.tension_n[search.pareto])


def test_reach_is_the_edge_of_the_limits_or_the_budget(angle_search):
    search = angle_search
    for i in np.flatnonzero(search.outcome == "meets")[::5]:
        design, at = search.design(int(i)), float(search.reach_tension_n[i])
        assert tip_of(solve(design, at), search.target_kind) == search.reach[i]
        assert search.reach[i] >= search.target
        if at < search.tension_max_n:  # a limit just above: strain, closure or singularity
            beyond = at + 1e-6 * search.tension_max_n
            try:
                over = strain_at(design, beyond) > search.allowable_strain
                solve(design, beyond)
            except ModelError:
                over = True
            assert over, (i, at)


def test_outcomes_other_than_meets_are_what_they_say(angle_search):
    search = angle_search
    for i in np.flatnonzero(search.outcome == "short")[::15]:
        top = solve(search.design(int(i)), search.tension_max_n)
        assert top.tip_angle_rad < search.target
    for i in np.flatnonzero(search.outcome == "strain"):
        design = search.design(int(i))
        if np.isfinite(search.tension_n[i]):  # reached, but too strained there
            assert strain_at(design, float(search.tension_n[i])) > search.allowable_strain
        else:  # too strained below the target
            reference = solve_inverse(design, tip_angle=search.target,
                                      tension_max=search.tension_max_n)
            assert strain_at(design, reference.tension_n) > search.allowable_strain


def test_a_limit_below_the_target_is_reported_as_limit():
    # Soft, deep-notched designs close a notch below 20 N: targets past the closure are
    # reported as limits (with the limit's message), those short of it as met.
    search = search_designs(BASE, {"w_d": (0.5 * MM, 0.7 * MM), "N": (3, 4)}, tip_angle=1.0,
                            samples=64, allowable_strain=1.0)
    limits = np.flatnonzero(search.outcome == "limit")
    assert limits.size and search.counts()["meets"]
    assert all("closes" in search.message[i] or "singularity" in search.message[i]
               for i in limits)
    for i in limits[:4]:
        with pytest.raises(ModelError):
            solve_inverse(search.design(int(i)), tip_angle=1.0, tension_max=20.0)


def test_total_length_sets_the_tube_between_notches():
    search = search_designs(BASE, {"L": (0.04, 0.06), "N": (4, 8)}, tip_angle=0.2, samples=64)
    for i in range(0, 64, 9):
        if search.outcome[i] == "invalid":
            assert "w_t" in search.message[i]
            continue
        design = search.design(i)
        assert design.length == pytest.approx(search.values["L"][i], rel=1e-12)
        assert design.N == search.values["N"][i] and design.w_n == BASE.w_n


def test_samples_are_reproducible_and_the_methods_differ():
    kwargs = {"tip_angle": 0.3, "samples": 50}
    one = search_designs(BASE, FREE, seed=3, **kwargs)
    again = search_designs(BASE, FREE, seed=3, **kwargs)
    lhs = search_designs(BASE, FREE, seed=3, sampling="lhs", **kwargs)
    np.testing.assert_array_equal(one.values["w_n"], again.values["w_n"])
    np.testing.assert_array_equal(one.tension_n, again.tension_n)
    assert not np.array_equal(one.values["w_n"], lhs.values["w_n"])
    for search in (one, lhs):
        assert set(np.unique(search.values["N"])) == set(range(3, 13))
        assert np.all((search.values["w_n"] >= 0.5 * MM) & (search.values["w_n"] <= 3.0 * MM))


def test_progress_reports_every_batch(monkeypatch):
    from tdcm_ros.model import inverse_design

    monkeypatch.setattr(inverse_design, "BATCH_DESIGNS", 40)
    calls = []
    search_designs(BASE, FREE, tip_angle=0.3, samples=100,
                   progress=lambda stage, done, total: calls.append((stage, done, total)))
    assert calls == [("design search", n, 100) for n in (0, 40, 80, 100)]


def test_no_design_meeting_the_target_names_the_closest():
    with pytest.raises(NoDesignMeetsTargetError, match="the closest reaches") as caught:
        search_designs(BASE, {"w_n": (1.0 * MM, 2.0 * MM)}, tip_angle=2.0, samples=32)
    search = caught.value.search
    best = int(np.argmax(search.reach))
    assert f"{search.reach[best]:.6g}" in str(caught.value)
    assert caught.value.exit_code == 3
    with pytest.raises(NoDesignMeetsTargetError, match=r"\d+ reach it only past the allowable "
                       "strain 0.0001"):  # strained below the target: no tension found
        search_designs(BASE, {"w_n": (1.0 * MM, 2.0 * MM)}, tip_angle=0.2, samples=32,
                       allowable_strain=1e-4)
    with pytest.raises(NoDesignMeetsTargetError, match=r"the closest reaches it at [\d.]+ N "
                       r"with peak strain [\d.]+ > allowable 0.012"):  # strained at the target
        search_designs(BASE, {"w_n": (1.0 * MM, 2.0 * MM)}, tip_angle=0.2, samples=32,
                       allowable_strain=0.012, ladder=2)


@pytest.mark.parametrize(("free", "kwargs", "error", "names"), [
    ({"w_x": (0, 1)}, {}, InvalidDesignError, "free field = 'w_x'"),
    ({}, {}, InvalidDesignError, "no free field"),
    ({"w_d": (1 * MM, 8 * MM)}, {}, InvalidDesignError, r"w_d max = 0.008.*2 R_outer"),
    ({"w_n": (2 * MM, 1 * MM)}, {}, InvalidDesignError, "w_n range 0.002:0.001 is empty"),
    ({"w_n": (-1.0, 1 * MM)}, {}, InvalidDesignError, "w_n min = -1.0"),
    ({"N": (2.5, 6)}, {}, InvalidDesignError, "N min"),
    ({"L": (0.0, 0.05)}, {}, InvalidDesignError, r"L min = 0.0 .*\(0, 1\] m"),
    ({"L": (0.04, 0.05), "w_t": (1 * MM, 2 * MM)}, {}, InvalidDesignError, "L or w_t|L sets"),
    ({"w_n": (1 * MM, 2 * MM)}, {"samples": 0}, InvalidSettingsError, "samples = 0"),
    ({"w_n": (1 * MM, 2 * MM)}, {"sampling": "grid"}, InvalidSettingsError, "sobol | lhs"),
    ({"w_n": (1 * MM, 2 * MM)}, {"ladder": 0}, InvalidSettingsError, "ladder = 0"),
    ({"w_n": (1 * MM, 2 * MM)}, {"tension_max": -5.0}, InvalidTargetError, "tension_max"),
    ({"w_n": (1 * MM, 2 * MM)}, {"tip_angle": 0.0}, InvalidTargetError, r"tip_angle = 0.0"),
    ({"w_n": (1 * MM, 2 * MM)}, {"tip_angle": None}, InvalidTargetError, "exactly one"),
    ({"w_n": (1 * MM, 2 * MM)}, {"tip_deflection": 0.01}, InvalidTargetError, "exactly one"),
    ({"w_n": (1 * MM, 2 * MM)}, {"allowable_strain": 2.0}, InvalidSettingsError,
     "allowable_strain"),
])
def test_bad_input_names_parameter_value_and_range(free, kwargs, error, names):
    arguments = {"tip_angle": 0.3, "samples": 8, **kwargs}
    with pytest.raises(error, match=names):
        search_designs(BASE, free, **arguments)
