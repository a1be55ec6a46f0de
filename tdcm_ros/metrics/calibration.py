"""Least-squares calibration of design parameters (e.g. Young's modulus) and the tendon's
friction from measured steps.

Residuals: for every step and every marker visible in it, the model's marker point at the
step's mean tension (one per tendon for a body with several) minus the measured mean position,
all three coordinates, in the step's bending plane (m; ``tdcm_base`` at roll 0, else turned by
the step's roll, :func:`~tdcm_ros.metrics.evaluation.plane_markers`); a step whose roll moved
(:func:`~tdcm_ros.metrics.evaluation.roll_note`) is left out. ``scipy.optimize.least_squares``
(trust region, bounds from the design field ranges) fits the design fields relative to their
start values and ``mu`` (the capstan friction coefficient, :class:`~tdcm_ros.model.FrictionTrack`)
as it is. With friction (fitted, or ``options.friction_mu`` above 0) each recording's steps are
solved in the order they happened, so loading and unloading steps at one level differ by the
stick-slip hysteresis: that difference is what tells ``mu`` from ``E`` (with loading steps
alone the two trade against each other; the checks below report it).

Uncertainty: ``cov = s^2 (J^T J)^-1`` at the optimum with ``s^2 = |r|^2 / (m - n)``; the interval
is ``value +- t_{(1+confidence)/2, m-n} sqrt(cov_ii)``. It assumes independent residuals of
equal variance and a model that can match the data (systematic misfit widens ``s`` but not
the bias). A parameter is reported *not identifiable* when ``J^T J`` is near-singular
(condition number above ``MAX_CONDITION``), when its interval is wider than
``MAX_RELATIVE_HALF_WIDTH`` of its value, or when two fitted parameters correlate beyond
``MAX_CORRELATION``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares
from scipy.special import stdtrit

from tdcm_ros.errors import InputError, TdcmError, out_of_range
from tdcm_ros.metrics.evaluation import (
    Evaluation,
    marker_points,
    model_tensions,
    plane_markers,
    roll_note,
    solve_tension,
)
from tdcm_ros.metrics.measure import MeasuredStep
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.mocap import Registration
from tdcm_ros.model import (
    FIELD_SPECS,
    MAX_MU,
    MU,
    Design,
    FrictionTrack,
    ModelSpec,
    ParameterCovariance,
    Progress,
    SolveResult,
    fittable_names,
    report_progress,
)

Array = NDArray[np.float64]
MAX_CONDITION = 1e10
MAX_RELATIVE_HALF_WIDTH = 0.5
MAX_CORRELATION = 0.99
SINGULAR_CONDITION = 1e14
"""Above this condition number ``J^T J`` is treated as singular: infinite standard errors."""
FAILED_RESIDUAL_M = 1.0
"""Residual (m) given to every coordinate when the model has no solution at a trial point."""


class CalibrationError(InputError):
    """The calibration cannot run on these data or parameters."""


@dataclass(frozen=True)
class FittedParameter:
    """One fitted design field: start and fitted value, standard error and interval (SI)."""

    name: str
    unit: str
    initial: float
    value: float
    std: float
    ci_low: float
    ci_high: float

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dict."""
        def num(v: float) -> float | None:
            return v if np.isfinite(v) else None

        return {"value": self.value, "unit": self.unit, "initial": self.initial,
                "std": num(self.std), "ci_low": num(self.ci_low), "ci_high": num(self.ci_high)}


@dataclass(frozen=True, eq=False)
class Calibration:
    """Fitted parameters, the fit's statistics and the evaluations before and after."""

    parameters: tuple[FittedParameter, ...]
    confidence: float
    correlation: Array
    condition: float
    residual_rms_m: float
    n_residuals: int
    identifiable: bool
    before: Evaluation
    after: Evaluation
    warnings: tuple[str, ...]
    held_out: Evaluation | None = None
    """The held-out trials (not fitted) evaluated with the fitted model, if any were."""
    notes: tuple[str, ...] = ()
    """What the numbers assume and do not show (not a reason to reject the fit)."""

    @property
    def design(self) -> Design:
        """The design with the fitted values."""
        return self.after.options.design

    @property
    def friction_mu(self) -> float:
        """The friction coefficient after the fit (fitted, or as given)."""
        return self.after.options.friction_mu

    @property
    def model(self) -> ModelSpec:
        """The fitted model: design, friction and the parameters' covariance (``tdcm calibrate
        --out``; None where the fit has no finite covariance)."""
        return ModelSpec(self.design, self.friction_mu, self.after.options.uncertainty)

    def to_json(self) -> dict[str, Any]:
        """The ``tdcm calibrate --json`` document: :meth:`fit_json` with the evaluations
        ``before`` and ``after`` the fit and of the ``held_out`` trials (null if none; each
        :meth:`.Evaluation.to_json`, per step too)."""
        return {**self.fit_json(), "before": self.before.to_json(),
                "after": self.after.to_json(),
                "held_out": None if self.held_out is None else self.held_out.to_json()}

    def fit_json(self) -> dict[str, Any]:
        """The fit alone: parameters, confidence, correlation, conditioning, residuals,
        warnings."""
        return {"parameters": {p.name: p.to_json() for p in self.parameters},
                "confidence": self.confidence, "identifiable": self.identifiable,
                "correlation": [[None if not np.isfinite(c) else float(c) for c in row]
                                for row in self.correlation],
                "condition_number": self.condition if np.isfinite(self.condition) else None,
                "residual_rms_m": self.residual_rms_m, "n_residuals": self.n_residuals,
                "friction_mu": self.friction_mu, "warnings": list(self.warnings),
                "notes": list(self.notes)}


