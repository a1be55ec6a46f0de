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


def notched_moment(h1: ArrayLike, r_outer: ArrayLike, r_inner: ArrayLike) -> Array:
    """Eq. 12 inside a notch: ``4 [J(h1, R_outer) - J(h2, r_inner)]``, ``h2 = min(h1, r_inner)`` (m^4).

    For ``h1 >= R_outer`` nothing is removed and the result equals :func:`tube_moment`. The radii
    (m) broadcast against ``h1``. The solver's own formula
    (:func:`tdcm_ros.model.grid_kernel.notched_inertia`), in its build, over arrays.
    """
    # lazily: the compiled module imports tdcm_ros.model, which imports this one
    from tdcm_ros.model.compiled import grid_kernels

    h1a, outer, inner = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                              for v in (h1, r_outer, r_inner)))
    out = np.empty(h1a.size)
    grid_kernels().notched_inertias(np.ascontiguousarray(h1a).ravel(),
                                    np.ascontiguousarray(outer).ravel(),
                                    np.ascontiguousarray(inner).ravel(), out)
    return out.reshape(h1a.shape)


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
