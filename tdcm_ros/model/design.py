"""The TD-CM design: every geometric and material parameter of the paper, in SI units.

Geometry (eq. 1): ``L = w_base + N w_n + (N-1) w_t + w_tip``; notch ``i`` (1-based) spans
``[l_i, r_i]`` with ``l_i = w_base + (i-1)(w_n + w_t)`` and ``r_i = l_i + w_n``.

Per notch: ``w_n``, ``w_d`` and ``w_o`` may be N values (notch ``i``'s width, backbone and
backbone offset, base to tip) and ``w_t`` N - 1 values (the tube after notch ``i``); then ``l_i`` is the sum of the
segments before notch ``i``. A list whose values are all equal is stored as that one value, so
an evenly spaced, identical pattern is the uniform design whichever way it is written.

``w_o`` moves a notch's backbone off the tube axis: the material left is the tube where
``w_o - h1 <= x <= w_o + h1`` (``h1`` the profile's half-width, ``w_d / 2`` at the notch centre;
``x`` toward the tendon). 0 is the paper's symmetric pair of cuts; ``w_o = -(R_outer - w_d/2)``
leaves the tube's ``-x`` side whole: a one-sided cut of depth ``2 R_outer - w_d`` from ``+x``.

``E`` defaults to 1.85 GPa (Formlabs Nylon 12 powder datasheet, tensile modulus). Thin SLS
features are often softer: treat ``E`` as a calibration parameter (``tdcm calibrate``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range, reject_unknown
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.material import Material
from tdcm_ros.model.profiles import (
    GIVEN_SECTION_PROFILES,
    PRISMATIC_PROFILES,
    PROFILE_NAMES,
    CircularProfile,
    NotchProfile,
    PolygonProfile,
    SectionProfile,
    SlicedProfile,
    profile_from_name,
)
from tdcm_ros.model.section import tube_moment
from tdcm_ros.model.sections import OFFSET_SLACK, open_faces
from tdcm_ros.model.tendons import Tendon, check_tendons
from tdcm_ros.spec import Spec, check_fields, spec_field, specs_of, spelled_as

MM = 1e-3
#: Shortest segment (m): ``w_n`` is at least this, ``w_base``, ``w_t`` and ``w_tip`` are 0 (absent)
#: or at least this, so no cell is negligible against the arc lengths it sits between.
MIN_SEGMENT_M = 1e-6
#: Fields a design may derive from its notch sections (:meth:`Design.derived_fields`).
DERIVABLE_FIELDS = frozenset({"profile", "w_d", "w_o", "R_c"})
#: Fields that may hold one value per notch (base to tip).
PER_NOTCH_FIELDS = ("w_n", "w_d", "w_o")
#: Fields that may hold one value per gap between adjacent notches (base to tip).
PER_GAP_FIELDS = ("w_t",)
#: A length (m): one value, or one per notch or gap (see the module docstring).
Lengths = float | tuple[float, ...]
#: Notch profiles whose section carries no width profile to integrate a material law over.
_WIDTHLESS_PROFILES = (SectionProfile, SlicedProfile)


def uniform_length(w_base: Any, n: Any, w_n: Any, w_t: Any, w_tip: Any) -> Any:
    """Eq. 1's total length ``L`` (m) of a uniform design (``n`` notches of width ``w_n``,
    tubes ``w_t`` between them, m), of floats or of arrays of many designs (the same
    floating-point operations either way)."""
    return w_base + n * w_n + (n - 1) * w_t + w_tip

@dataclass(frozen=True)
class Design:
    """A notched TD-CM design in SI units (m, Pa), validated on construction."""

    w_base: float = spec_field(unit="m", description="length of the proximal tube segment",
                               low=0.0, high=1.0)
    w_tip: float = spec_field(unit="m", description="length of the distal tube segment",
                              low=0.0, high=1.0)
    w_n: float | tuple[float, ...] = spec_field(
        unit="m", description="notch width along the body (per notch: a list in Python and "
        "--set, or a body file)", low=MIN_SEGMENT_M, high=1.0, kind="float")
    w_t: float | tuple[float, ...] = spec_field(
        unit="m", description="tube length between adjacent notches (per gap: a list in Python "
        "and --set, or a body file)", low=0.0, high=1.0, kind="float")
    w_d: float | tuple[float, ...] = spec_field(
        unit="m", description="backbone width (minimum, at the notch centre; per notch: a list "
        "in Python and --set, or a body file)", low=0.0, high=1.0, low_open=True, kind="float")
    N: int = spec_field(kind="int", description="number of notches", low=1, high=1000)
    R_outer: float = spec_field(unit="m", description="outer radius of the tube", low=0.0,
                                high=0.5, low_open=True)
    r_inner: float = spec_field(unit="m", description="inner radius of the tube (0 for a solid rod)",
                                low=0.0, high=0.5)
    R_c: float = spec_field(unit="m", description="tendon offset from the midline, on the +x side",
                            low=0.0, high=0.5, low_open=True)
    E: float = spec_field(1.85e9, unit="Pa", description="Young's modulus (calibration parameter)",
                          low=0.0, high=1e12, low_open=True)
    w_o: float | tuple[float, ...] = spec_field(
        0.0, unit="m", description="backbone offset toward the tendon (+x) from the tube axis; 0: "
        "the paper's symmetric notch, -(R_outer - w_d/2): a one-sided cut from +x (per notch: "
        "a list in Python and --set, or a body file)", low=-0.5, high=0.5, kind="float")
    profile: NotchProfile | tuple[NotchProfile, ...] = field(default_factory=CircularProfile)
    tendons: tuple[Tendon, ...] = ()
    """Several tendons, or one off the paper's (:mod:`tdcm_ros.model.tendons`); empty: the
    paper's one tendon at ``R_c`` on +x. With a list, ``R_c`` is the first one's ``|offset|``."""
    material: Material = field(default_factory=Material)
    """The material law (:mod:`tdcm_ros.model.material`; default linear, modulus ``E``)."""

    def __post_init__(self) -> None:
        check_fields(self, {k: v for k, v in FIELD_SPECS.items() if k not in _LISTABLE},
                     error=InvalidDesignError)
        for name in _LISTABLE:
            object.__setattr__(self, name, _lengths(name, getattr(self, name), self._count(name)))
        object.__setattr__(self, "profile", _profiles(self.profile, self.N))
        self._take_prismatic_extents()
        self._check_cross_fields()
        if not isinstance(self.material, Material):
            raise out_of_range("material", self.material, "a Material", error=InvalidDesignError)
        self.material.check(self.E)
        if not self.material.is_linear and any(
                isinstance(p, _WIDTHLESS_PROFILES) for p in self.notch_profiles()):
            raise InvalidDesignError(
                f"material.law = {self.material.law!r} takes band, cut and polygon notches (the "
                "law is integrated over their sections' widths; a section given by its numbers or "
                "a mesh's slices has none); allowed: law linear with section or mesh notches",
                parameter="material.law", value=self.material.law, allowed="linear")
        if self.tendons != ():
            object.__setattr__(self, "tendons", check_tendons(
                self.tendons, self.R_outer, self.segment_ends()))
            if self.R_c != abs(self.tendons[0].offset):
                raise out_of_range("R_c", self.R_c, f"{abs(self.tendons[0].offset):g} m (the "
                                   "first tendon's |offset| where tendons are listed)",
                                   error=InvalidDesignError)

    def tendon_list(self) -> tuple[Tendon, ...]:
        """The design's tendons: its list, or the paper's one at ``R_c`` on +x, to the tip."""
        return self.tendons if self.tendons else (Tendon(self.R_c, name="tendon_1"),)

    def _take_prismatic_extents(self) -> None:
        """Set ``w_d`` and ``w_o`` of each notch whose section is given (a polygon, a section's
        numbers or a mesh's slices) to its extent in ``x`` and that extent's middle (m), after
        checking a prismatic one (a polygon: simple, of positive area, its vertices within
        ``R_outer`` of the axis)."""
        given = [(i, p) for i, p in enumerate(self.notch_profiles())
                 if isinstance(p, GIVEN_SECTION_PROFILES)]
        if not given:
            return
        w_d, w_o = self.per_notch("w_d"), self.per_notch("w_o")
        for i, profile in given:
            where = f"profile[{i}]" if isinstance(self.profile, tuple) else "profile"
            try:
                if isinstance(profile, PRISMATIC_PROFILES):
                    profile.section(self.R_outer)
            except InvalidDesignError as error:
                raise InvalidDesignError(f"{where}: {error}", parameter=where,
                                         value=error.value, allowed=error.allowed) from error
            if isinstance(profile, PolygonProfile):
                profile.check_inside(self.R_outer, f"{where} (polygon)")
            if isinstance(profile, SlicedProfile) and not math.isclose(
                    float(self.per_notch("w_n")[i]), profile.width, rel_tol=1e-12):
                name = f"w_n[{i}]" if isinstance(self.w_n, tuple) else "w_n"
                raise out_of_range(name, float(self.per_notch("w_n")[i]),
                                   f"{profile.width:g} m (the width of the notch's slices)",
                                   error=InvalidDesignError)
            low, high = profile.x_extent()
            w_d[i], w_o[i] = high - low, 0.5 * (high + low)
        for name, values in (("w_d", w_d), ("w_o", w_o)):
            object.__setattr__(self, name, _lengths(name, values.tolist(), self.N))

    def _check_cross_fields(self) -> None:
        """Ranges that depend on other fields: radii inside ``R_outer`` (m), the backbone
        narrower than the tube and inside it (``|w_o| <= R_outer - w_d/2``), and tube segments absent or at least ``MIN_SEGMENT_M`` long."""
        diameter = 2.0 * self.R_outer
        below = (("r_inner", self.R_outer, f"[0, R_outer = {self.R_outer:g}) m"),
                 ("R_c", self.R_outer if self.tendons == () else math.inf,
                  f"(0, R_outer = {self.R_outer:g}) m"),
                 ("w_d", diameter, f"(0, 2 R_outer = {diameter:g}) m"))
        given = [isinstance(p, GIVEN_SECTION_PROFILES) for p in self.notch_profiles()]
        for name, limit, allowed in below:
            for index, (where, value) in enumerate(_entries(name, getattr(self, name))):
                # a section given whole (a rod between disks) may fill the tube's width
                fills = name == "w_d" and (all(given) if where == name else given[index])
                if value > limit or (value == limit and not fills):
                    raise out_of_range(where, value, allowed, error=InvalidDesignError)
        room = self.R_outer - 0.5 * self.per_notch("w_d")
        slack = OFFSET_SLACK * self.R_outer  # a cut's w_o = -(R_outer - w_d/2) to rounding
        for i in np.flatnonzero(np.abs(self.per_notch("w_o")) > room + slack)[:1]:
            where = f"w_o[{i}]" if isinstance(self.w_o, tuple) else "w_o"
            raise out_of_range(where, float(self.per_notch("w_o")[i]),
                               f"[-{room[i]:g}, {room[i]:g}] m (the backbone, w_d wide, inside "
                               "the tube: |w_o| <= R_outer - w_d/2)", error=InvalidDesignError)
        for name in ("w_base", "w_t", "w_tip"):
            for where, value in _entries(name, getattr(self, name)):
                if 0.0 < value < MIN_SEGMENT_M:
                    raise out_of_range(where, value, f"0 (no segment) or [{MIN_SEGMENT_M:g}, 1] m",
                                       error=InvalidDesignError)

    def derived_fields(self) -> frozenset[str]:
        """Fields this design does not take as values: ``profile`` unless every notch has a
        named one, and ``w_d``, ``w_o`` where a notch's section is given whole (a polygon or a
        section's numbers: they are its extent). Parameters, sweeps and searches leave them."""
        profiles = self.notch_profiles()
        derived = set()
        if any(p.name not in PROFILE_NAMES for p in profiles):
            derived.add("profile")  # each in DERIVABLE_FIELDS
        if any(isinstance(p, GIVEN_SECTION_PROFILES) for p in profiles):
            derived |= {"w_d", "w_o"}
        if self.tendons:
            derived.add("R_c")
        return frozenset(derived)

    def require_free(self, names: Sequence[str], what: str) -> None:
        """Raise :class:`InvalidDesignError` if ``what`` would vary a :meth:`derived_fields`
        field of this design (naming it)."""
        derived = self.derived_fields()
        for name in names:
            if name in derived:
                source = "tendons (the first one's |offset|)" if name == "R_c" else \
                    "notch sections (a polygon or a section given whole: its extent in x)"
                raise InvalidDesignError(
                    f"{what}: {name} is derived from this design's {source}; allowed: other "
                    "fields",
                    parameter=name, value=name, allowed="a field the design takes as a value")

    def open_faces(self) -> NDArray[np.bool_]:
        """Per notch (shape (2, N), base to tip): whether its faces can meet at the tube's outer
        surface on the +x side (row 0) and the -x side (row 1), i.e. whether the cut opens there
        (the section's material, ``w_o +- w_d/2`` at the notch centre, does not keep the wall:
        :func:`tdcm_ros.model.sections.keeps_wall`)."""
        return open_faces(self.per_notch("w_d"), self.per_notch("w_o"), self.R_outer)

    def _count(self, name: str) -> int:
        """How many values a per-notch (N) or per-gap (N - 1) field holds when it is a list."""
        return self.N if name in PER_NOTCH_FIELDS else self.N - 1

    @property
    def is_uniform(self) -> bool:
        """Whether every notch is the same and evenly spaced (no field holds a list)."""
        return not any(isinstance(getattr(self, name), tuple) for name in (*_LISTABLE, "profile"))

    def notch_profiles(self) -> tuple[NotchProfile, ...]:
        """Each notch's profile, base to tip, whether the design stores one or a list."""
        profile = self.profile
        return profile if isinstance(profile, tuple) else (profile,) * self.N

    def uniform_profile(self, what: str = "this") -> NotchProfile:
        """The profile where every notch has the same one; a list raises
        :class:`InvalidDesignError` saying that ``what`` takes one profile."""
        profile = self.profile
        if isinstance(profile, tuple):
            names = [p.name for p in profile]
            raise InvalidDesignError(
                f"profile = {names!r} holds one profile per notch; {what} takes one profile",
                parameter="profile", value=names, allowed="one profile")
        return profile

    def uniform(self, name: str, what: str = "this") -> float:
        """Field ``name`` (``w_n``, ``w_d``, ``w_o``, ``w_t``) where it holds one value (m); a per-notch
        list raises :class:`InvalidDesignError` saying that ``what`` takes one value."""
        value = getattr(self, name)
        if isinstance(value, tuple):
            raise InvalidDesignError(
                f"{name} = {list(value)!r} holds one value per notch; {what} takes a uniform "
                f"design (one {name})", parameter=name, value=list(value),
                allowed=f"one value of {name} (a uniform design)")
        return float(value)

    def per_notch(self, name: str) -> NDArray[np.float64]:
        """Field ``name`` (``w_n``, ``w_d``, ``w_o``: N values; ``w_t``: N - 1) as an array (m), base
        to tip, whether the design stores one value or a list."""
        value = getattr(self, name)
        return np.array(value, dtype=float) if isinstance(value, tuple) else np.full(
            self._count(name), float(value))

    @property
    def length(self) -> float:
        """Total length ``L`` (m), eq. 1 (sums of the per-notch values where there are lists)."""
        if self.is_uniform:
            return uniform_length(self.w_base, self.N, self.uniform("w_n"), self.uniform("w_t"),
                                  self.w_tip)
        return float(self._ends()[-1] + self.w_tip)

    def notch_bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Arrays ``(l, r)`` (m) of notch start and end arc lengths, eq. 1."""
        if self.is_uniform:
            w_n = self.uniform("w_n")
            i = np.arange(self.N, dtype=float)
            left = self.w_base + i * (w_n + self.uniform("w_t"))
            return left, left + w_n
        ends = self._ends()
        return ends[0::2], ends[1::2]

    def segment_ends(self) -> NDArray[np.float64]:
        """Arc lengths (m) where a segment ends, base to tip (no 0; the tip last)."""
        left, right = self.notch_bounds()
        ends = np.concatenate([left, right, [self.length]])
        return np.unique(ends[ends > 0.0])

    def _ends(self) -> NDArray[np.float64]:
        """``l_1, r_1, l_2, ..., r_N`` (m) of a per-notch design, summed segment by segment
        from the base, so that a notch right after another starts exactly where it ends."""
        lengths = np.zeros(2 * self.N)
        lengths[0] = self.w_base
        lengths[1::2] = self.per_notch("w_n")
        lengths[2::2] = self.per_notch("w_t")
        return np.cumsum(lengths)

    @property
    def tube_second_moment(self) -> float:
        """``I0`` of the uncut tube (m^4)."""
        return tube_moment(self.R_outer, self.r_inner)

    def with_overrides(self, **overrides: Any) -> Design:
        """A copy with fields replaced (validated); unknown names, and a field derived from the
        notch sections (:meth:`derived_fields`) unless ``profile`` is replaced too, raise
        :class:`InvalidDesignError`."""
        reject_unknown("design field", overrides, (f.name for f in fields(self)),
                       error=InvalidDesignError)
        if "profile" not in overrides and DERIVABLE_FIELDS.intersection(overrides):
            self.require_free(list(overrides), "with_overrides")
        return replace(self, **overrides)

    def to_dict(self) -> dict[str, Any]:
        """All fields in SI units (a per-notch field as a list), plus the derived length ``L``;
        the profile by name; ``tendons`` and ``material`` where they are not the paper's (a
        material's keys that are not finite left out: JSON has no inf or nan)."""
        data = {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()
                if k not in ("profile", "material") and (k != "tendons" or v)}
        if not self.material.is_trivial:
            data["material"] = {k: v for k, v in asdict(self.material).items()
                                if not isinstance(v, float) or math.isfinite(v)}
        profile = self.profile
        data["profile"] = [p.name for p in profile] if isinstance(profile, tuple) else profile.name
        data["L"] = self.length
        return data


#: Specs of the numeric design fields (all but ``profile``), by name.
FIELD_SPECS = specs_of(Design)
_LISTABLE = PER_NOTCH_FIELDS + PER_GAP_FIELDS
#: The specs of the per-notch and per-gap fields' lists (each entry in the field's range).
_LIST_SPECS = {name: replace(FIELD_SPECS[name], kind="list") for name in _LISTABLE}


def _lengths(name: str, value: Any, count: int) -> Lengths:
    """``value`` of the per-notch or per-gap field ``name`` checked (m): one number, or a list
    of ``count`` numbers each in the field's range; a list of equal values becomes that value."""
    spec = FIELD_SPECS[name]
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        return float(spec.check(value, error=InvalidDesignError))
    if count == 0 and len(value) == 0:
        return 0.0  # a one-notch design has no gaps
    items = _LIST_SPECS[name].check(list(value), error=InvalidDesignError)
    if len(items) != count:
        what = "notch" if name in PER_NOTCH_FIELDS else "gap between notches"
        raise out_of_range(name, list(items), f"one number, or {count} numbers (one per {what}:"
                           f" N = {count if what == 'notch' else count + 1})",
                           error=InvalidDesignError)
    return items[0] if all(v == items[0] for v in items) else tuple(items)


def _profiles(value: Any, count: int) -> NotchProfile | tuple[NotchProfile, ...]:
    """``value`` as a notch profile (a name or a profile), or a list of ``count`` of them (one
    per notch); a list of equal profiles becomes that profile."""
    def one(item: Any, where: str) -> NotchProfile:
        if isinstance(item, str):
            return profile_from_name(item)
        if not hasattr(item, "h1"):
            raise InvalidDesignError(
                f"{where} = {item!r} is not a notch profile; allowed: circular, rectangular, "
                "CustomProfile(h1) or PolygonProfile(shell)", parameter=where, value=item,
                allowed="circular | rectangular | CustomProfile | PolygonProfile")
        return item

    if isinstance(value, (list, tuple)):
        if len(value) != count:
            raise out_of_range("profile", [getattr(p, "name", p) for p in value],
                               f"one profile, or {count} (one per notch: N = {count})",
                               error=InvalidDesignError)
        items = tuple(one(item, f"profile[{i}]") for i, item in enumerate(value))
        return items[0] if all(item == items[0] for item in items) else items
    return one(value, "profile")


def _entries(name: str, value: Any) -> list[tuple[str, float]]:
    """``(name, value)``, or ``(name[i], value_i)`` for each entry of a per-notch list."""
    if isinstance(value, tuple):
        return [(f"{name}[{i}]", float(v)) for i, v in enumerate(value)]
    return [(name, float(value))]


#: The design as node parameters (``design.<name>``): every numeric field and the profile by name.
PARAMETER_SPECS = {**FIELD_SPECS, "profile": Spec(
    "profile", description="notch profile", default="circular", kind="str",
    choices=PROFILE_NAMES)}


def parameter_specs(design: Design) -> dict[str, Spec]:
    """:data:`PARAMETER_SPECS` that can hold ``design``'s values: all but the fields it holds
    per notch (a body file's per-notch values are read from the file, not from parameters) and
    its :meth:`~Design.derived_fields`."""
    derived = design.derived_fields()
    return {k: v for k, v in PARAMETER_SPECS.items()
            if not isinstance(getattr(design, k, None), tuple) and k not in derived}


def parse_field(name: str, text: str) -> Any:
    """Parse a ``NAME=VALUE`` override value from text in SI units (``N`` as an integer)."""
    if name == "profile":
        stripped = text.strip()
        if stripped.startswith("[") and stripped.endswith("]"):
            return [part.strip() for part in stripped[1:-1].split(",") if part.strip()]
        return text
    spec = FIELD_SPECS.get(name)
    if spec is None:
        allowed = ", ".join([*FIELD_SPECS, "profile"])
        raise InvalidDesignError(f"unknown design field {name!r}; allowed: {allowed}",
                                 parameter=name, value=text, allowed=allowed)
    stripped = text.strip()
    if name in _LIST_SPECS and stripped.startswith("[") and stripped.endswith("]"):
        return _LIST_SPECS[name].parse(stripped[1:-1], name, error=InvalidDesignError)
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