def parse_fit(text: str) -> tuple[str, ...]:
    """``E``, ``E,mu`` or ``E,w_d``: real-valued design fields and ``mu``, without repeats."""
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    allowed = fittable_names()
    for name in names:
        if name not in allowed:
            raise CalibrationError(f"--fit {name!r} is neither a real-valued design field nor mu; "
                                   "allowed: "
                                   f"{', '.join(allowed)}", parameter="--fit", value=name,
                                   allowed=", ".join(allowed))
    if not names or len(set(names)) != len(names):
        raise CalibrationError(f"--fit {text!r}: give distinct names, e.g. E or E,w_d",
                               parameter="--fit", value=text, allowed="NAME[,NAME...]")
    return names


@dataclass(frozen=True, eq=False)
class _Data:
    """Measured marker points in each step's bending plane (steps, k, 3) m with their step
    tensions (steps, J) N, a column per tendon, and the recording each step belongs to (steps,);
    steps whose roll moved left out."""

    tensions: Array
    markers: Array
    sources: NDArray[np.int64]

    @classmethod
    def of(cls, prepared: Sequence[tuple[Sequence[MeasuredStep], Registration]],
           options: EvaluateOptions, in_order: bool) -> _Data:
        """``in_order``: keep each recording's steps as they happened (friction); else warm
        starts follow increasing tension (the largest of a step's)."""
        tensions, markers, sources = [], [], []
        for k, (steps, reg) in enumerate(prepared):
            for step in steps:
                if roll_note(step, options):
                    continue
                tensions.append(model_tensions(step.tensions_n, options))
                markers.append(plane_markers(step, reg))
                sources.append(k)
        order = (np.arange(len(tensions)) if in_order
                 else np.argsort([max(t) for t in tensions], kind="stable"))
        return cls(np.asarray(tensions)[order], np.asarray(markers)[order],
                   np.asarray(sources, dtype=np.int64)[order])


def _model_markers(design: Design, mu: float, data: _Data, options: EvaluateOptions) -> Array:
    """The model's markers (steps, k, 3) m; a fresh friction track per recording."""
    out = np.empty_like(data.markers)
    warm: SolveResult | None = None
    track = FrictionTrack(mu)
    for i, tensions in enumerate(data.tensions.tolist()):
        if i and data.sources[i] != data.sources[i - 1]:
            track = FrictionTrack(mu)
        warm = track.solve(design, solve_tension(tensions), settings=options.solver,
                           warm_start=warm)
        out[i] = marker_points(warm, design, options)
    return out


