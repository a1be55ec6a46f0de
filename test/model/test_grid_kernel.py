"""The grid kernel: its scalar eq. 12 against quadrature, and its builds agreeing."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from tdcm_ros.model import CustomProfile, SolverSettings, compiled, grid_kernel, preset
from tdcm_ros.model.design import MM
from tdcm_ros.model.grid import grid_parts
from tdcm_ros.model.section import notched_moment

E = 1.7e9
EPS = float(np.finfo(float).eps)


@settings(max_examples=300)
@given(r_outer=st.floats(0.5, 5.0), inner_ratio=st.floats(0.0, 0.95),
       h_ratio=st.one_of(st.floats(0.0, 1.2), st.floats(0.0, 0.06)))
def test_the_kernels_eq_12_matches_quadrature_on_both_sides_of_its_series(
        r_outer: float, inner_ratio: float, h_ratio: float) -> None:
    """The strip moment J (closed form above h/R = 0.05, series below, where the closed form
    cancels) against adaptive quadrature; the compliance the cells use is eq. 12's."""
    r_outer *= MM
    r_inner = inner_ratio * r_outer
    h1 = h_ratio * r_outer
    for h, radius in ((h1, r_outer), (min(h1, r_inner), r_inner)):
        expected = quad(lambda y, radius=radius: y * y * math.sqrt(max(radius**2 - y * y, 0.0)),
                        0.0, min(h, radius), epsabs=0.0, epsrel=1e-13, limit=200)[0]
        assert grid_kernel.disc_strip_moment(h, radius) == pytest.approx(
            expected, rel=1e-11, abs=1e-13 * radius**4 + 1e-300)  # 1e-300: denormals
    h1 = max(h1, 1e-3 * r_outer)  # I > 0: a finite compliance
    got = 1.0 / (E * grid_kernel.notch_compliance(h1, r_outer, r_inner, E))
    assert got == pytest.approx(float(notched_moment(h1, r_outer, r_inner)), rel=4 * EPS)


def designs() -> list:
    base = preset("paper-experiment")
    return [base, base.with_overrides(N=3, w_n=2.5 * MM, w_d=1.0 * MM),
            base.with_overrides(N=1, profile="rectangular", w_base=0.0),
            base.with_overrides(N=4, profile=CustomProfile(lambda s: 0.6 * MM + 0.2 * s))]


def parts_arrays(parts):
    return (parts.proto_fc, parts.proto_fq, parts.proto_strain)


@pytest.mark.parametrize("partials", ["nested", "interpolated"])
@pytest.mark.parametrize("routing", ["paper", "free"])
def test_plain_and_compiled_builds_agree_to_1e_15(routing, partials, monkeypatch):
    cfg = SolverSettings(routing=routing)
    for key in ("wanted", "chosen", "build"):
        monkeypatch.setitem(compiled._state, key, compiled._state[key])
    compiled.use_compiled(False)
    assert compiled.grid_kernels() is compiled.GRID_PLAIN
    plain = parts_arrays(grid_parts(designs(), cfg, partials=partials))
    compiled.use_compiled(True)
    assert compiled.grid_kernels() is not compiled.GRID_PLAIN
    fast = parts_arrays(grid_parts(designs(), cfg, partials=partials))
    for a, b in zip(plain, fast, strict=True):
        scale = np.max(np.abs(a), axis=0, keepdims=True)
        assert np.all(np.abs(a - b) <= 1e-15 * scale)


def test_threads_give_the_same_bits():
    many = [preset("paper-experiment").with_overrides(w_n=w * MM)
            for w in np.linspace(1.0, 2.5, 9)] + designs()
    for partials in ("nested", "interpolated"):
        one = parts_arrays(grid_parts(many, SolverSettings(), partials=partials))
        two = parts_arrays(grid_parts(many, SolverSettings(), workers=3, partials=partials))
        for a, b in zip(one, two, strict=True):
            assert a.tobytes() == b.tobytes()


def test_plain_build_never_imports_numba():
    code = ("import sys, numpy as np\n"
            "from tdcm_ros.model import preset, solve\n"
            "from tdcm_ros.model.batch import solve_batch\n"
            "d = preset('paper-experiment')\n"
            "solve(d, 10.0); solve_batch([d, d.with_overrides(N=3)], np.array([5.0, 9.0]))\n"
            "print('numba' in sys.modules)\n")
    env = {**os.environ, "TDCM_JIT": "0"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True)
    assert out.stdout.split()[-1] == "False"
