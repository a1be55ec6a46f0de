"""Solver settings: routing, load form, discretisation and the convergence strategy."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from tdcm_ros.errors import reject_unknown
from tdcm_ros.model.errors import InvalidSettingsError
from tdcm_ros.spec import check_fields, spec_field, specs_of

ROUTINGS = ("paper", "free")
LOAD_FORMS = ("closed", "literal")
ACCELERATIONS = ("auto", "anderson", "relaxation", "none")
GRID_KINDS = ("adaptive", "uniform")
AXIAL_MODELS = ("rigid", "compressible")


@dataclass(frozen=True)
class SolverSettings:
    """How Algorithm 1 is discretised and driven.

    - ``routing``: ``paper`` keeps the tendon on the offset curve inside notches and straight
      across tube segments (eqs. 3-4 as written); ``free`` runs it straight across each notch gap
      and on the offset curve inside the tubes.
    - ``loads``: ``closed`` uses the tendon's equilibrium form ``m = (p_c - p) x (-T t_c)``;
      ``literal`` sums eqs. 8-10 (anchor, distributed and kink forces) on the grid.
    - ``grid``: ``adaptive`` also puts cell boundaries where a notch's ``h1`` crosses
      ``r_inner`` or ``R_outer`` and gives segments where the tendon runs as a chord more cells;
      ``uniform`` cuts every segment into equal steps of its profile coordinate.
    - ``cells_per_notch`` / ``cells_per_tube``: cells per segment; cell boundaries always fall on
      every ``l_i`` and ``r_i``.
    - ``quad_order``: Gauss-Legendre points per cell for compliance and position integrals.
    - ``tol``: Algorithm 1's ``epsilon`` (m) on the largest midline node displacement between
      two iterations. ``max_iter`` bounds the iterations over all strategies.
    - ``acceleration``: ``auto`` (Picard while it contracts, Anderson when it slows, damped
      relaxation and load continuation as fall-backs), or one strategy only.
    - ``axial``: ``rigid`` (the paper's inextensible midline) or ``compressible`` (each
      section shortens by ``T / (E A)`` under the tendons' resultant ``T``, ``A`` its area).
    """

    routing: str = spec_field("paper", choices=ROUTINGS, description="tendon routing")
    loads: str = spec_field("closed", choices=LOAD_FORMS, description="load form")
    grid: str = spec_field("adaptive", choices=GRID_KINDS,
                           description="cell layout: adaptive (boundaries at profile kinks) or uniform")
    cells_per_notch: int = spec_field(4, low=1, high=512, description="cells per notch")
    cells_per_tube: int = spec_field(1, low=1, high=512, description="cells per tube segment")
    quad_order: int = spec_field(6, low=1, high=32, description="Gauss-Legendre points per cell")
    tol: float = spec_field(1e-10, unit="m", low=0.0, high=1e-2, low_open=True,
                            description="convergence tolerance on the midline nodes")
    max_iter: int = spec_field(200, low=1, high=100000, description="largest number of iterations")
    acceleration: str = spec_field("auto", choices=ACCELERATIONS,
                                   description="convergence strategy")
    relaxation: float = spec_field(0.5, low=0.0, high=1.0, low_open=True,
                                   description="damping factor of the relaxation strategy")
    anderson_depth: int = spec_field(5, low=1, high=50, description="iterates Anderson mixes")
    continuation_steps: int = spec_field(8, low=0, high=1024,
                                         description="load continuation steps (fall-back)")
    axial: str = spec_field("rigid", choices=AXIAL_MODELS, description="midline under the "
                            "tendons' axial load: rigid (the paper's) or compressible (EA)")

    def __post_init__(self) -> None:
        check_fields(self, SOLVER_SPECS, error=InvalidSettingsError)

    def with_overrides(self, **overrides: Any) -> SolverSettings:
        """A validated copy with fields replaced; unknown names raise."""
        reject_unknown("solver setting", overrides, (f.name for f in fields(self)),
                       error=InvalidSettingsError)
        return replace(self, **overrides)

    def to_dict(self) -> dict[str, Any]:
        """All settings as a plain dict."""
        return asdict(self)


#: Specs of every solver setting, by name (declared on the fields above).
SOLVER_SPECS = specs_of(SolverSettings)
