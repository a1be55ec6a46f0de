"""Notch profiles: the backbone half-width ``h1`` across one notch (eq. 13 and alternatives).

A profile maps a reference coordinate ``u`` in [0, 1] across the notch to the local arc
length ``sigma = s - l_i`` in [0, w_n] (m) and gives ``h1`` there (m). The map is chosen so
that ``h1`` is smooth in ``u``: the circular notch uses the paper's own angle ``t``, in which
the profile is a sine, instead of ``s``, in which it has an infinite slope at the edges.
Quadrature and cell boundaries are placed uniformly in ``u``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from tdcm_ros.model.sections import SectionProperties

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


class _StraightSlot:
    """A notch the same all along it: ``sigma = w_n u`` and ``h1 = w_d/2`` at every ``u``."""

    def sigma(self, u: Array, w_n: Width) -> Array:
        """Local arc length (m) at reference coordinate ``u``."""
        return w_n * u

    def dsigma_du(self, u: Array, w_n: Width) -> Array:
        """Jacobian d(sigma)/du (m)."""
        return np.full_like(u, w_n)

    def h1(self, u: Array, w_n: Width, w_d: Width) -> Array:
        """Backbone half-width (m) at ``u``: ``w_d / 2``."""
        return np.full_like(u, 0.5 * w_d)


@dataclass(frozen=True)
class RectangularProfile(_StraightSlot):
    """A straight-bottomed slot: ``h1 = w_d/2`` across the whole notch."""

    name: str = "rectangular"


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


@dataclass(frozen=True)
class PolygonProfile(_StraightSlot):
    """A prismatic notch whose section is a polygon of material. Along the body it is the
    rectangular slot; ``h1`` is half the polygon's extent in ``x``, which a
    :class:`~tdcm_ros.model.design.Design` holds as the notch's ``w_d`` (and the extent's middle
    as ``w_o``). The mechanics read the section whole (:meth:`section`), not ``h1``.

    ``shell`` and ``holes`` are :class:`~tdcm_ros.model.sections.PolygonSection`'s (vertices
    ``(x, y)`` in m in the section plane, ``x`` toward the tendon).
    """

    shell: tuple[tuple[float, float], ...]
    holes: tuple[tuple[tuple[float, float], ...], ...] = ()
    name: str = "polygon"

    def __post_init__(self) -> None:
        def ring(points: Any) -> tuple[tuple[float, float], ...]:
            try:
                return tuple((float(x), float(y)) for x, y in points)
            except (TypeError, ValueError):
                return tuple(points)  # the section's check names what is wrong with it

        object.__setattr__(self, "shell", ring(self.shell))
        object.__setattr__(self, "holes", tuple(ring(hole) for hole in self.holes))

    def section(self, r_outer: float) -> SectionProperties:
        """The polygon's section properties in a tube of outer radius ``r_outer`` (m); checked
        (a simple polygon of positive area) and computed once per polygon and radius."""
        return _polygon_properties(self.shell, self.holes, float(r_outer))

    def x_extent(self) -> tuple[float, float]:
        """The smallest and largest ``x`` of the polygon's material (m)."""
        xs = [x for x, _ in self.shell]
        return min(xs), max(xs)

    def check_inside(self, r_outer: float, where: str) -> None:
        """Raise :class:`~tdcm_ros.model.errors.InvalidDesignError` naming ``where`` unless
        every vertex is within ``r_outer`` (m, to rounding) of the tube axis."""
        from tdcm_ros.errors import out_of_range
        from tdcm_ros.model.errors import InvalidDesignError
        from tdcm_ros.model.sections import OFFSET_SLACK

        reach = max(math.hypot(x, y) for x, y in self.shell)
        if reach > r_outer * (1.0 + OFFSET_SLACK):
            raise out_of_range(where, reach, f"vertices within R_outer = {r_outer:g} m of the "
                               "tube axis", error=InvalidDesignError)


@dataclass(frozen=True)
class SectionProfile(_StraightSlot):
    """A prismatic notch whose section is given by its numbers (a slice of a mesh,
    :mod:`tdcm_ros.model.mesh_body`): ``area`` (m^2), ``centroid_x`` (m), ``second_moment``
    about the centroid (m^4), ``x_low``/``x_high``, the material's extent in ``x`` (m)."""

    area: float
    centroid_x: float
    second_moment: float
    x_low: float
    x_high: float
    name: str = "section"

    def section(self, r_outer: float) -> SectionProperties:
        """The section's properties in a tube of outer radius ``r_outer`` (m)."""
        from tdcm_ros.model.sections import SectionProperties, keeps_wall

        x_bar = self.centroid_x
        return SectionProperties(
            area=np.array(self.area), centroid_x=np.array(x_bar),
            second_moment=np.array(self.second_moment),
            fibre_tendon_side=np.array(self.x_high - x_bar),
            fibre_far_side=np.array(x_bar - self.x_low),
            face_arm=np.array(np.inf if keeps_wall(self.x_high, r_outer) else r_outer - x_bar))

    def x_extent(self) -> tuple[float, float]:
        """The smallest and largest ``x`` of the section's material (m)."""
        return self.x_low, self.x_high


PrismaticProfile = PolygonProfile | SectionProfile
PRISMATIC_PROFILES = (PolygonProfile, SectionProfile)


@lru_cache(maxsize=256)
def _polygon_properties(shell: tuple[tuple[float, float], ...],
                        holes: tuple[tuple[tuple[float, float], ...], ...], r_outer: float
                        ) -> SectionProperties:
    from tdcm_ros.model.sections import PolygonSection

    return PolygonSection(shell, r_outer, holes).properties()


NotchProfile = (CircularProfile | RectangularProfile | CustomProfile | PolygonProfile
                | SectionProfile)

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
