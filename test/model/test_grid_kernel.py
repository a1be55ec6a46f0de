"""The grid kernel: its scalar eq. 12 against quadrature, and its builds agreeing."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import fields

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from tdcm_ros.model import CustomProfile, SolverSettings, compiled, grid_kernel, preset
from tdcm_ros.model.design import MM
from tdcm_ros.model.grid import grid_parts
from tdcm_ros.model.grid_layout import cell_table
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


@contextmanager
def build(compiled_build: bool) -> Iterator[None]:
    """Inside, the compiled or the plain build of every kernel; the choice ends with it."""
    saved = dict(compiled._state)
    compiled.use_compiled(compiled_build)
    try:
        yield
    finally:
        compiled._state.update(saved)


@st.composite
def design_sets(draw: st.DrawFn) -> list:
    """One to four designs: uniform or notch by notch (own widths, profile, backbone offset),
    with or without a base, tip and tubes between notches."""
    base = preset("paper-experiment")
    out = []
    for _ in range(draw(st.integers(1, 4))):
        n = draw(st.integers(1, 6))
        per_notch = draw(st.booleans())

        def values(low: float, high: float, n: int = n, per_notch: bool = per_notch):
            one = st.floats(low, high)
            return [draw(one) * MM for _ in range(n)] if per_notch else draw(one) * MM

        profile = st.sampled_from(["circular", "rectangular"])
        out.append(base.with_overrides(
            N=n, w_n=values(0.4, 3.0), w_d=values(0.6, 2.4),
            w_o=values(0.0, 0.5) if draw(st.booleans()) else 0.0,
            profile=[draw(profile) for _ in range(n)] if per_notch else draw(profile),
            w_t=draw(st.sampled_from([0.0, 2.0])) * MM,
            w_tip=draw(st.sampled_from([0.0, 4.0])) * MM,
            w_base=draw(st.sampled_from([0.0, 5.0])) * MM))
    return out


@settings(max_examples=40, deadline=None)
@given(designs=design_sets(), routing=st.sampled_from(["paper", "free"]),
       grid=st.sampled_from(["adaptive", "uniform"]))
def test_compiled_layout_and_gathers_equal_the_plain_build_bit_for_bit(designs, routing, grid):
    """The cell layout (``grid_kernel.lay_cells``), the members' index tables
    (``grid_kernel.member_cells``) and the kernel arrays laid out from the prototype cells
    (``kernel.gather``) of the compiled build are the plain build's, bit for bit."""
    pytest.importorskip("numba")
    parts = grid_parts(designs, SolverSettings(routing=routing, grid=grid))
    rows = np.arange(len(designs))[::-1].copy()
    found = []
    for flag in (False, True):
        with build(flag):
            assert compiled.is_compiled() == flag
            table = cell_table(parts.table.prototypes, routing)
            cells = parts.stack(rows).cells
            found.append([getattr(table, f.name) for f in fields(table)
                          if f.name != "prototypes"] + list(parts.kernel_indices(rows)) +
                         [cells.fc, cells.fq, cells.ic, cells.notch, cells.scal])
    table_fields = [getattr(parts.table, f.name) for f in fields(parts.table)
                    if f.name != "prototypes"]
    plain, fast = found
    assert len(plain) == len(fast) == len(table_fields) + 11
    for a, b, c in zip(plain, fast, table_fields + fast[len(table_fields):], strict=True):
        assert a.dtype == b.dtype and a.shape == b.shape
        assert a.tobytes() == b.tobytes() == c.tobytes()
