"""NumPy's floating-point warnings off around the model's NumPy paths.

Hostile inputs overflow by design (a huge tension, a diverging iterate); the model checks
finiteness itself and raises typed errors, so NumPy's overflow, invalid-value and
divide-by-zero warnings would only be noise. The compiled kernels raise no such warnings, so
the fast path of a solve runs without the guard (it costs ~0.8 us per entry).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ParamSpec, TypeVar

import numpy as np

P = ParamSpec("P")
R = TypeVar("R")


def quiet_fp(func: Callable[P, R]) -> Callable[P, R]:
    """``func`` run with NumPy's overflow, invalid and divide warnings off (a fresh
    ``np.errstate`` per call, so nested and re-entrant calls are safe)."""

    @functools.wraps(func)
    def quiet(*args: P.args, **kwargs: P.kwargs) -> R:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            return func(*args, **kwargs)

    return quiet
