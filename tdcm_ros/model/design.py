"""The TD-CM design: every geometric and material parameter of the paper, in SI units.

Geometry (eq. 1): ``L = w_base + N w_n + (N-1) w_t + w_tip``; notch ``i`` (1-based) spans
``[l_i, r_i]`` with ``l_i = w_base + (i-1)(w_n + w_t)`` and ``r_i = l_i + w_n``.

``E`` defaults to 1.85 GPa (Formlabs Nylon 12 powder datasheet, tensile modulus). Thin SLS
features are often softer: treat ``E`` as a calibration parameter (``tdcm calibrate``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range, reject_unknown
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.profiles import (
    PROFILE_NAMES,
    CircularProfile,
    NotchProfile,
    profile_from_name,
)
from tdcm_ros.model.section import tube_moment
from tdcm_ros.spec import Spec, check_fields, spec_field, specs_of, spelled_as

MM = 1e-3
#: Shortest segment (m): ``w_n`` is at least this, ``w_base``, ``w_t`` and ``w_tip`` are 0 (absent)
#: or at least this, so no cell is negligible against the arc lengths it sits between.
MIN_SEGMENT_M = 1e-6


@dataclass(frozen=True)
class Design:
    """A notched TD-CM design in SI units (m, Pa), validated on construction."""

    w_base: float = spec_field(unit="m", description="length of the proximal tube segment",
                               low=0.0, high=1.0)
    w_tip: float = spec_field(unit="m", description="length of the distal tube segment",
                              low=0.0, high=1.0)
    w_n: float = spec_field(unit="m", description="notch width along the body",
                            low=MIN_SEGMENT_M, high=1.0)
    w_t: float = spec_field(unit="m", description="tube length between adjacent notches",
                            low=0.0, high=1.0)
    w_d: float = spec_field(unit="m", description="backbone width (minimum, at the notch centre)",
                            low=0.0, high=1.0, low_open=True)
    N: int = spec_field(kind="int", description="number of notches", low=1, high=1000)
    R_outer: float = spec_field(unit="m", description="outer radius of the tube", low=0.0,
                                high=0.5, low_open=True)
    r_inner: float = spec_field(unit="m", description="inner radius of the tube (0 for a solid rod)",
                                low=0.0, high=0.5)
    R_c: float = spec_field(unit="m", description="tendon offset from the midline, on the +x side",
                            low=0.0, high=0.5, low_open=True)
    E: float = spec_field(1.85e9, unit="Pa", description="Young's modulus (calibration parameter)",
                          low=0.0, high=1e12, low_open=True)
    profile: NotchProfile = field(default_factory=CircularProfile)

    def __post_init__(self) -> None:
        check_fields(self, FIELD_SPECS, error=InvalidDesignError)
        self._check_cross_fields()
        if not hasattr(self.profile, "h1"):
            raise InvalidDesignError(
                f"profile = {self.profile!r} is not a notch profile; allowed: circular, "
                "rectangular, or CustomProfile(h1)", parameter="profile", value=self.profile,
                allowed="circular | rectangular | CustomProfile")

    def _check_cross_fields(self) -> None:
        """Ranges that depend on other fields: radii inside ``R_outer`` (m), the backbone
        narrower than the tube, and tube segments absent or at least ``MIN_SEGMENT_M`` long."""
        diameter = 2.0 * self.R_outer
        below = (("r_inner", self.R_outer, f"[0, R_outer = {self.R_outer:g}) m"),
                 ("R_c", self.R_outer, f"(0, R_outer = {self.R_outer:g}) m"),
                 ("w_d", diameter, f"(0, 2 R_outer = {diameter:g}) m"))
        for name, limit, allowed in below:
            if getattr(self, name) >= limit:
                raise out_of_range(name, getattr(self, name), allowed, error=InvalidDesignError)
        for name in ("w_base", "w_t", "w_tip"):
            value = getattr(self, name)
            if 0.0 < value < MIN_SEGMENT_M:
                raise out_of_range(name, value, f"0 (no segment) or [{MIN_SEGMENT_M:g}, 1] m",
                                   error=InvalidDesignError)

    @property
    def length(self) -> float:
        """Total length ``L`` (m), eq. 1."""
        return self.w_base + self.N * self.w_n + (self.N - 1) * self.w_t + self.w_tip

    def notch_bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Arrays ``(l, r)`` (m) of notch start and end arc lengths, eq. 1."""
        i = np.arange(self.N, dtype=float)
        left = self.w_base + i * (self.w_n + self.w_t)
        return left, left + self.w_n

    @property
    def tube_second_moment(self) -> float:
        """``I0`` of the uncut tube (m^4)."""
        return tube_moment(self.R_outer, self.r_inner)

    def with_overrides(self, **overrides: Any) -> Design:
        """A copy with fields replaced (validated); unknown names raise :class:`InvalidDesignError`."""
        reject_unknown("design field", overrides, (f.name for f in fields(self)),
                       error=InvalidDesignError)
        if isinstance(overrides.get("profile"), str):
            overrides["profile"] = profile_from_name(overrides["profile"])
        return replace(self, **overrides)

    def to_dict(self) -> dict[str, Any]:
        """All fields in SI units, plus the derived length ``L``; the profile by name."""
        data = {k: v for k, v in asdict(self).items() if k != "profile"}
        data["profile"] = self.profile.name
        data["L"] = self.length
        return data


