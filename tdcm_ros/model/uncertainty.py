"""How far off a predicted shape may be: the fitted parameters' covariance carried to points.

A calibration (``tdcm calibrate``) leaves its parameters' covariance ``C_p`` (design fields in
SI units and the capstan friction ``mu``) and the standard deviation ``residual_m`` (m) of its
residuals (marker noise and what the model cannot explain). A point ``x(p)`` of the predicted
shape then has the covariance

``C_x = J C_p J^T``  (``J = dx/dp``, by forward differences through the solver)

and a marker measured there falls at ``x`` within ``C_x + residual_m^2 I`` (the prediction's
covariance). :func:`monte_carlo_covariances` is the check: the sample covariance of ``x(p)`` over
parameters drawn from ``N(p, C_p)``. The 95 % band of a point is the ellipsoid
``d^T C^-1 d <= chi2_3(0.95)`` (:func:`inside_band`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tdcm_ros.errors import InputError, out_of_range
from tdcm_ros.model.design import FIELD_SPECS, Design

Array = NDArray[np.float64]
#: The friction coefficient's name among the fitted parameters (not a design field).
MU = "mu"
#: Relative forward-difference step of the point Jacobian (of the parameter's value, or of its
#: standard deviation where that is larger: ``mu`` may be 0).
JACOBIAN_STEP = 1e-3
#: Draws a Monte Carlo check may make per sample it keeps (the rest fall outside the ranges).
MAX_REDRAWS = 10
#: Largest eigenvalue of a covariance allowed below zero, relative to its largest (rounding).
PSD_TOLERANCE = 1e-9

#: The points of a shape for a design and friction ``mu``: (k, 3) m.
PointsAt = Callable[[Design, float], Array]


class InvalidUncertaintyError(InputError):
    """A parameter covariance or a band request is invalid."""

    kind = "invalid_uncertainty"


def fittable_names() -> tuple[str, ...]:
    """Parameters a calibration can fit and carry: the real design fields and ``mu``."""
    return (*(n for n, spec in FIELD_SPECS.items() if not spec.integer), MU)


@dataclass(frozen=True, eq=False)
class ParameterCovariance:
    """Fitted parameters ``names`` (SI; ``mu`` dimensionless) with their ``values``, their
    ``covariance`` (n, n) and the residual standard deviation ``residual_m`` (m)."""

    names: tuple[str, ...]
    values: Array
    covariance: Array
    residual_m: float

    def __post_init__(self) -> None:
        known = fittable_names()
        for name in self.names:
            if name not in known:
                raise out_of_range("uncertainty.parameters", name, ", ".join(known),
                                   error=InvalidUncertaintyError)
        n = len(self.names)
        if n == 0 or len(set(self.names)) != n:
            raise out_of_range("uncertainty.parameters", list(self.names),
                               "one or more distinct names", error=InvalidUncertaintyError)
        values = np.asarray(self.values, dtype=float)
        cov = np.asarray(self.covariance, dtype=float)
        if values.shape != (n,) or not np.all(np.isfinite(values)):
            raise out_of_range("uncertainty.values", self.values, f"{n} finite numbers",
                               error=InvalidUncertaintyError)
        if cov.shape != (n, n) or not np.all(np.isfinite(cov)) or not np.allclose(
                cov, cov.T, rtol=1e-9, atol=0.0):
            raise out_of_range("uncertainty.covariance", cov.tolist(),
                               f"a finite symmetric {n} x {n} matrix",
                               error=InvalidUncertaintyError)
        eig = np.linalg.eigvalsh(cov)
        if eig[0] < -PSD_TOLERANCE * max(eig[-1], 0.0) or eig[-1] <= 0.0:
            raise out_of_range("uncertainty.covariance", cov.tolist(),
                               "positive semi-definite, not zero", error=InvalidUncertaintyError)
        if not (math.isfinite(self.residual_m) and self.residual_m >= 0.0):
            raise out_of_range("uncertainty.residual_m", self.residual_m, "[0, inf) m",
                               error=InvalidUncertaintyError)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "covariance", (cov + cov.T) / 2.0)

    @property
    def std(self) -> Array:
        """Each parameter's standard deviation (its unit)."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def at(self, design: Design, mu: float) -> Array:
        """The parameters' values in ``design`` and friction ``mu`` (where the band is taken)."""
        return np.array([mu if name == MU else float(getattr(design, name))
                         for name in self.names])

    def to_dict(self) -> dict[str, object]:
        """The body file's ``uncertainty`` section."""
        return {"parameters": list(self.names), "values": self.values.tolist(),
                "covariance": self.covariance.tolist(), "residual_m": self.residual_m}


def with_values(design: Design, mu: float, names: Sequence[str], values: ArrayLike
                ) -> tuple[Design, float]:
    """``design`` and ``mu`` with the parameters ``names`` set to ``values``."""
    given = dict(zip(names, np.asarray(values, dtype=float).tolist(), strict=True))
    new_mu = given.pop(MU, mu)
    return (design.with_overrides(**given) if given else design), new_mu


