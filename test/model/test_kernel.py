"""One kernel source: its plain and compiled builds agree, members are independent, padding
cells are neutral, and the compiled code caches (or not) wherever the package lives."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.model import SolverSettings, compiled, kernel, preset, solve
from tdcm_ros.model.cells import FC_FIELDS, FQ_FIELDS
from tdcm_ros.model.grid import build_grid
from tdcm_ros.model.kinematics import integrate
from tdcm_ros.model.limits import notch_gaps
from tdcm_ros.model.loads import closed_form
from test.support.cells import stack_cells

REPO = Path(__file__).resolve().parents[2]


def tips(designs, tensions, routing):
    """Tip positions (m) of single solves."""
    cfg = SolverSettings(routing=routing)
    return np.array([solve(d, t, settings=cfg).tip_position for d, t in zip(designs, tensions)])


@pytest.mark.parametrize("routing", ["paper", "free"])
def test_plain_and_compiled_builds_agree(routing, monkeypatch):
    designs = [preset("paper-experiment"), preset("fig3-wd-1.2").with_overrides(N=3)]
    fast = tips(designs, [20.0, 7.0], routing)
    monkeypatch.setitem(compiled._state, "build", compiled.PLAIN)
    slow = tips(designs, [20.0, 7.0], routing)
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-15)


@settings(max_examples=15)
@given(n_a=st.integers(1, 6), n_b=st.integers(1, 6), scale=st.floats(0.0, 40.0),
       routing=st.sampled_from(["paper", "free"]))
def test_padded_stack_gives_each_member_its_own_answers(n_a, n_b, scale, routing):
    """Grids of different cell and notch counts stack with zero-length padding cells that
    move no node: each member's shape, moments and gaps equal its own grid's."""
    cfg = SolverSettings(routing=routing)
    base = preset("paper-experiment")
    grids = [build_grid(base.with_overrides(N=n_a), cfg), build_grid(base.with_overrides(N=n_b), cfg)]
    cells = stack_cells([g.cells for g in grids])
    rng = np.random.default_rng(n_a * 7 + n_b)
    moments = [rng.uniform(0.0, 1e-3 * scale, g.n_cells) for g in grids]
    padded = np.zeros((2, cells.n_cells))
    for j, m in enumerate(moments):
        padded[j, :m.size] = m
    shape = integrate(cells, padded, padded)
    m_a, _ = closed_form(cells, shape, np.array([scale, scale]))
    for j, (grid, m) in enumerate(zip(grids, moments)):
        alone = integrate(grid, m, m)
        n = grid.n_cells
        np.testing.assert_array_equal(shape.p[j, :n + 1], alone.p)
        np.testing.assert_array_equal(shape.p[j, n:], alone.p[-1])  # padding moves nothing
        np.testing.assert_array_equal(m_a[j, :n], closed_form(grid, alone, scale)[0])
        gaps = np.empty((1, cells.notch.shape[2]))
        kernel.gaps(cells.scal[j:j + 1], shape.p[j:j + 1], shape.tangent[j:j + 1],
                    cells.notch[j:j + 1], gaps)
        np.testing.assert_array_equal(gaps[0, :grid.notch_left_node.size],
                                      notch_gaps(grid, alone))
        assert np.all(gaps[0, grid.notch_left_node.size:] == np.inf)


def test_plain_build_iterates_like_the_compiled_one(monkeypatch):
    cfg = SolverSettings(routing="free")
    fast = solve(preset("paper-experiment"), 20.0, settings=cfg)
    monkeypatch.setitem(compiled._state, "build", compiled.PLAIN)
    slow = solve(preset("paper-experiment"), 20.0, settings=cfg)
    assert not compiled.is_compiled()
    assert slow.converged and slow.iterations == fast.iterations > 1
    assert slow.residual_history == pytest.approx(fast.residual_history, rel=1e-6, abs=1e-15)


def test_asking_for_numba_without_it_is_a_typed_error_naming_the_extra(monkeypatch):
    monkeypatch.setitem(compiled._state, "build", None)
    monkeypatch.setitem(compiled._state, "chosen", False)
    monkeypatch.setenv(compiled.ENVIRONMENT, "1")
    monkeypatch.setitem(sys.modules, "numba", None)  # import numba now raises ImportError
    with pytest.raises(compiled.InvalidSettingsError, match=r"tdcm_ros\[fast\]") as caught:
        compiled.kernels()
    assert caught.value.parameter == "TDCM_JIT"
    monkeypatch.setenv(compiled.ENVIRONMENT, "")  # unset: the plain build, no error
    assert compiled.kernels() is compiled.PLAIN


def test_bad_switch_value_is_a_typed_error(monkeypatch):
    monkeypatch.setitem(compiled._state, "build", None)
    monkeypatch.setitem(compiled._state, "chosen", False)
    monkeypatch.setenv(compiled.ENVIRONMENT, "yes")
    with pytest.raises(compiled.InvalidSettingsError, match="TDCM_JIT"):
        compiled.kernels()


SCRIPT = ("import sys; from tdcm_ros.model import preset, solve, compiled; "
          "r = solve(preset('paper-experiment'), 20.0); "
          "print(compiled.is_compiled(), 'numba' in sys.modules, r.converged)")


def run_copy(tmp_path, env_extra, readonly=True):
    """Run SCRIPT against a copy of the package (read-only if asked); its stdout."""
    root = tmp_path / "pkg"
    shutil.copytree(REPO / "tdcm_ros", root / "tdcm_ros",
                    ignore=shutil.ignore_patterns("__pycache__"))
    if readonly:
        for path in [root, *root.rglob("*")]:
            path.chmod(0o555 if path.is_dir() else 0o444)
    env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1", **env_extra}
    try:
        out = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True,
                             text=True, timeout=300, check=True)
    finally:
        for path in [root, *root.rglob("*")]:
            path.chmod(0o755 if path.is_dir() else 0o644)
    return out.stdout.split()


def test_compiled_code_caches_in_numba_cache_dir_when_the_package_is_read_only(tmp_path):
    cache = tmp_path / "cache"
    home = tmp_path / "home"
    home.mkdir()
    env = {"NUMBA_CACHE_DIR": str(cache), "HOME": str(home), "TDCM_JIT": "1"}
    assert run_copy(tmp_path, env) == ["True", "True", "True"]
    assert any(cache.rglob("*.nbi")), "no cache index written"
    shutil.rmtree(tmp_path / "pkg")
    assert run_copy(tmp_path, env) == ["True", "True", "True"]  # loads from that cache


def test_compiles_uncached_when_no_cache_location_is_writable():
    """numba refuses ``cache=True`` (RuntimeError) when no cache directory is writable; the
    kernels are then compiled without a cache instead of failing."""
    calls = []

    class FakeNumba:
        @staticmethod
        def njit(cache, nogil, error_model):
            calls.append(cache)
            if cache:
                raise RuntimeError("cannot cache function: no locator available")
            return lambda function: function

    build = compiled._compile(FakeNumba)
    assert calls == [True, False] * len(kernel.KERNELS)
    assert build.iterate.__code__ is kernel.iterate.__code__
    assert build.iterate.__globals__["integrate_row"] is build.integrate_row


def test_switch_off_never_imports_numba(tmp_path):
    assert run_copy(tmp_path, {"TDCM_JIT": "0"}, readonly=False) == ["False", "False", "True"]


@settings(max_examples=300)
@given(phi=st.one_of(st.floats(-0.04, 0.04), st.floats(-0.3, 0.3), st.floats(-40.0, 40.0)))
def test_unit_is_exp_i_phi_within_one_ulp(phi):
    """The Taylor branches of kernel.unit agree with libm's cos and sin to 1 ulp."""
    value = kernel.unit(phi)
    assert abs(value.real - np.cos(phi)) <= np.spacing(abs(np.cos(phi)))
    assert abs(value.imag - np.sin(phi)) <= max(np.spacing(abs(np.sin(phi))), 0.0)


