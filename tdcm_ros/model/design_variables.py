"""The free variables of a shape design: design fields varied per notch, by a law along the
body, or as one number (SI units).

A :class:`Variable` frees one field of the base :class:`~tdcm_ros.model.design.Design`:

- per notch (``w_n``, ``w_d``, ``cut``) or per gap between notches (``w_t``), by a ``law``:
  ``each`` (one variable per notch or gap, base to tip), ``uniform`` (one value for all),
  ``linear`` (two: the values at the first and the last, linear in between) or ``quadratic``
  (three: first, middle, last; the parabola through them over the notch index);
- ``cut`` is a one-sided cut's depth from +x (m): it sets the notch's backbone ``w_d = 2
  R_outer - cut`` and offset ``w_o = -cut / 2``, so the material left is the tube's ``-x`` side;
- one number (law ``uniform``): the tube's ``R_outer`` and ``r_inner``, the tendon offset
  ``R_c`` (with one tendon; its ``offset`` follows), ``E`` (the material's modulus, Pa), and
  ``w_base``, ``w_tip``.

Each variable has a closed range ``[low, high]``; a law's values (its ends and middle) each
take that range, and the values it interpolates stay inside it. :class:`VariableSet` maps a
vector of every variable (in order) to a design: fields not freed come from the base.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.model.design import Design
from tdcm_ros.model.errors import InvalidDesignError

Array = NDArray[np.float64]

#: Fields with one value per notch, and ``cut`` (a one-sided cut's depth, m).
NOTCH_FIELDS = ("w_n", "w_d", "cut")
#: Fields with one value per gap between adjacent notches.
GAP_FIELDS = ("w_t",)
#: Fields with one value for the body.
SCALAR_FIELDS = ("R_outer", "r_inner", "R_c", "E", "w_base", "w_tip")
FIELDS = NOTCH_FIELDS + GAP_FIELDS + SCALAR_FIELDS
#: Laws over a per-notch or per-gap field, and the number of variables each takes.
LAWS = {"each": 0, "uniform": 1, "linear": 2, "quadratic": 3}
#: Largest value of a length variable (m) and of ``E`` (Pa).
MAX_LENGTH_M = 1.0
MAX_E_PA = 1e12


@dataclass(frozen=True)
class Variable:
    """One freed field: ``field`` (:data:`.FIELDS`), its ``law`` (:data:`.LAWS`; ``uniform`` for a
    scalar field) and its range ``[low, high]`` (m, or Pa for ``E``)."""

    field: str
    low: float
    high: float
    law: str = "uniform"

    def __post_init__(self) -> None:
        if self.field not in FIELDS:
            raise out_of_range("vary.field", self.field, ", ".join(FIELDS),
                               error=InvalidDesignError)
        if self.law not in LAWS:
            raise out_of_range(f"vary[{self.field}].law", self.law, ", ".join(LAWS),
                               error=InvalidDesignError)
        if self.field in SCALAR_FIELDS and self.law != "uniform":
            raise out_of_range(f"vary[{self.field}].law", self.law,
                               "uniform (one value for the body)", error=InvalidDesignError)
        top = MAX_E_PA if self.field == "E" else MAX_LENGTH_M
        for end in ("low", "high"):
            value = getattr(self, end)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                    not math.isfinite(value) or not 0.0 <= value <= top:
                raise out_of_range(f"vary[{self.field}].{end}", value, f"[0, {top:g}]",
                                   unit="Pa" if self.field == "E" else "m",
                                   error=InvalidDesignError)
        if not self.low < self.high:
            raise out_of_range(f"vary[{self.field}].high", self.high,
                               f"above low = {self.low:g}", error=InvalidDesignError)

    def count(self, notches: int) -> int:
        """Variables this field takes on a body of ``notches`` notches."""
        if self.law != "each":
            return LAWS[self.law]
        return notches if self.field in NOTCH_FIELDS else notches - 1

    def values(self, x: Array, notches: int) -> tuple[float, ...]:
        """The field's value per notch (or gap), base to tip, from its variables ``x``."""
        size = notches if self.field in NOTCH_FIELDS else notches - 1
        if self.law == "each":
            return tuple(float(v) for v in x)
        if self.law == "uniform":
            return (float(x[0]),) * size
        u = np.linspace(0.0, 1.0, size) if size > 1 else np.zeros(1)
        if self.law == "linear":
            out = x[0] + (x[1] - x[0]) * u
        else:  # quadratic through (0, x0), (1/2, x1), (1, x2)
            out = (x[0] * (2.0 * u - 1.0) * (u - 1.0) - 4.0 * x[1] * u * (u - 1.0)
                   + x[2] * u * (2.0 * u - 1.0))
        return tuple(float(v) for v in np.clip(out, self.low, self.high))

    @property
    def name(self) -> str:
        """``field`` or ``field~law`` (a per-notch field's law)."""
        return self.field if self.field in SCALAR_FIELDS else f"{self.field}~{self.law}"


