"""Second moment of area (eq. 12) and area of the notched tube, in closed form.

Inside a notch the section is the annulus ``r_inner <= rho <= R_outer`` restricted to
``|y| <= h1``, where ``y`` is the distance from the neutral axis in the bending direction;
the hole is removed only up to ``h2 = min(h1, r_inner)`` (eq. 13's clipping). Outside the
notches ``I0 = pi/4 (R_outer^4 - r_inner^4)``. The section area ``A`` (for body forces such
as gravity) follows the same restriction. All lengths in m, ``A`` in m^2, ``I`` in m^4.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


#: Below this ``h/R`` :func:`disc_strip_moment` sums its series: the closed form's two terms
#: cancel (relative error ~ 1e-16 (R/h)^2) while the series' truncation stays below 1e-15.
SERIES_BELOW = 0.05
#: ``J/R^4 = sum_k c_k t^(2k+3)``: ``t^2 sqrt(1 - t^2)`` expanded and integrated.
_SERIES = (1.0 / 3.0, -1.0 / 10.0, -1.0 / 56.0, -1.0 / 144.0, -5.0 / 1408.0)


def disc_strip_moment(h: ArrayLike, radius: ArrayLike) -> Array:
    """``J(h) = integral_0^h y^2 sqrt(radius^2 - y^2) dy`` with ``h`` clipped to [0, radius] (m^4);
    0 where ``radius <= 0``. ``radius`` (m) broadcasts against ``h`` (one radius per cell).

    Closed form: ``(h/8)(2h^2 - R^2) sqrt(R^2 - h^2) + (R^4/8) asin(h/R)``; for
    ``h/R < SERIES_BELOW`` its Taylor series in ``t = h/R``, exact to rounding where the closed
    form cancels (a backbone far thinner than the tube).
    """
    solid = np.asarray(radius, dtype=float)
    radius = np.where(solid > 0.0, solid, 1.0)
    hc = np.clip(np.asarray(h, dtype=float), 0.0, radius)
    root = np.sqrt(np.maximum(radius * radius - hc * hc, 0.0))
    closed = (hc / 8.0) * (2.0 * hc * hc - radius * radius) * root + (
        radius**4 / 8.0) * np.arcsin(hc / radius)
    t = hc / radius
    t2 = t * t
    series = np.zeros_like(t)
    for coefficient in reversed(_SERIES):
        series = series * t2 + coefficient
    return np.where(solid > 0.0, np.where(t < SERIES_BELOW, radius**4 * t**3 * series, closed),
                    0.0)


def notched_moment(h1: ArrayLike, r_outer: ArrayLike, r_inner: ArrayLike) -> Array:
    """Eq. 12 inside a notch: ``4 [J(h1, R_outer) - J(h2, r_inner)]``, ``h2 = min(h1, r_inner)`` (m^4).

    For ``h1 >= R_outer`` nothing is removed and the result equals :func:`tube_moment`. The radii
    (m) broadcast against ``h1``.
    """
    h1a = np.asarray(h1, dtype=float)
    h2 = np.minimum(h1a, r_inner)
    return 4.0 * (disc_strip_moment(h1a, r_outer) - disc_strip_moment(h2, r_inner))


def tube_moment(r_outer: float, r_inner: float) -> float:
    """Eq. 12 outside notches: ``pi/4 (R_outer^4 - r_inner^4)`` (m^4)."""
    return float(np.pi / 4.0 * (r_outer**4 - r_inner**4))



def disc_strip_area(h: ArrayLike, radius: float) -> Array:
    """``K(h) = integral_0^h sqrt(radius^2 - y^2) dy`` with ``h`` clipped to [0, radius] (m^2).

    Closed form: ``(h sqrt(R^2 - h^2) + R^2 asin(h/R)) / 2``.
    """
    if radius <= 0.0:
        return np.zeros_like(np.asarray(h, dtype=float))
    hc = np.clip(np.asarray(h, dtype=float), 0.0, radius)
    root = np.sqrt(np.maximum(radius * radius - hc * hc, 0.0))
    return 0.5 * (hc * root + radius * radius * np.arcsin(hc / radius))


def notched_area(h1: ArrayLike, r_outer: float, r_inner: float) -> Array:
    """Area of the section inside a notch: ``4 [K(h1, R_outer) - K(h2, r_inner)]`` (m^2).

    Same section as :func:`notched_moment` (``h2 = min(h1, r_inner)``); for ``h1 >= R_outer``
    it equals :func:`tube_area`.
    """
    h1a = np.asarray(h1, dtype=float)
    h2 = np.minimum(h1a, r_inner)
    return 4.0 * (disc_strip_area(h1a, r_outer) - disc_strip_area(h2, r_inner))


def tube_area(r_outer: float, r_inner: float) -> float:
    """Area of the uncut annulus ``pi (R_outer^2 - r_inner^2)`` (m^2)."""
    return float(np.pi * (r_outer**2 - r_inner**2))