@pytest.mark.parametrize("routing", ["paper", "free"])
def test_cells_of_a_built_stack_equal_the_stacked_grids(routing):
    """grid.build_grids' stack (tip-node padding notches) runs the kernels like per-design
    grids stacked here: same shapes, moments, gaps and constrained peak compliance."""
    from tdcm_ros.model.grid import build_grids

    cfg = SolverSettings(routing=routing)
    base = preset("paper-experiment")
    designs = [base.with_overrides(N=n, w_n=w) for n, w in ((2, 1e-3), (5, 2e-3), (8, 1.5e-3))]
    built = build_grids(designs, cfg).cells
    mine = stack_cells([build_grid(d, cfg).cells for d in designs])
    np.testing.assert_array_equal(built.constrained_peak_c, mine.constrained_peak_c)
    rows = np.arange(3)
    for cells in (built, mine):
        assert cells.members == 3
    results = []
    for cells in (built, mine):
        n = cells.n_cells
        x = np.ascontiguousarray(np.broadcast_to((cells.r_c * 15.0)[:, None], (3, 2 * n)))
        p = np.empty((3, n + 1), complex)
        theta = np.empty((3, n + 1))
        tangent = np.empty((3, n + 1), complex)
        info = np.empty((3, 3 + 200))
        compiled.kernels().iterate(cells.fc, cells.fq, cells.ic, cells.notch, cells.scal, rows,
                                   np.full(3, 15.0), x, p, theta, tangent, 1e-10, 1.0, 0.3,
                                   1e3, info)
        results.append((p[:, -1], info[:, :3]))
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])
    assert np.all(results[0][1][:, 2] > 0.0)  # padding notches never read as closed


