"""A second solver of the notched rod, written independently of the package's code path.

Sections by numerical quadrature (or given whole); a prismatic notch's *centroid line* is an
arc in closed form (the neutral fibre keeps its length, the moment about the centroid is
constant where the tendon follows the body), left and re-joined to the tube axis by jumps at
the notch's faces, where the package stretches the axis instead; a circular notch by scipy's
ODE solver along the axis; tubes by the ODE solver under the tendon's chords, iterated to a
fixed point. Paper routing only.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from scipy.integrate import quad, solve_ivp

from tdcm_ros.model.design import Design


def strip_by_quadrature(lo: float, hi: float, r_outer: float, r_inner: float
                        ) -> tuple[float, float, float]:
    """Area, centroid offset and centroidal second moment of the tube where lo <= x <= hi,
    integrating the section's chord length 2 (sqrt(R^2 - x^2) - sqrt(r^2 - x^2)) over x."""
    def chord(x: float) -> float:
        return 2.0 * (math.sqrt(max(r_outer**2 - x * x, 0.0))
                      - math.sqrt(max(r_inner**2 - x * x, 0.0)))

    for kink in (-r_inner, r_inner):  # an end within rounding of a kink is taken at it: the
        if abs(lo - kink) < 1e-12 * r_outer:  # chord's infinite slope just past an end costs
            lo = kink  # quad 1e-4 (hypothesis: ends 5e-17 m inside the lumen's edge)
        if abs(hi - kink) < 1e-12 * r_outer:
            hi = kink
    kinks = [k for k in (-r_inner, r_inner) if lo < k < hi]
    moments = [quad(lambda x, n=n: x**n * chord(x), lo, hi, points=kinks or None,
                    epsabs=1e-13 * r_outer ** (n + 2), epsrel=1e-12, limit=200)[0]
               for n in range(3)]  # epsabs: a symmetric strip's first moment is 0
    area, first, second = moments
    centroid = first / area
    return area, centroid, second - area * centroid**2


#: A notch whose section changes along it: its section at ``sigma`` (m from the notch's start)
#: as centroid offset (m) and centroidal I (m^4), and where its derivatives jump (m).
Varying = tuple[Callable[[float], tuple[float, float]], Sequence[float]]


def notch_motion(design: Design, k: int, tension: float,
                 given: tuple[float, float] | None = None, varying: Varying | None = None
                 ) -> tuple[complex, float]:
    """Notch ``k``'s tube-axis displacement (z + i x, m, in the frame of its start) and bend
    (rad) under paper routing, where the tendon follows the body and the moment about the
    centroid is (R_c - x_bar) T whatever the shape. Prismatic (rectangular, or a section
    ``given`` as its centroid's offset (m) and centroidal I (m^4)): the neutral fibre is an
    arc of the notch's width, the axis reached by the jumps -x_bar n at the faces. Circular
    (eq. 13's half-width along the notch): scipy's ODE solver on the axis, which stretches by
    x_bar kappa, with the section by quadrature at every step; a ``varying`` section the same
    way, from break to break."""
    e, r_c, r_outer, r_inner = design.E, design.R_c, design.R_outer, design.r_inner
    w_n, w_d = design.per_notch("w_n")[k], design.per_notch("w_d")[k]
    w_o = design.per_notch("w_o")[k]

    def section(h1: float) -> tuple[float, float]:
        lo, hi = max(w_o - h1, -r_outer), min(w_o + h1, r_outer)
        _, centroid, inertia = strip_by_quadrature(lo, hi, r_outer, r_inner)
        return centroid, e * inertia

    if given is not None or design.notch_profiles()[k].name == "rectangular":
        centroid, ei = (given[0], e * given[1]) if given is not None else section(w_d / 2)
        kappa = (r_c - centroid) * tension / ei
        bend = kappa * w_n
        arc = (np.exp(1j * bend) - 1.0) / (1j * kappa)
        return 1j * centroid + arc - 1j * centroid * np.exp(1j * bend), bend

    def along(sigma: float) -> tuple[float, float]:
        if varying is not None:
            centroid, inertia = varying[0](sigma)
            return centroid, e * inertia
        return section((w_n + w_d) / 2 - math.sqrt(max(sigma * (w_n - sigma), 0.0)))

    def rhs(sigma: float, y: np.ndarray) -> list[float]:
        centroid, ei = along(sigma)
        kappa = (r_c - centroid) * tension / ei
        stretch = 1.0 + centroid * kappa
        return [stretch * math.cos(y[2]), stretch * math.sin(y[2]), kappa]

    state = np.zeros(3)
    stations = sorted({0.0, w_n, *(b for b in (varying[1] if varying else ()) if 0 < b < w_n)})
    for a, b in itertools.pairwise(stations):
        state = solve_ivp(rhs, (a, b), state, method="DOP853", rtol=1e-12, atol=1e-15).y[:, -1]
    return complex(state[0], state[1]), float(state[2])


