"""Candidate designs for inverse design: free fields over ranges, sampled quasi-randomly.

A free field is a design field the search varies (``w_n``, ``w_d``, ``N``, ``w_base``, ``w_t``,
``w_tip``, SI units) or ``L``, the total length (m), which then sets the tube between notches
``w_t = (L - w_base - N w_n - w_tip) / (N - 1)`` (``w_tip`` when ``N = 1``). Every other field
comes from the base design.

Sampling: ``sobol`` (default), a scrambled Sobol' sequence (``scipy.stats.qmc``): low
discrepancy in the joint space, so every region of the design box of a few dimensions is
visited evenly and a rerun with the same seed gives the same candidates; ``lhs``, a Latin
hypercube: each field's range stratified into as many slices as samples (even marginals, not
joint). ``N`` takes each integer of its range with equal probability.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.design import FIELD_SPECS, MIN_SEGMENT_M, Design
from tdcm_ros.model.errors import InvalidDesignError, InvalidSettingsError

Array = NDArray[np.float64]

FREE_FIELDS = ("w_n", "w_d", "N", "w_base", "w_t", "w_tip", "L")
"""Fields the search may free (``L``: total length, m, setting ``w_t``)."""
SAMPLINGS = ("sobol", "lhs")
MAX_SAMPLES = 10_000_000
LENGTH_LIMIT_M = 1.0
"""Largest total length (m): the design fields' own upper bound."""


@dataclass(frozen=True)
class FreeRange:
    """One free field and its closed range ``[low, high]`` (SI units; integers for ``N``)."""

    name: str
    low: float
    high: float

    @property
    def integer(self) -> bool:
        """Whether the field takes integer values."""
        return self.name == "N"


def free_ranges(base: Design, free: Mapping[str, Any]) -> tuple[FreeRange, ...]:
    """``{name: (low, high)}`` checked against the fields' allowed ranges (and ``w_d`` below
    ``2 R_outer`` of ``base``); raises :class:`InvalidDesignError` naming the field, the value
    and the allowed range."""
    if not free:
        raise InvalidDesignError("no free field: give at least one of " + ", ".join(FREE_FIELDS),
                                 parameter="free", value={}, allowed=", ".join(FREE_FIELDS))
    base.require_free(list(free), "free fields")
    if "L" in free and "w_t" in free:
        raise InvalidDesignError("free L sets w_t: free one of L and w_t, not both",
                                 parameter="free", value=sorted(free), allowed="L or w_t")
    out = []
    for name, span in free.items():
        if name not in FREE_FIELDS:
            raise out_of_range("free field", name, ", ".join(FREE_FIELDS),
                               error=InvalidDesignError)
        try:
            low, high = span
        except (TypeError, ValueError):
            raise InvalidDesignError(f"{name} range {span!r} is not (MIN, MAX)", parameter=name,
                                     value=span, allowed="(MIN, MAX)") from None
        low, high = (_end(base, name, value, end) for value, end in ((low, "min"), (high, "max")))
        if low > high:
            raise InvalidDesignError(
                f"{name} range {low:g}:{high:g} is empty; allowed: MIN <= MAX",
                parameter=name, value=(low, high), allowed="MIN <= MAX")
        out.append(FreeRange(name, float(low), float(high)))
    return tuple(out)


def _end(base: Design, name: str, value: Any, end: str) -> float:
    """One end of a free range, checked as a value of the field."""
    where = f"{name} {end}"
    if name == "L":
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                not (math.isfinite(value) and 0.0 < value <= LENGTH_LIMIT_M):
            raise out_of_range(where, value, f"(0, {LENGTH_LIMIT_M:g}] m",
                               error=InvalidDesignError)
        return float(value)
    checked = FIELD_SPECS[name].check(value, where, error=InvalidDesignError)
    if name == "w_d" and checked >= 2.0 * base.R_outer:
        raise out_of_range(where, value, f"(0, 2 R_outer = {2.0 * base.R_outer:g}) m",
                           error=InvalidDesignError)
    return float(checked)


def sample_unit(dimensions: int, samples: int, sampling: str, seed: int) -> Array:
    """``samples`` points of the unit cube of ``dimensions`` (rows), by ``sampling``."""
    if isinstance(samples, bool) or not isinstance(samples, int) or \
            not 1 <= samples <= MAX_SAMPLES:
        raise out_of_range("samples", samples, f"an integer in [1, {MAX_SAMPLES}]",
                           error=InvalidSettingsError)
    if sampling not in SAMPLINGS:
        raise out_of_range("sampling", sampling, " | ".join(SAMPLINGS),
                           error=InvalidSettingsError)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise out_of_range("seed", seed, "an integer >= 0", error=InvalidSettingsError)
    from scipy.stats import qmc  # lazily: the model package does not load scipy

    if sampling == "lhs":
        return np.asarray(qmc.LatinHypercube(d=dimensions, seed=seed).random(samples))
    # A power of two keeps Sobol's balance; the first `samples` points of it are used.
    points = qmc.Sobol(d=dimensions, scramble=True, seed=seed).random_base2(
        max(0, math.ceil(math.log2(samples))))
    return np.asarray(points[:samples])


def scale(ranges: tuple[FreeRange, ...], unit: Array) -> dict[str, Array]:
    """Unit-cube points mapped onto the ranges: ``{name: values}`` (integers for ``N``,
    each integer of the range equally likely)."""
    out = {}
    for k, span in enumerate(ranges):
        if span.integer:
            count = span.high - span.low + 1.0
            out[span.name] = np.minimum(span.low + np.floor(unit[:, k] * count), span.high)
        else:
            out[span.name] = span.low + unit[:, k] * (span.high - span.low)
    return out


def candidate(base: Design, values: Mapping[str, float]) -> Design:
    """``base`` with the free fields set (``L`` through ``w_t``, or ``w_tip`` when
    ``N = 1``); an impossible combination raises :class:`InvalidDesignError`."""
    fields = {name: int(value) if name == "N" else float(value)
              for name, value in values.items() if name != "L"}
    if "L" in values:
        design = base.with_overrides(**fields)
        w_n = design.uniform("w_n", "a design search over L")
        rest = values["L"] - design.w_base - design.N * w_n - design.w_tip
        if design.N == 1:
            fields["w_tip"] = values["L"] - design.w_base - w_n
        else:
            fields["w_t"] = rest / (design.N - 1)
        for name in ("w_t", "w_tip"):
            if name in fields and fields[name] < 0.0:
                raise out_of_range(name, fields[name], f"0 or [{MIN_SEGMENT_M:g}, 1] m (set by "
                                   f"L = {values['L']:g} m)", error=InvalidDesignError)
    return base.with_overrides(**fields)