def test_one_shot_picks_the_plain_build_only_inside_and_only_if_unchosen(monkeypatch):
    for key in ("wanted", "chosen"):
        monkeypatch.setitem(compiled._state, key, compiled._state[key])
    monkeypatch.setitem(compiled._state, "build", None)
    monkeypatch.setitem(compiled._state, "chosen", False)
    monkeypatch.delenv(compiled.ENVIRONMENT, raising=False)
    with compiled.one_shot():
        assert compiled.kernels() is compiled.PLAIN
    assert compiled._state["build"] is None  # the process is not switched for good
    monkeypatch.setenv(compiled.ENVIRONMENT, "1")
    with compiled.one_shot():
        assert compiled.is_compiled()  # an explicit TDCM_JIT wins
    with compiled.one_shot():
        assert compiled.is_compiled()  # a loaded build is kept


def iterate_both_ways(code, parts, rows, tension, budget):
    """``iterate_prototypes`` reading ``parts``' prototype tables by index, and ``iterate`` on
    the same members' gathered cells (:meth:`GridParts.stack`) followed by ``peak_strains``
    on their gathered strain coefficients: (x, p, theta, tangent, info, strain) of each."""
    indices = parts.kernel_indices(np.arange(parts.members.N.size))
    cells = parts.stack(np.arange(parts.members.N.size)).cells
    n = cells.n_cells
    out = []
    for way in ("indexed", "gathered"):
        m = rows.size
        x = np.ascontiguousarray(np.broadcast_to((cells.r_c[rows] * tension)[:, None],
                                                 (m, 2 * n)))
        shape = [np.empty((m, n + 1), complex), np.empty((m, n + 1)),
                 np.empty((m, n + 1), complex)]
        info = np.zeros((m, 3 + budget))
        strain = np.full(m, np.nan)
        if way == "indexed":
            code.iterate_prototypes(parts.proto_fc[..., None], parts.proto_fq,
                                    parts.proto_strain, FC_FIELDS, FQ_FIELDS,
                                    indices.cell_proto, indices.ic, indices.notch, indices.scal,
                                    indices.notch_cells, indices.notch_proto, rows, tension, x,
                                    *shape, 1e-10, 1.0, 0.3, 1e3, info, strain)
        else:
            code.iterate(cells.fc, cells.fq, cells.ic, cells.notch, cells.scal, rows, tension,
                         x, *shape, 1e-10, 1.0, 0.3, 1e3, info)
            coefficients = np.empty((cells.members, 2, indices.notch_proto.shape[1],
                                     parts.proto_strain.shape[2]))
            code.gather(indices.notch_proto, np.arange(2), parts.proto_strain, coefficients)
            done = np.flatnonzero(info[:, 1] == kernel.CONVERGED)
            found = np.empty(done.size)
            code.peak_strains(rows[done], indices.notch_cells, coefficients[:, 0],
                              coefficients[:, 1], x[done], found)
            strain[done] = found
        out.append((x, *shape, info, strain))
    return out


@pytest.mark.parametrize("build", ["plain", "compiled"])
@pytest.mark.parametrize("routing", ["paper", "free"])
def test_iterate_prototypes_is_iterate_on_the_gathered_cells_bit_for_bit(build, routing):
    """The batch's iteration reads each design's cells from the prototype tables through its
    index tables (padding included: three cell counts, one off-axis design) and lays them out
    per design as its members come, in any order: the same bits as the iteration on a stack
    of gathered cells, and the peak strain of converged members only."""
    from tdcm_ros.model.grid import grid_parts

    code = kernel if build == "plain" else compiled.kernels()
    base = preset("paper-experiment")
    designs = [base.with_overrides(N=n, w_n=w, w_o=o)
               for n, w, o in ((2, 1e-3, 0.0), (5, 2e-3, 0.0), (8, 1.5e-3, 0.0), (3, 1e-3, 3e-4))]
    parts = grid_parts(designs, SolverSettings(routing=routing))
    rows = np.array([0, 1, 2, 2, 3, 1, 0], np.int64)
    tension = np.array([15.0, 3.0, 9.0, 20.0, 12.0, 7.0, 1.0])
    for budget, converges in ((200, True), (0, False)):
        indexed, gathered = iterate_both_ways(code, parts, rows, tension, budget)
        for mine, theirs in zip(indexed, gathered, strict=True):
            assert mine.tobytes() == theirs.tobytes()
        assert np.all((indexed[4][:, 1] == kernel.CONVERGED) == converges)
        assert np.all(indexed[5] > 0.0) if converges else np.all(np.isnan(indexed[5]))