def reference_tip(design: Design, tension: float,
                  given: Mapping[int, tuple[float, float]] | None = None,
                  varying: Mapping[int, Varying] | None = None) -> tuple[complex, np.ndarray]:
    """Tip (z + i x, m) and the bend across each notch (rad) of a design under paper routing
    by the second solver of the module docstring (:func:`notch_motion` in the notches; the
    prismatic sections ``given`` by notch index, as centroid offset (m) and I (m^4); the
    sections changing along a notch ``varying`` by notch index)."""
    given = given or {}
    varying = varying or {}
    e, r_c, r_outer, r_inner = design.E, design.R_c, design.R_outer, design.r_inner
    tube_ei = e * math.pi / 4.0 * (r_outer**4 - r_inner**4)
    left, right = design.notch_bounds()
    motions: dict[tuple[float, ...], tuple[complex, float]] = {}
    notches = []
    for k in range(design.N):
        key = (design.per_notch("w_n")[k], design.per_notch("w_d")[k],
               design.per_notch("w_o")[k], float(design.notch_profiles()[k].name == "circular"),
               *given.get(k, ()))
        if k in varying:
            key = (*key, float(k))
        if key not in motions:
            motions[key] = notch_motion(design, k, tension, given.get(k), varying.get(k))
        notches.append(motions[key])
    tubes = [(0.0, left[0]), *zip(right[:-1], left[1:], strict=True),
             (right[-1], design.length)]
    chords: list[tuple[complex, complex] | None] = [None] * len(tubes)

    def tube(start: complex, theta: float, length: float, chord: tuple[complex, complex] | None
             ) -> tuple[complex, float]:
        if length <= 0.0:
            return start, theta
        if chord is None:  # the first pass: the tendon straight at R_c
            anchor, direction = start + 1j * r_c * np.exp(1j * theta), np.exp(1j * theta)
        else:
            anchor, direction = chord[0], (chord[1] - chord[0]) / abs(chord[1] - chord[0])

        def rhs(_: float, y: np.ndarray) -> list[float]:
            p = complex(y[0], y[1])
            moment = -tension * ((anchor - p).conjugate() * direction).imag
            return [math.cos(y[2]), math.sin(y[2]), moment / tube_ei]

        out = solve_ivp(rhs, (0.0, length), [start.real, start.imag, theta], method="DOP853",
                        rtol=1e-13, atol=1e-16)
        return complex(out.y[0, -1], out.y[1, -1]), float(out.y[2, -1])

    for _ in range(50):
        p, theta = 0j, 0.0
        ends = []
        for k, (a, b) in enumerate(tubes):
            tube_start = (p, theta)
            p, theta = tube(p, theta, b - a, chords[k])
            ends.append((tube_start, (p, theta)))
            if k < len(notches):
                moved_by, bend = notches[k]
                p, theta = p + np.exp(1j * theta) * moved_by, theta + bend
        new = [(s[0] + 1j * r_c * np.exp(1j * s[1]), f[0] + 1j * r_c * np.exp(1j * f[1]))
               for s, f in ends]
        moved = max(abs(a[0] - b[0]) + abs(a[1] - b[1]) for a, b in zip(new, chords, strict=True)
                    ) if chords[0] is not None else math.inf
        chords = list(new)
        if moved < 1e-14:
            return p, np.array([bend for _, bend in notches])
    raise AssertionError("the reference did not converge")