def point_jacobian(points_at: PointsAt, design: Design, mu: float,
                   uncertainty: ParameterCovariance, base: Array | None = None) -> Array:
    """``dx/dp`` (n, k, 3), m per parameter unit, of the points ``points_at`` gives, by
    forward differences (step :data:`JACOBIAN_STEP` of the value or its standard deviation)
    at ``design`` and ``mu``; ``base``: the points there if already solved."""
    x0 = uncertainty.at(design, mu)
    centre = points_at(design, mu) if base is None else base
    steps = JACOBIAN_STEP * np.maximum(np.abs(x0), uncertainty.std)
    out = np.empty((len(x0), *centre.shape))
    for i, (name, step) in enumerate(zip(uncertainty.names, steps, strict=True)):
        moved_design, moved_mu = with_values(design, mu, (name,), (x0[i] + step,))
        out[i] = (points_at(moved_design, moved_mu) - centre) / step
    return out


def point_covariances(jacobian: Array, covariance: Array) -> Array:
    """``J C_p J^T`` per point: (k, 3, 3) m^2 from ``jacobian`` (n, k, 3) and ``covariance``
    (n, n)."""
    return np.einsum("aki,ab,bkj->kij", jacobian, covariance, jacobian)


def linearised_covariances(points_at: PointsAt, design: Design, mu: float,
                           uncertainty: ParameterCovariance, base: Array | None = None
                           ) -> Array:
    """Each point's covariance (k, 3, 3) m^2 from the parameters' (linearised)."""
    return point_covariances(point_jacobian(points_at, design, mu, uncertainty, base),
                             uncertainty.covariance)


def monte_carlo_covariances(points_at: PointsAt, design: Design, mu: float,
                            uncertainty: ParameterCovariance, samples: int,
                            rng: np.random.Generator) -> Array:
    """Each point's sample covariance (k, 3, 3) m^2 over ``samples`` parameter draws from
    ``N(p, C_p)`` (draws outside a parameter's range, or ``mu < 0``, are drawn again, at most
    :data:`MAX_REDRAWS` times ``samples`` draws in all)."""
    if samples < 2:
        raise out_of_range("samples", samples, "[2, inf)", error=InvalidUncertaintyError)
    x0 = uncertainty.at(design, mu)
    points: list[Array] = []
    for _ in range(MAX_REDRAWS * samples):
        draw = rng.multivariate_normal(x0, uncertainty.covariance)
        try:
            moved = with_values(design, mu, uncertainty.names, draw)
        except InputError:
            continue
        if moved[1] < 0.0:
            continue
        points.append(points_at(*moved))
        if len(points) == samples:
            break
    else:
        raise InvalidUncertaintyError(
            f"only {len(points)} of {samples} parameter draws were valid designs in "
            f"{MAX_REDRAWS * samples} draws; allowed: a covariance mostly inside the parameters' "
            "ranges", parameter="uncertainty.covariance", value=uncertainty.covariance.tolist(),
            allowed="draws inside the parameters' ranges")
    stack = np.asarray(points)
    centred = stack - stack.mean(axis=0)
    return np.einsum("ski,skj->kij", centred, centred) / (samples - 1)


def chi2_3(confidence: float) -> float:
    """The squared Mahalanobis radius of a 3-D normal's ``confidence`` ellipsoid (the
    ``chi2_3`` quantile; its CDF ``erf(sqrt(x/2)) - sqrt(2x/pi) exp(-x/2)`` inverted)."""
    return _inverse(lambda x: math.erf(math.sqrt(x / 2.0))
                    - math.sqrt(2.0 * x / math.pi) * math.exp(-x / 2.0), confidence)


def normal_quantile(confidence: float) -> float:
    """``z`` of the two-sided ``confidence`` interval of a normal (``erf(z / sqrt 2)``
    inverted)."""
    return _inverse(lambda z: math.erf(z / math.sqrt(2.0)), confidence)


def _inverse(cdf: Callable[[float], float], confidence: float) -> float:
    """The ``x >= 0`` where the increasing ``cdf`` reaches ``confidence`` (bisection to
    rounding)."""
    if not (math.isfinite(confidence) and 0.0 < confidence < 1.0):
        raise out_of_range("confidence", confidence, "(0, 1)", error=InvalidUncertaintyError)
    low, high = 0.0, 1.0
    while cdf(high) < confidence:
        high *= 2.0
    for _ in range(200):
        mid = (low + high) / 2.0
        if mid in (low, high):
            break
        low, high = (mid, high) if cdf(mid) < confidence else (low, mid)
    return high


def prediction_covariances(covariances: Array, residual_m: float) -> Array:
    """Where a marker measured at each point may fall: ``C_x + residual_m^2 I`` (k, 3, 3)."""
    return covariances + residual_m**2 * np.eye(3)


def inside_band(offsets: Array, covariances: Array, confidence: float = 0.95) -> NDArray[
        np.bool_]:
    """Whether each offset (k, 3) m (measured minus predicted) lies in its prediction
    covariance's (k, 3, 3, full rank) ``confidence`` ellipsoid."""
    solved = np.linalg.solve(covariances, offsets[..., None])[..., 0]
    return np.einsum("ki,ki->k", offsets, solved) <= chi2_3(confidence)


def band_half_widths(covariances: Array, normals: Array, confidence: float = 0.95) -> Array:
    """Half-width (m) of each point's band along its unit ``normals`` (k, 3): the
    ``confidence`` interval of the point's offset along the normal."""
    variance = np.einsum("ki,kij,kj->k", normals, covariances, normals)
    return normal_quantile(confidence) * np.sqrt(np.clip(variance, 0.0, None))
