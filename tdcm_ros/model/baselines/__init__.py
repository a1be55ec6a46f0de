"""Baseline models with the same input (:class:`.Design`) and output (:class:`.SolveResult`).

Registered by name in :data:`METHODS`:

- ``algorithm1``: the package's model (:func:`tdcm_ros.model.solve`), for side-by-side runs;
- ``constant-curvature``: one arc from the mean moment;
- ``pseudo-rigid-body``: one torsional-spring joint per notch, rigid tubes;
- ``shooting-whole`` / ``shooting-segmented``: Cosserat BVP by shooting, over the whole
  length or restarted at every stiffness jump.

Use :func:`get_method` (unknown names raise :class:`.InvalidSettingsError` listing the valid
ones) or :func:`solve_with`.
"""

from __future__ import annotations

from typing import Any, Protocol

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.baselines.constant_curvature import solve_constant_curvature
from tdcm_ros.model.baselines.pseudo_rigid_body import solve_pseudo_rigid_body
from tdcm_ros.model.baselines.shooting import (
    DEFAULT_OPTIONS,
    OdeMethod,
    ShootingOptions,
    solve_shooting_segmented,
    solve_shooting_whole,
)
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidSettingsError
from tdcm_ros.model.result import SolveResult
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import solve


class Method(Protocol):
    """A model: ``(design, tension (N), *, settings) -> SolveResult``. A method may take keyword
    options of its own besides (:func:`solve_with` passes them on by name)."""

    def __call__(self, design: Design, tension: float, /, *,
                 settings: SolverSettings = ...) -> SolveResult: ...


METHODS: dict[str, Method] = {
    "algorithm1": solve,
    "constant-curvature": solve_constant_curvature,
    "pseudo-rigid-body": solve_pseudo_rigid_body,
    "shooting-whole": solve_shooting_whole,
    "shooting-segmented": solve_shooting_segmented,
}


def get_method(name: str) -> Method:
    """The registered method ``name``; raises :class:`.InvalidSettingsError` listing valid names."""
    try:
        return METHODS[name]
    except KeyError:
        raise out_of_range("method", name, " | ".join(METHODS),
                           error=InvalidSettingsError) from None


def solve_with(name: str, design: Design, tension: float, **options: Any) -> SolveResult:
    """Solve ``design`` at ``tension`` (N) with the method ``name`` and its keyword options."""
    return get_method(name)(design, tension, **options)


__all__ = [
    "DEFAULT_OPTIONS",
    "METHODS",
    "Method",
    "OdeMethod",
    "ShootingOptions",
    "get_method",
    "solve_constant_curvature",
    "solve_pseudo_rigid_body",
    "solve_shooting_segmented",
    "solve_shooting_whole",
    "solve_with",
]
