"""Solver settings: routing, load form, discretisation and the convergence strategy."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from tdcm_ros.errors import out_of_range, reject_unknown
from tdcm_ros.model.errors import InvalidSettingsError

ROUTINGS = ("paper", "free")
LOAD_FORMS = ("closed", "literal")
ACCELERATIONS = ("auto", "anderson", "relaxation", "none")
GRID_KINDS = ("adaptive", "uniform")


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
    """

    routing: str = "paper"
    loads: str = "closed"
    grid: str = "adaptive"
    cells_per_notch: int = 4
    cells_per_tube: int = 1
    quad_order: int = 6
    tol: float = 1e-10
    max_iter: int = 200
    acceleration: str = "auto"
    relaxation: float = 0.5
    anderson_depth: int = 5
    continuation_steps: int = 8

    def __post_init__(self) -> None:
        choices = {"routing": ROUTINGS, "loads": LOAD_FORMS, "acceleration": ACCELERATIONS,
                   "grid": GRID_KINDS}
        for name, allowed in choices.items():
            if getattr(self, name) not in allowed:
                raise out_of_range(name, getattr(self, name), " | ".join(allowed),
                                   error=InvalidSettingsError)
        integers = {"cells_per_notch": (1, 512), "cells_per_tube": (1, 512),
                    "quad_order": (1, 32), "max_iter": (1, 100000), "anderson_depth": (1, 50),
                    "continuation_steps": (0, 1024)}
        for name, (low, high) in integers.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                raise out_of_range(name, value, f"integer in [{low}, {high}]",
                                   error=InvalidSettingsError)
        if not (isinstance(self.tol, (int, float)) and math.isfinite(self.tol)
                and 0.0 < self.tol <= 1e-2):
            raise out_of_range("tol", self.tol, "(0, 0.01] m", error=InvalidSettingsError)
        if not (isinstance(self.relaxation, (int, float)) and 0.0 < self.relaxation <= 1.0):
            raise out_of_range("relaxation", self.relaxation, "(0, 1]", error=InvalidSettingsError)

    def with_overrides(self, **overrides: Any) -> SolverSettings:
        """A validated copy with fields replaced; unknown names raise."""
        reject_unknown("solver setting", overrides, (f.name for f in fields(self)),
                       error=InvalidSettingsError)
        return replace(self, **overrides)

    def to_dict(self) -> dict[str, Any]:
        """All settings as a plain dict."""
        return asdict(self)