#: Specs of the numeric design fields (all but ``profile``), by name.
FIELD_SPECS = specs_of(Design)
#: The design as node parameters (``design.<name>``): every numeric field and the profile by name.
PARAMETER_SPECS = {**FIELD_SPECS, "profile": Spec(
    "profile", description="notch profile", default="circular", kind="str",
    choices=PROFILE_NAMES)}


def parse_field(name: str, text: str) -> Any:
    """Parse a ``NAME=VALUE`` override value from text in SI units (``N`` as an integer)."""
    if name == "profile":
        return text
    spec = FIELD_SPECS.get(name)
    if spec is None:
        allowed = ", ".join([*FIELD_SPECS, "profile"])
        raise InvalidDesignError(f"unknown design field {name!r}; allowed: {allowed}",
                                 parameter=name, value=text, allowed=allowed)
    return spec.parse(text, error=InvalidDesignError)


def _simulation_design(w_n_mm: float, w_d_mm: float) -> Design:
    """Sec. III-A designs: L = 53 mm, w_base = 5, N = 8, w_t = w_tip = 6 - w_n (mm)."""
    w_t = 6.0 - w_n_mm
    return Design(w_base=5 * MM, w_tip=w_t * MM, w_n=w_n_mm * MM, w_t=w_t * MM, w_d=w_d_mm * MM,
                  N=8, R_outer=3.92 * MM, r_inner=1.55 * MM, R_c=2.75 * MM)


PRESETS: dict[str, Design] = {
    "paper-experiment": Design(w_base=5 * MM, w_tip=4 * MM, w_n=2 * MM, w_t=4 * MM, w_d=1.4 * MM,
                               N=8, R_outer=3.92 * MM, r_inner=1.55 * MM, R_c=2.75 * MM),
    "fig2-wn-1": _simulation_design(1.0, 1.5),
    "fig2-wn-1.9": _simulation_design(1.9, 1.5),
    "fig2-wn-2.5": _simulation_design(2.5, 1.5),
    "fig3-wd-1.2": _simulation_design(1.5, 1.2),
    "fig3-wd-1.52": _simulation_design(1.5, 1.52),
    "fig3-wd-2": _simulation_design(1.5, 2.0),
}


def preset(name: str) -> Design:
    """A named design: ``paper-experiment`` (Sec. III-B) or a Sec. III-A figure design
    (``-`` and ``_`` are the same in names: ``paper_experiment`` works too)."""
    known = spelled_as(name, PRESETS) if isinstance(name, str) else None
    if known is None:
        raise InvalidDesignError(
            f"unknown design preset {name!r}; allowed: {', '.join(PRESETS)}",
            parameter="design", value=name, allowed=", ".join(PRESETS))
    return PRESETS[known]