def calibrate_steps(prepared: Sequence[tuple[Sequence[MeasuredStep], Registration]],
                    names: Sequence[str], options: EvaluateOptions, *,
                    confidence: float = 0.95, progress: Progress | None = None
                    ) -> tuple[EvaluateOptions, list[FittedParameter], Array, float, float, int,
                               list[str]]:
    """Fit ``names`` on measured steps with their registrations; see the module docstring.
    ``progress`` counts the model evaluations (stage ``fitting NAMES``; no total known).

    Returns the options with the fitted design and friction (and, where the fit has a finite
    covariance, its :class:`~tdcm_ros.model.ParameterCovariance`), the parameters, their
    correlation matrix, the condition number of ``J^T J``, the residual RMS (m), the residual
    count and the identifiability warnings.
    """
    if not (np.isfinite(confidence) and 0.0 < confidence < 1.0):
        raise out_of_range("confidence", confidence, "(0, 1)")
    friction = MU in names or options.friction_mu > 0.0
    data = _Data.of(prepared, options, in_order=friction)
    seen = ~np.isnan(data.markers)
    n = len(names)
    m = int(seen.sum())
    if m <= n:
        raise CalibrationError(f"{m} marker coordinates for {n} parameters; allowed: more "
                               "residuals than parameters", parameter="--fit", value=list(names))
    start = options.design
    starts = np.array([options.friction_mu if name == MU else float(getattr(start, name))
                       for name in names])
    # design fields relative to their start values; mu as it is (its start may be 0)
    x0 = np.array([1.0 if name == MU else v for name, v in zip(names, starts, strict=True)])
    low = np.array([0.0 if name == MU else max(FIELD_SPECS[name].low, 0.0) / v + 1e-6
                    for name, v in zip(names, x0, strict=True)])
    high = np.array([MAX_MU if name == MU else FIELD_SPECS[name].high / v
                     for name, v in zip(names, x0, strict=True)])
    units = [FIELD_SPECS[name].unit if name != MU else "" for name in names]

    def model_at(scaled: Array) -> tuple[Design, float]:
        values = dict(zip(names, (scaled * x0).tolist(), strict=True))
        mu = values.pop(MU, options.friction_mu)
        return start.with_overrides(**values), mu

    stage = f"fitting {', '.join(names)}"
    evaluations = 0

    def residuals(scaled: Array) -> Array:
        nonlocal evaluations
        evaluations += 1
        report_progress(progress, stage, evaluations, None)
        try:
            predicted = _model_markers(*model_at(scaled), data, options)
        except TdcmError:
            return np.full(m, FAILED_RESIDUAL_M)
        return (predicted - data.markers)[seen]

    begin = starts / x0
    first = residuals(begin)
    if np.all(first == FAILED_RESIDUAL_M):
        _model_markers(*model_at(begin), data, options)  # raises the model's own error
    fit = least_squares(residuals, begin, bounds=(low, high), x_scale="jac",
                        diff_step=1e-4,  # type: ignore[arg-type]  # scipy-stubs gap: scalar is array_like
                        xtol=1e-10, ftol=1e-12)
    dof = m - n
    s2 = float(fit.fun @ fit.fun) / dof
    jtj = np.asarray(fit.jac).T @ np.asarray(fit.jac)  # relative units: parameter / start
    eig = np.linalg.eigvalsh(jtj)
    condition = float(eig[-1] / eig[0]) if eig[0] > 0 else float("inf")
    cov: Array | None = None
    if condition < SINGULAR_CONDITION:
        cov = s2 * np.linalg.inv(jtj) * np.outer(x0, x0)
        std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        corr = np.clip(cov / np.outer(std, std), -1.0, 1.0) if np.all(std > 0) else np.eye(n)
    else:  # numerically singular: no finite interval
        std = np.full(n, np.inf)
        corr = np.full((n, n), np.nan)
        np.fill_diagonal(corr, 1.0)
    half = float(stdtrit(dof, 0.5 + confidence / 2.0)) * std  # scipy.stats.t.ppf's own call
    values = fit.x * x0
    params = [FittedParameter(nm, unit, float(v0), float(v), float(sd), float(v - h),
                              float(v + h))
              for nm, unit, v0, v, sd, h in zip(names, units, starts, values, std, half,
                                                strict=True)]
    warnings = _identifiability(params, corr, condition)
    if fit.status <= 0:
        warnings.append(f"least squares stopped without converging: {fit.message}")
    rms = float(np.sqrt(np.mean(fit.fun**2)))
    design, mu = model_at(fit.x)
    # a band needs a finite covariance and a residual to widen it by
    uncertainty = (ParameterCovariance(tuple(names), values, cov, float(np.sqrt(s2)))
                   if cov is not None and s2 > 0.0 else None)
    fitted = replace(options, design=design, friction_mu=mu, uncertainty=uncertainty)
    return fitted, params, corr, condition, rms, m, warnings


def _identifiability(params: Sequence[FittedParameter], corr: Array, condition: float
                     ) -> list[str]:
    warnings = []
    if not condition < MAX_CONDITION:
        warnings.append(f"not identifiable: J^T J is near-singular (condition number "
                        f"{condition:.3g} > {MAX_CONDITION:.0e}); the data do not fix "
                        f"{', '.join(p.name for p in params)} together")
    for p in params:
        if not (p.ci_high - p.value < MAX_RELATIVE_HALF_WIDTH * abs(p.value)):
            warnings.append(f"not identifiable: {p.name} = {p.value:.4g} {p.unit} +- "
                            f"{p.ci_high - p.value:.3g} {p.unit} (interval half-width above "
                            f"{MAX_RELATIVE_HALF_WIDTH:.0%} of the value)")
    for i in range(len(params)):
        for j in range(i + 1, len(params)):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > MAX_CORRELATION:
                warnings.append(f"not identifiable: {params[i].name} and {params[j].name} are "
                                f"correlated ({corr[i, j]:+.4f}); fit one and fix the other")
    return warnings