@dataclass(frozen=True)
class VariableSet:
    """The variables of a search over ``base`` (see the module docstring)."""

    base: Design
    variables: tuple[Variable, ...]

    def __post_init__(self) -> None:
        if not self.variables:
            raise InvalidDesignError("vary lists no field; allowed: one or more of "
                                     + ", ".join(FIELDS), parameter="vary", value=[],
                                     allowed="a non-empty list")
        seen = set()
        for variable in self.variables:
            key = "w_d" if variable.field == "cut" else variable.field
            if key in seen:
                raise out_of_range("vary.field", variable.field, "each field once (cut and "
                                   "w_d both set the backbone)", error=InvalidDesignError)
            seen.add(key)
            if variable.field in GAP_FIELDS and self.base.N < 2:
                raise out_of_range("vary.field", variable.field, "a per-notch field (w_t "
                                   "needs 2 or more notches)", error=InvalidDesignError)
            if variable.field == "R_c" and len(self.base.tendons) > 1:
                raise out_of_range("vary.field", "R_c", "a body with one tendon",
                                   error=InvalidDesignError)

    @property
    def size(self) -> int:
        """Length of the vector :meth:`design` takes."""
        return sum(v.count(self.base.N) for v in self.variables)

    def bounds(self) -> Array:
        """``(size, 2)``: each variable's ``[low, high]``."""
        return np.array([(v.low, v.high) for v in self.variables
                         for _ in range(v.count(self.base.N))], dtype=float)

    def names(self) -> tuple[str, ...]:
        """Each variable's name: ``field``, ``field[i]`` (law ``each``, 0-based from the base)
        or ``field~law[j]``."""
        out: list[str] = []
        for v in self.variables:
            n = v.count(self.base.N)
            out += [v.field] if v.field in SCALAR_FIELDS else [
                f"{v.field}[{j}]" if v.law == "each" else f"{v.name}[{j}]" for j in range(n)]
        return tuple(out)

    def fields(self, x: Sequence[float] | Array) -> dict[str, Any]:
        """The design fields the vector ``x`` sets (SI units)."""
        x = np.asarray(x, dtype=float)
        if x.shape != (self.size,):
            raise out_of_range("x", x.shape, f"shape ({self.size},)", error=InvalidDesignError)
        out: dict[str, Any] = {}
        start = 0
        for v in self.variables:
            part = x[start:start + v.count(self.base.N)]
            start += part.size
            if v.field in SCALAR_FIELDS:
                out[v.field] = float(part[0])
            else:
                out[v.field] = v.values(part, self.base.N)
        return out

    def design(self, x: Sequence[float] | Array) -> Design:
        """The base design with the fields of ``x`` set; an impossible combination (e.g. a cut
        deeper than the tube) raises :class:`InvalidDesignError`."""
        fields = self.fields(x)
        base = self.base
        cut = fields.pop("cut", None)
        if cut is not None:
            r_outer = fields.get("R_outer", base.R_outer)
            fields["w_d"] = tuple(2.0 * r_outer - c for c in cut)
            fields["w_o"] = tuple(-c / 2.0 for c in cut)
        if "R_c" in fields and base.tendons:
            first = base.tendons[0]
            offset = math.copysign(fields["R_c"], first.offset)
            fields["tendons"] = (replace(first, offset=offset), *base.tendons[1:])
        return replace(base, **fields)
