"""Property tests of :func:`tdcm_ros.model.solve` over the whole design space, hostile corners
included (issue 13): every call returns a finite result or raises one of the model's typed
errors, nothing else, prints nothing, and is bounded in time."""

import time
import warnings

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tdcm_ros.model import (
    FIELD_SPECS,
    Design,
    Loading,
    ModelError,
    NotchContact,
    SolverSettings,
    solve,
)
from tdcm_ros.model.design import MIN_SEGMENT_M
from tdcm_ros.model.profiles import profile_from_name

WALL_S = 10.0  # per solve; the slowest seen at N = 1000 is ~1 s


def lengths(*, optional: bool) -> st.SearchStrategy[float]:
    """A segment length (m): its floor, its ceiling or anything between; 0 where optional."""
    high = FIELD_SPECS["w_n"].high
    choices = [st.just(MIN_SEGMENT_M), st.just(high), st.floats(MIN_SEGMENT_M, high)]
    return st.one_of(st.just(0.0), *choices) if optional else st.one_of(*choices)


FRACTIONS = st.one_of(st.just(1e-12), st.just(1.0 - 1e-12),
                      st.floats(1e-12, 1.0, exclude_max=True))


@st.composite
def designs(draw: st.DrawFn) -> Design:
    """Designs valid on construction, spanning each field's range and the cross-field ones."""
    r_outer = draw(st.one_of(st.just(FIELD_SPECS["R_outer"].high), st.just(1e-9),
                             st.floats(1e-9, FIELD_SPECS["R_outer"].high)))
    return Design(
        w_base=draw(lengths(optional=True)), w_tip=draw(lengths(optional=True)),
        w_n=draw(lengths(optional=False)), w_t=draw(lengths(optional=True)),
        w_d=draw(FRACTIONS) * 2.0 * r_outer,
        N=draw(st.one_of(st.just(int(FIELD_SPECS["N"].high)), st.integers(1, 60))),
        R_outer=r_outer, r_inner=draw(st.one_of(st.just(0.0), FRACTIONS)) * r_outer,
        R_c=draw(FRACTIONS) * r_outer,
        E=draw(st.one_of(st.just(FIELD_SPECS["E"].high), st.just(1e-300),
                         st.floats(1e-300, FIELD_SPECS["E"].high))),
        profile=profile_from_name(draw(st.sampled_from(["circular", "rectangular"]))))


@settings(max_examples=100, database=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(design=designs(),
       tension=st.one_of(st.just(0.0), st.just(20.0), st.floats(0.0, 1e300)),
       loads=st.sampled_from(["closed", "literal"]), routing=st.sampled_from(["paper", "free"]),
       strict=st.booleans(), loaded=st.booleans())
def test_every_solve_is_finite_or_a_typed_error(design, tension, loads, routing, strict, loaded):
    config = SolverSettings(loads=loads, routing=routing, max_iter=60)
    loading = (Loading(tip_force=(0.1, 0.0), notch_contact=NotchContact())
               if loaded and loads == "closed" else None)
    started = time.monotonic()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a NumPy RuntimeWarning is noise: fail on it
        try:
            result = solve(design, tension, settings=config, strict=strict, loading=loading)
        except ModelError as error:
            assert str(error)
        else:
            assert result.converged or not strict
            for values in (result.positions, result.theta, result.cell_moments,
                           result.quaternions):
                assert np.all(np.isfinite(values))
    assert time.monotonic() - started < WALL_S
