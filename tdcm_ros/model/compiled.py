"""Which build of :mod:`tdcm_ros.model.kernel` runs: as plain Python, or compiled by numba.

The kernels are one source. Compiling them needs numba (about 0.3 s and 90 MB just to import),
so it happens lazily, on the first kernel call of a process that uses the compiled build, and
the machine code (which releases the GIL, so threads can run it at once) is cached on disk (``cache=True``: next to the package when it is writable,
else numba's user-wide cache or ``NUMBA_CACHE_DIR``; without any writable place the kernels
are compiled uncached, never refused).

The switch: environment variable ``TDCM_JIT`` (read once, at the first kernel call) or
:func:`.use_compiled`. ``TDCM_JIT=0`` runs the plain-Python build (no numba import: right for
a one-shot command that solves once); ``1`` requires numba; unset (default) compiles when
numba is importable and otherwise runs the plain build.
"""

from __future__ import annotations

import os
import types
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from tdcm_ros.errors import out_of_range
from tdcm_ros.model import grid_kernel, kernel
from tdcm_ros.model.errors import InvalidSettingsError
from tdcm_ros.model.quiet import quiet_fp

ENVIRONMENT = "TDCM_JIT"
PLAIN = types.SimpleNamespace(**{name: quiet_fp(getattr(kernel, name))
                                 for name in kernel.KERNELS})
"""The plain-Python build: NumPy scalar arithmetic in it would warn where the compiled
build is silent, so each entry point runs under :func:`~tdcm_ros.model.quiet.quiet_fp`."""
GRID_PLAIN = types.SimpleNamespace(**{name: quiet_fp(getattr(grid_kernel, name))
                                      for name in grid_kernel.KERNELS})
"""The plain-Python build of :mod:`grid_kernel`, guarded the same way."""
_CHOICES = {"0": False, "1": True, "": None}
_state: dict[str, Any] = {"wanted": None, "chosen": False, "build": None, "grid_build": None}


def use_compiled(flag: bool | None) -> None:
    """Select the build for the rest of the process: True compiled (needs numba), False plain
    Python, None the default (compiled if numba is importable). Overrides ``TDCM_JIT``."""
    _state["wanted"] = flag
    _state["build"] = None
    _state["chosen"] = True


@contextmanager
def one_shot() -> Iterator[None]:
    """Inside, for a command that solves once: the plain build, unless ``TDCM_JIT`` or
    :func:`.use_compiled` chose or a build is already loaded (compiling would cost ~1 s of
    numba import and cache loading, far more than it saves). The choice ends with the block."""
    if _state["chosen"] or _state["build"] is not None or \
            os.environ.get(ENVIRONMENT, "").strip():
        yield
        return
    _state["build"] = PLAIN
    try:
        yield
    finally:
        _state["build"] = None


def kernels() -> types.SimpleNamespace:
    """The kernel functions of the selected build (attributes named as in :mod:`kernel`)."""
    build = _state["build"]
    if build is None:
        build = _state["build"] = _select()
    return build


def grid_kernels() -> types.SimpleNamespace:
    """The functions of :mod:`grid_kernel` in the build :func:`kernels` selected."""
    if kernels() is PLAIN:
        return GRID_PLAIN
    build = _state["grid_build"]
    if build is None:
        import numba

        build = _state["grid_build"] = _compile(numba, grid_kernel)
    return build


def is_compiled() -> bool:
    """Whether the selected build is numba's."""
    return kernels() is not PLAIN


def _select() -> types.SimpleNamespace:
    wanted = _state["wanted"]
    if not _state.get("chosen"):
        value = os.environ.get(ENVIRONMENT, "").strip()
        if value not in _CHOICES:
            raise out_of_range(ENVIRONMENT, value, "0 (plain Python) | 1 (numba) | unset",
                               error=InvalidSettingsError)
        wanted = _CHOICES[value]
    if wanted is False:
        return PLAIN
    try:
        import numba
    except ImportError as missing:
        if wanted:
            raise InvalidSettingsError(
                f"{ENVIRONMENT}=1 needs numba, which is not installed: pip install "
                "'tdcm_ros[fast]' (or python3-numba on a ROS machine)", parameter=ENVIRONMENT,
                value="1", allowed="numba installed, or 0 (plain Python)") from missing
        return PLAIN
    return _compile(numba)


def _compile(numba: Any, module: types.ModuleType = kernel) -> types.SimpleNamespace:
    """Each kernel function of ``module`` (its ``KERNELS``) jitted, its calls to the others
    resolved to their jitted versions (the plain functions keep theirs)."""
    namespace = dict(vars(module))
    compiled = {}
    for name in module.KERNELS:
        plain = getattr(module, name)
        clone = types.FunctionType(plain.__code__, namespace, name, plain.__defaults__,
                                   plain.__closure__)
        clone.__qualname__ = plain.__qualname__
        clone.__module__ = plain.__module__
        clone.__doc__ = plain.__doc__
        # error_model="numpy": a float divided by zero is inf or nan, as in the plain build
        # (NumPy scalars), which the solver then reports as a non-finite iterate; numba's
        # default would raise ZeroDivisionError out of a hostile design's grid build.
        try:
            jitted = numba.njit(cache=True, nogil=True, error_model="numpy")(clone)
        except RuntimeError:  # no writable cache location: compile every process instead
            jitted = numba.njit(cache=False, nogil=True, error_model="numpy")(clone)
        namespace[name] = compiled[name] = jitted
    return types.SimpleNamespace(**compiled)
