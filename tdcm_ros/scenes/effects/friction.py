"""Stick-slip capstan friction of the tendon, as two separate objects:

- :class:`FrictionState`: the tendon's tension along ``s`` after the world's last converged
  solve (the history); it changes only in :meth:`FrictionState.advance`, which the world calls
  with each converged result.
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
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model import SolveResult

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
