"""Table I metrics from per-step deflections and shape errors (SI units; percent for MAPE)."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tdcm_ros.errors import out_of_range


@dataclass(frozen=True)
class TableMetrics:
    """Table I over the usable steps (a step is usable when its tip deflection is measured).

    ``mae_m``, ``rmse_m``: of ``predicted - measured`` tip deflection (m). ``mape_pct``: mean of
    ``|predicted - measured| / measured`` (%) over the steps whose measured deflection is at
    least the threshold; ``mape_excluded`` of them were left out; ``None`` when none is left.
    ``shape_error_m``: mean over steps of the midline station distance (m). ``deflection_mean_m``:
    mean over trials of the measured tip deflection at the trial's highest-tension step (m);
    ``predicted_deflection_mean_m`` the same for the model. ``n_steps`` counts usable steps,
    ``n_flagged`` the steps left out of every metric.
    """

    mape_pct: float | None
    rmse_m: float | None
    mae_m: float | None
    shape_error_m: float | None
    deflection_mean_m: float | None
    predicted_deflection_mean_m: float | None
    n_trials: int
    n_steps: int
    n_flagged: int
    mape_excluded: int
    mape_threshold_m: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (``None`` where a metric has no data)."""
        return asdict(self)


def _mean(values: np.ndarray) -> float | None:
    return float(np.mean(values)) if values.size else None


def table_metrics(trials: ArrayLike, tensions_n: ArrayLike, measured_m: ArrayLike,
                  predicted_m: ArrayLike, shape_errors_m: ArrayLike, *,
                  mape_threshold_m: float = 1e-3) -> TableMetrics:
    """Table I from per-step arrays; NaN in ``measured_m``/``predicted_m`` marks a flagged step
    (left out everywhere), NaN in ``shape_errors_m`` a step without a measured midline."""
    if not (np.isfinite(mape_threshold_m) and mape_threshold_m > 0.0):
        raise out_of_range("mape_threshold_m", mape_threshold_m, "(0, inf)", unit="m")
    trial = np.asarray(trials, dtype=int)
    tension = np.asarray(tensions_n, dtype=float)
    meas = np.asarray(measured_m, dtype=float)
    pred = np.asarray(predicted_m, dtype=float)
    shape = np.asarray(shape_errors_m, dtype=float)
    usable = np.isfinite(meas) & np.isfinite(pred)
    err = pred[usable] - meas[usable]
    big = meas[usable] >= mape_threshold_m
    mape = _mean(100.0 * np.abs(err[big]) / meas[usable][big])
    highest_meas, highest_pred = [], []
    for k in np.unique(trial[usable]):
        rows = np.flatnonzero(usable & (trial == k))
        top = rows[np.argmax(tension[rows])]
        highest_meas.append(meas[top])
        highest_pred.append(pred[top])
    return TableMetrics(
        mape_pct=mape, rmse_m=float(np.sqrt(np.mean(err**2))) if err.size else None,
        mae_m=_mean(np.abs(err)), shape_error_m=_mean(shape[usable & np.isfinite(shape)]),
        deflection_mean_m=_mean(np.asarray(highest_meas)),
        predicted_deflection_mean_m=_mean(np.asarray(highest_pred)),
        n_trials=len(highest_meas), n_steps=int(usable.sum()), n_flagged=int((~usable).sum()),
        mape_excluded=int((~big).sum()), mape_threshold_m=float(mape_threshold_m))
