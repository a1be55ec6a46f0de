"""Design space (paper Sec. III-A, Figs. 2(c), 3(c)): tip response over design fields x tension.

:func:`sweep` varies one or two numeric design fields (SI units, by name) and the tendon
tension, solving every grid point with :func:`tdcm_ros.model.batch.solve_batch`; it returns
tip deflection and tip angle surfaces with a feasibility status per point.
:func:`design_curves` gives the same quantities along tension for chosen designs (the
paper's "design curves").

Feasibility (``status``), first match wins:

- ``invalid`` / ``singularity`` / ``closure`` / ``non_convergence``: where the single
  :func:`tdcm_ros.model.solve` raises ``InvalidDesignError``/``TensionRangeError``,
  ``TendonSingularityError``, ``NotchClosureError`` or ``ConvergenceError``;
- ``strain``: the largest bending strain in a notch, ``|kappa| min(h1, R_outer)`` at the
  outer fibre of the backbone, exceeds ``allowable_strain``;
- ``ok`` otherwise. Values are NaN where no solution exists; :meth:`DesignSpace.masked`
  also hides the ``strain`` points.

Coupling ``fixed-pitch`` is the rule of the paper's simulations (``L = 53 mm`` with
``w_t = w_tip = 6 mm - w_n``): the pitch ``P = w_n + w_t`` of the base design is kept, and
every swept design gets ``w_t = w_tip = P - w_n``, so ``L = w_base + N P`` stays fixed.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.batch import BatchResult, solve_batch
from tdcm_ros.model.design import FIELD_SPECS, Design
from tdcm_ros.model.errors import InvalidDesignError, InvalidSettingsError
from tdcm_ros.model.limits import check_tension
from tdcm_ros.model.progress import Progress, report_progress
from tdcm_ros.model.settings import SolverSettings
from tdcm_ros.model.solver import DEFAULT_SETTINGS

Array = NDArray[np.float64]

NYLON12_ELONGATION_AT_BREAK = {"xy": 0.11, "z": 0.06}
"""Formlabs Nylon 12 Powder (SLS, Fuse 1) technical data sheet, elongation at break per
build direction (the same sheet gives the 1.85 GPa tensile modulus used for ``E``)."""
DEFAULT_ALLOWABLE_STRAIN = NYLON12_ELONGATION_AT_BREAK["z"]
"""The lower (Z, across layers) datasheet value: the build direction of the body is unknown
and an elongation at break is a failure, not a working, strain."""
COUPLINGS = ("none", "fixed-pitch")
PROGRESS_UPDATES = 40
"""Most chunks a sweep with a progress hook is solved in."""
PROGRESS_CHUNK_DESIGNS = 100
"""Fewest designs in such a chunk: each ``solve_batch`` call builds its grids at a fixed cost
of a few ms (bench/bench_progress.py), so a small sweep is solved in one batch."""
STATUSES = ("ok", "strain", "closure", "singularity", "non_convergence", "invalid")


@dataclass(frozen=True, eq=False)
class DesignSpace:
    """A sweep's grid: arrays of shape ``(len(values[0]), [len(values[1]),] len(tensions))``.

    ``fields`` name the swept design fields, ``values`` their SI values, ``tensions`` (N).
    ``tip_deflection_m`` (m), ``tip_angle_rad`` (rad) and ``max_bending_strain`` are NaN
    where no solution exists; ``status`` holds names from :data:`STATUSES`.
    """

    base: Design
    fields: tuple[str, ...]
    values: tuple[Array, ...]
    tensions: Array
    coupling: str
    allowable_strain: float
    designs: tuple[Design, ...]
    status: NDArray[np.str_]
    message: NDArray[np.object_]
    tip_deflection_m: Array
    tip_angle_rad: Array
    max_bending_strain: Array

    @property
    def feasible(self) -> NDArray[np.bool_]:
        """Points inside every limit, the strain limit included."""
        return self.status == "ok"

    def masked(self, quantity: str) -> np.ma.MaskedArray:
        """``tip_deflection_m``, ``tip_angle_rad`` or ``max_bending_strain`` with every
        infeasible point masked."""
        if quantity not in ("tip_deflection_m", "tip_angle_rad", "max_bending_strain"):
            raise out_of_range("quantity", quantity,
                               "tip_deflection_m | tip_angle_rad | max_bending_strain")
        return np.ma.masked_array(getattr(self, quantity), mask=~self.feasible)


@dataclass(frozen=True, eq=False)
class DesignCurve:
    """Tip response of one design along ``tensions`` (N); same fields as :class:`DesignSpace`."""

    label: str
    design: Design
    tensions: Array
    status: NDArray[np.str_]
    tip_deflection_m: Array
    tip_angle_rad: Array
    max_bending_strain: Array


def couple(design: Design, coupling: str, pitch: float) -> Design:
    """Apply ``coupling`` to ``design``; ``pitch`` = ``w_n + w_t`` of the base design (m)."""
    if coupling == "none":
        return design
    if coupling != "fixed-pitch":
        raise out_of_range("coupling", coupling, " | ".join(COUPLINGS), error=InvalidDesignError)
    w_n = design.uniform("w_n", "fixed-pitch coupling")
    if not w_n <= pitch:
        raise out_of_range("w_n", w_n, f"(0, {pitch:g}] m under fixed-pitch coupling "
                           "(w_t = w_tip = pitch - w_n >= 0)", error=InvalidDesignError)
    return design.with_overrides(w_t=pitch - w_n, w_tip=pitch - w_n)


def sweep(base: Design, axes: Mapping[str, ArrayLike], tensions: ArrayLike, *,
          coupling: str = "none", allowable_strain: float = DEFAULT_ALLOWABLE_STRAIN,
          settings: SolverSettings = DEFAULT_SETTINGS,
          progress: Progress | None = None) -> DesignSpace:
    """Tip response of ``base`` with one or two fields varied (``{name: SI values}``) at every
    tension (N). Invalid axis values raise :class:`InvalidDesignError`.

    With ``progress`` the designs are solved in chunks (at most :data:`.PROGRESS_UPDATES`, at
    least :data:`.PROGRESS_CHUNK_DESIGNS` designs each), each reported as ``progress("design
    sweep", designs solved, designs)``; the answers are the same."""
    if not isinstance(base, Design):
        raise InvalidDesignError(f"base = {base!r} is not a Design", parameter="base",
                                 value=base, allowed="tdcm_ros.model.Design")
    if not 1 <= len(axes) <= 2:
        raise InvalidDesignError(f"axes = {list(axes)!r}: sweep one or two design fields",
                                 parameter="axes", value=list(axes), allowed="1 or 2 field names")
    if coupling == "fixed-pitch" and {"w_t", "w_tip"} & set(axes):
        raise InvalidDesignError("fixed-pitch coupling sets w_t and w_tip; do not sweep them",
                                 parameter="axes", value=list(axes),
                                 allowed="fields other than w_t, w_tip")
    fields = tuple(axes)
    base.require_free(fields, "swept fields")
    values = tuple(_axis_values(name, axes[name]) for name in fields)
    t = _tensions(tensions)
    strain_limit = _allowable(allowable_strain)
    pitch = (base.uniform("w_n", "fixed-pitch coupling") + base.uniform(
        "w_t", "fixed-pitch coupling")) if coupling == "fixed-pitch" else math.nan
    shape = tuple(v.size for v in values)
    designs = []
    for index in np.ndindex(*shape):
        overrides = {name: _scalar(name, values[a].item(index[a])) for a, name in enumerate(fields)}
        designs.append(couple(base.with_overrides(**overrides), coupling, pitch))
    result = _solve_reporting(designs, t, settings, progress)
    status = _classify(result.status, result.max_bending_strain, strain_limit)
    grid_shape = shape + (t.size,)
    return DesignSpace(
        base=base, fields=fields, values=values, tensions=t, coupling=coupling,
        allowable_strain=strain_limit, designs=tuple(designs),
        status=status.reshape(grid_shape), message=result.message.reshape(grid_shape),
        tip_deflection_m=result.tip_deflection_m.reshape(grid_shape),
        tip_angle_rad=result.tip_angle_rad.reshape(grid_shape),
        max_bending_strain=result.max_bending_strain.reshape(grid_shape))


def _solve_reporting(designs: list[Design], tensions: Array, settings: SolverSettings,
                     progress: Progress | None) -> BatchResult:
    """``solve_batch`` of ``designs`` at every tension, in chunks reported to ``progress``."""
    if progress is None:
        return solve_batch(designs, np.broadcast_to(tensions, (len(designs), tensions.size)),
                           settings=settings)
    size = max(PROGRESS_CHUNK_DESIGNS, -(-len(designs) // PROGRESS_UPDATES))
    parts = []
    report_progress(progress, "design sweep", 0, len(designs))
    for start in range(0, len(designs), size):
        chunk = designs[start:start + size]
        parts.append(solve_batch(chunk, np.broadcast_to(tensions, (len(chunk), tensions.size)),
                                 settings=settings))
        report_progress(progress, "design sweep", start + len(chunk), len(designs))
    return BatchResult(**{f.name: np.concatenate([getattr(p, f.name) for p in parts])
                          for f in dataclasses.fields(BatchResult)})


def design_curves(designs: Mapping[str, Design], tensions: ArrayLike, *,
                  allowable_strain: float = DEFAULT_ALLOWABLE_STRAIN,
                  settings: SolverSettings = DEFAULT_SETTINGS) -> dict[str, DesignCurve]:
    """The "design curves": tip response of each labelled design along ``tensions`` (N)."""
    for label, design in designs.items():
        if not isinstance(design, Design):
            raise InvalidDesignError(f"design {label!r} = {design!r} is not a Design",
                                     parameter=label, value=design,
                                     allowed="tdcm_ros.model.Design")
    t = _tensions(tensions)
    strain_limit = _allowable(allowable_strain)
    labels = list(designs)
    result = solve_batch([designs[k] for k in labels], np.broadcast_to(t, (len(labels), t.size)),
                         settings=settings)
    status = _classify(result.status, result.max_bending_strain, strain_limit)
    return {label: DesignCurve(label=label, design=designs[label], tensions=t, status=status[i],
                               tip_deflection_m=result.tip_deflection_m[i],
                               tip_angle_rad=result.tip_angle_rad[i],
                               max_bending_strain=result.max_bending_strain[i])
            for i, label in enumerate(labels)}


def _classify(status: NDArray[np.str_], strain: Array, limit: float) -> NDArray[np.str_]:
    """Batch statuses plus ``strain`` where an otherwise valid point exceeds ``limit``."""
    out = status.astype("<U16")
    out[(status == "ok") & (strain > limit)] = "strain"
    return out


def _axis_values(name: str, raw: ArrayLike) -> Array:
    if name not in FIELD_SPECS:
        raise InvalidDesignError(f"cannot sweep {name!r}; allowed: {', '.join(FIELD_SPECS)}",
                                 parameter="axes", value=name, allowed=", ".join(FIELD_SPECS))
    try:
        values = np.atleast_1d(np.asarray(raw, dtype=float))
    except (TypeError, ValueError) as exc:
        raise InvalidDesignError(f"{name} values {raw!r} are not numbers", parameter=name,
                                 value=raw, allowed=FIELD_SPECS[name].allowed()) from exc
    if values.ndim != 1 or values.size == 0 or not np.all(np.isfinite(values)):
        raise InvalidDesignError(
            f"{name} values must be a non-empty 1-D array of finite numbers, got {raw!r}",
            parameter=name, value=raw, allowed=FIELD_SPECS[name].allowed())
    return values


def _scalar(name: str, value: float) -> Any:
    """An axis value as the field's type (``N`` must be a whole number)."""
    if not FIELD_SPECS[name].integer:
        return float(value)
    if value != math.floor(value):
        raise InvalidDesignError(f"{name} = {value!r} is not an integer",
                                 parameter=name, value=value, allowed=FIELD_SPECS[name].allowed())
    return int(value)


def _tensions(raw: ArrayLike) -> Array:
    values = np.atleast_1d(np.asarray(raw, dtype=object)).ravel()
    return np.array([check_tension(v) for v in values], dtype=float)


def _allowable(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
            math.isfinite(value) and 0.0 < value <= 1.0):
        raise out_of_range("allowable_strain", value, "(0, 1]", error=InvalidSettingsError)
    return float(value)
