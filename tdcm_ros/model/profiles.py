"""Notch profiles: the backbone half-width ``h1`` across one notch (eq. 13 and alternatives).

A profile maps a reference coordinate ``u`` in [0, 1] across the notch to the local arc
length ``sigma = s - l_i`` in [0, w_n] (m) and gives ``h1`` there (m). The map is chosen so
that ``h1`` is smooth in ``u``: the circular notch uses the paper's own angle ``t``, in which
the profile is a sine, instead of ``s``, in which it has an infinite slope at the edges.
Quadrature and cell boundaries are placed uniformly in ``u``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
#: A width (m): one number, or one per row of ``u`` (broadcasting against it).
Width = float | Array


@dataclass(frozen=True)
class CircularProfile:
    """Eq. 13: a slot of width ``w_n`` with a semicircular bottom reaching ``w_d/2`` at its centre.

    With ``t = pi (1 + u)``, ``sigma = (w_n/2)(1 + cos t)`` and
    ``h1 = (w_n + w_d)/2 + (w_n/2) sin t``.
    """

    name: str = "circular"

    def sigma(self, u: Array, w_n: Width) -> Array:
        """Local arc length (m) at reference coordinate ``u``."""
        return 0.5 * w_n * (1.0 - np.cos(np.pi * u))

    def dsigma_du(self, u: Array, w_n: Width) -> Array:
        """Jacobian d(sigma)/du (m)."""
        return 0.5 * w_n * np.pi * np.sin(np.pi * u)

    def h1(self, u: Array, w_n: Width, w_d: Width) -> Array:
        """Backbone half-width (m) at ``u``."""
        return 0.5 * (w_n + w_d) - 0.5 * w_n * np.sin(np.pi * u)


@dataclass(frozen=True)
class RectangularProfile:
    """A straight-bottomed slot: ``h1 = w_d/2`` across the whole notch."""

    name: str = "rectangular"

    def sigma(self, u: Array, w_n: Width) -> Array:
        """Local arc length (m) at reference coordinate ``u``."""
        return w_n * u

    def dsigma_du(self, u: Array, w_n: Width) -> Array:
        """Jacobian d(sigma)/du (m)."""
        return np.full_like(u, w_n)

    def h1(self, u: Array, w_n: Width, w_d: Width) -> Array:
        """Backbone half-width (m) at ``u``."""
        return np.full_like(u, 0.5 * w_d)


@dataclass(frozen=True)
class CustomProfile:
    """A user-supplied profile ``h1(sigma)``: half-width (m) at local arc length ``sigma`` (m).

    ``h1`` must accept a NumPy array of ``sigma`` in [0, w_n] and return positive, finite
    half-widths of the same shape. Quadrature is uniform in ``sigma``; a profile with infinite
    slopes converges more slowly than the built-in circular one.
    """

    half_width: Callable[[Array], Array] = field(compare=True)
    name: str = "custom"

    def sigma(self, u: Array, w_n: Width) -> Array:
        """Local arc length (m) at reference coordinate ``u``."""
        return w_n * u

    def dsigma_du(self, u: Array, w_n: Width) -> Array:
        """Jacobian d(sigma)/du (m)."""
        return np.full_like(u, w_n)

    def h1(self, u: Array, w_n: Width, w_d: Width) -> Array:
        """Backbone half-width (m) at ``u`` from the user's function."""
        return np.asarray(self.half_width(w_n * u), dtype=float) * np.ones_like(u)


NotchProfile = CircularProfile | RectangularProfile | CustomProfile

PROFILE_NAMES: tuple[str, ...] = ("circular", "rectangular")


def profile_from_name(name: str) -> CircularProfile | RectangularProfile:
    """Return a built-in profile by name (``circular`` or ``rectangular``)."""
    from tdcm_ros.errors import out_of_range
    from tdcm_ros.model.errors import InvalidDesignError

    if name == "circular":
        return CircularProfile()
    if name == "rectangular":
        return RectangularProfile()
    raise out_of_range("profile", name, " | ".join(PROFILE_NAMES), error=InvalidDesignError)
