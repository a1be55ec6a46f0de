"""Material laws: the paper's linear one, or a bilinear one with a superelastic plateau.

``Material(law="bilinear", plateau_strain=eps_p, E_plateau=E_p)``: the stress is ``E eps`` up to
``|eps| = eps_p`` and grows with ``E_p`` beyond (nitinol's loading branch; the usual first
model: a plateau from about 2 % strain at about 8 % of ``E``). A section's moment at curvature
``kappa`` is the law integrated over it, strain ``kappa y`` at ``y`` from the centroid::

    M(kappa) = kappa [E I - (E - E_p) J(eps_p / |kappa|)],
    J(d) = int_{|y| > d} (|y| - d) |y| b(y) dy,

``b`` the section's width at ``y``: an annulus cut to the band ``|x - w_o| <= h1`` (its chord
lengths), or a polygon notch's section (:class:`~tdcm_ros.model.profiles.PolygonProfile`,
integrated exactly by Green's theorem: :func:`~tdcm_ros.model.sections.plateau_excess`). ``M``
is monotone in ``kappa`` (``E_p > 0``), so each moment has one curvature, found by false
position (Illinois's rule) in its bracket.
The neutral axis stays at the centroid: exact for sections symmetric about it (the paper's
bands, the tubes, a symmetric polygon), an approximation for one-sided cuts and polygons in the
plateau. Sections given by their numbers or by a mesh's slices carry no width profile: they
take the linear law only.

``recoverable_strain`` (default none): the largest strain the material recovers from; a
solution past it raises :class:`~tdcm_ros.model.errors.StrainLimitError`.

:class:`~tdcm_ros.model.material_model.MaterialLaw` is the moment model that applies it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.errors import InvalidDesignError

LAWS = ("linear", "bilinear")


@dataclass(frozen=True)
class Material:
    """A material law (see the module docstring): ``law`` (``linear`` | ``bilinear``),
    ``plateau_strain`` (the plateau's onset strain) and ``E_plateau`` (Pa, its slope) for the
    bilinear law, and ``recoverable_strain`` (inf: none)."""

    law: str = "linear"
    plateau_strain: float = math.inf
    E_plateau: float = math.nan
    recoverable_strain: float = math.inf

    @property
    def is_trivial(self) -> bool:
        """Whether this is the paper's material: the linear law without a strain limit."""
        return self.law == "linear" and self.recoverable_strain == math.inf

    @property
    def is_linear(self) -> bool:
        """Whether the law is linear (no plateau)."""
        return self.law == "linear"

    def check(self, modulus: float) -> None:
        """Raise :class:`.InvalidDesignError` naming the bad key (``material.<key>``) for a
        material of elastic modulus ``modulus`` (Pa)."""
        if self.law not in LAWS:
            raise out_of_range("material.law", self.law, " | ".join(LAWS),
                               error=InvalidDesignError)
        _positive("material.recoverable_strain", self.recoverable_strain, "(0, inf]",
                  allow_inf=True)
        if self.is_linear:
            if math.isfinite(self.plateau_strain) or not math.isnan(self.E_plateau):
                raise InvalidDesignError(
                    "material.plateau_strain and material.E_plateau go with law: bilinear; "
                    "allowed: law bilinear, or neither", parameter="material.law",
                    value=self.law, allowed="bilinear")
            return
        _positive("material.plateau_strain", self.plateau_strain, "(0, 1)")
        if self.plateau_strain >= 1.0:
            raise out_of_range("material.plateau_strain", self.plateau_strain, "(0, 1)",
                               error=InvalidDesignError)
        _positive("material.E_plateau", self.E_plateau, f"(0, E = {modulus:g}] Pa")
        if self.E_plateau > modulus:
            raise out_of_range("material.E_plateau", self.E_plateau,
                               f"(0, E = {modulus:g}] Pa (a softer plateau)", unit="Pa",
                               error=InvalidDesignError)


def _positive(name: str, value: object, allowed: str, allow_inf: bool = False) -> None:
    """Raise :class:`.InvalidDesignError` unless ``value`` is a positive number (finite unless
    ``allow_inf``)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0.0 or (
            not allow_inf and not math.isfinite(value)):
        raise out_of_range(name, value, allowed, error=InvalidDesignError)
