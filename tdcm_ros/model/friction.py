"""Stick-slip capstan friction of the tendon: the scenes' world and the estimator (model node,
evaluation, calibration) share it.

- :class:`FrictionState`: the tendon's tension along ``s`` after the last converged solve (the
  history); it changes only in :meth:`FrictionState.advance`, called with each converged
  result.
- :class:`StickSlipTension`: the tension profile handed to the model
  (:class:`~tdcm_ros.model.loading.TensionProfile`); a pure function of the state it reads, so
  the solver may call it any number of times, on any trial shape.

Where the tendon slips, the tension obeys the capstan law ``|dT/dw| = mu T`` against the
motion: pulled in (loading) it falls toward the tip, ``T_base exp(-mu w)``; paid out
(unloading) it rises, ``T_base exp(mu w)``, with ``w`` the tendon's turning from the base.
Where it sticks, the tension keeps its previous value. Both together: the new profile is the
previous one clipped to ``[T_base exp(-mu w), T_base exp(mu w)]`` (a play operator per point),
which starts from a slack tendon. The state is kept per node just past each kink (the model's
``SolveResult.tendon_tension``), so a stuck kink carries no friction jump: an error of about
``mu`` times the kink's turning.

- :class:`FrictionTrack`: a sequence of tensions solved in the order they happened, each under
  the stick-slip profile of the history so far (the direction of the tension's change decides
  whether the tendon loses or gains tension toward the tip); ``mu = 0`` is the paper's
  frictionless solve.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.design import Design
from tdcm_ros.model.loading import MAX_MU, InvalidLoadingError, Loading
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS, solve

Array = NDArray[np.float64]


class FrictionState:
    """Tension (N) at the node arc lengths ``s`` (m) of the last converged solve; a slack
    tendon before the first."""

    def __init__(self) -> None:
        self._along: tuple[Array, Array] | None = None

    @property
    def tension_along(self) -> tuple[Array, Array] | None:
        """``(s, T)`` of the last converged solve, or ``None`` before the first."""
        return self._along

    def at(self, s: Array) -> Array:
        """The state's tension (N) at arc lengths ``s`` (m), interpolated if the grid differs."""
        if self._along is None:
            return np.zeros_like(s, dtype=float)
        s_prev, t_prev = self._along
        if s_prev.shape == np.shape(s) and np.array_equal(s_prev, s):
            return t_prev
        return np.interp(s, s_prev, t_prev)

    def advance(self, result: SolveResult) -> None:
        """``result`` converged: its tendon tension becomes the state (a result solved
        without a tension profile has none and leaves the state as it is)."""
        if result.tendon_tension is not None:
            self._along = (np.array(result.s, dtype=float),
                           np.array(result.tendon_tension, dtype=float))


@dataclass(frozen=True, eq=False)
class StickSlipTension:
    """The tension profile of friction coefficient ``mu`` over ``state``: the state's tension
    clipped to ``[T_base exp(-mu w), T_base exp(mu w)]``; reads the state, never changes it."""

    mu: float
    state: FrictionState = field(repr=False)

    def __call__(self, s: Array, wrap_angle: Array, tension_base: float) -> Array:
        """Tension at each node (N) for base tension ``tension_base`` (N)."""
        low = tension_base * np.exp(-self.mu * wrap_angle)
        high = tension_base * np.exp(self.mu * wrap_angle)
        return np.clip(self.state.at(s), low, high)


def check_mu(mu: float, name: str = "friction.mu") -> float:
    """``mu`` as a float in ``[0, MAX_MU]``; raises :class:`InvalidLoadingError` naming ``name``."""
    value = float(mu)
    if not np.isfinite(value) or not 0.0 <= value <= MAX_MU:
        raise out_of_range(name, mu, f"[0, {MAX_MU:g}]", error=InvalidLoadingError)
    return value


class FrictionTrack:
    """Solves tensions in the order they happened under stick-slip friction ``mu`` (a fresh
    track starts from a slack tendon); ``mu = 0`` solves each one as the paper does."""

    def __init__(self, mu: float) -> None:
        self.mu = check_mu(mu)
        self.state = FrictionState()

    def profile(self, mu: float | None = None) -> Loading | None:
        """The loading of the next solve: the stick-slip profile of ``mu`` (default the
        track's) over the history, or None without friction."""
        value = self.mu if mu is None else mu
        return Loading(tension_profile=StickSlipTension(value, self.state)) if value else None

    def solve(self, design: Design, tension: float | Sequence[float], *,
              settings: SolverSettings = DEFAULT_SETTINGS,
              warm_start: SolveResult | None = None) -> SolveResult:
        """The shape at ``tension`` (N) after the history; the result becomes the history."""
        result = self.solve_at(design, tension, settings=settings, warm_start=warm_start)
        self.state.advance(result)
        return result

    def solve_at(self, design: Design, tension: float | Sequence[float], *,
                 mu: float | None = None, settings: SolverSettings = DEFAULT_SETTINGS,
                 warm_start: SolveResult | None = None) -> SolveResult:
        """The shape at ``tension`` (N) after the history under friction ``mu`` (default the
        track's), leaving the history as it is (e.g. for a sensitivity)."""
        return solve(design, tension, settings=settings, warm_start=warm_start,
                     loading=self.profile(mu))
