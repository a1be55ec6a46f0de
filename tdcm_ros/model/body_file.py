"""Body files: a TD-CM described in YAML as a row of segments from base to tip (SI units).

::

    tube: {R_outer: 3.92e-3, r_inner: 1.55e-3}     # m
    material: {E: 1.85e9}                         # Pa
    tendons:                                      # one or more
      - {offset: 2.75e-3, routing: paper}         # m from the tube axis, + on the +x side
    segments:                                     # base to tip
      - tube: 5.0e-3                              # a plain tube of this length (m)
      - repeat: 8                                 # these segments, 8 times
        segments:
          - notch: {width: 2.0e-3, band: 1.4e-3, profile: circular}
          - tube: 4.0e-3

A notch has a ``width`` along the body (m) and one section: ``band`` (the paper's symmetric
pair of cuts leaving a backbone this wide, m, centred on the tube axis or ``offset`` from it
toward +x, m; ``profile`` circular (default) or rectangular), ``cut`` (a one-sided cut from +x,
this deep from the surface, m: a band ``2 R_outer - cut`` wide at ``offset = -cut/2``;
``profile`` rectangular (default) or circular, the cut's outline along the body) or ``polygon``
(the material left, a list of ``[x, y]`` in m, with optional ``holes``) or ``section`` (given by
its numbers: ``area`` m^2, ``centroid_x`` m, ``second_moment`` about the centroid m^4, the
material's extent ``x_low``..``x_high`` m; prismatic like a polygon). Instead of ``tube`` and
``segments``, ``mesh: {file: body.stl, unit: mm}`` gives the body as a triangle mesh (relative
to the body file's folder), sliced into its tube and prismatic notches by
:mod:`tdcm_ros.model.mesh_body`. Every problem is an
:class:`~tdcm_ros.model.errors.InvalidDesignError` naming the key by its path in the file
(``segments[1].segments[0].notch.cut``), the value and the allowed range.

A tendon has a signed ``offset`` (m, + on the +x side, - on the -x side), a ``routing``
(``paper``: following the body in the notches, chords across the tubes; ``free``: the
reverse; default the solver's, ``paper``), an ``anchor`` (m from the base, at a segment
boundary; default the tip), ``guides`` (``internal``: through the wall, ``|offset| <
R_outer``; ``external``: through guides such as disks, any offset up to 0.5 m) and a ``name``
(default ``tendon_1``, ``tendon_2``, ...: :mod:`tdcm_ros.model.tendons`). The solver takes one
tension per tendon.

A *model file* is a body file with what a calibration adds (:class:`~tdcm_ros.model.ModelSpec`):
``friction: {mu: 0.3}`` (the capstan coefficient tendon/channel) and ``uncertainty`` (the fitted
``parameters``, their ``values``, ``covariance`` and the fit's ``residual_m``).

The solver takes band, cut and polygon notches, each with its own width and section, any
tubes between them, and the tendons: :meth:`.BodySpec.design` gives that
:class:`~tdcm_ros.model.design.Design` (per-notch values where the notches differ; a polygon
notch is a :class:`~tdcm_ros.model.profiles.PolygonProfile`, prismatic along the body).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tdcm_ros.errors import out_of_range, reject_unknown
from tdcm_ros.model.design import MIN_SEGMENT_M, OFFSET_SLACK, Design, preset
from tdcm_ros.model.errors import InvalidDesignError
from tdcm_ros.model.loading import MAX_MU
from tdcm_ros.model.material import LAWS, Material
from tdcm_ros.model.profiles import (
    PROFILE_NAMES,
    NotchProfile,
    PolygonProfile,
    PrismaticProfile,
    SectionProfile,
    SlicedProfile,
    profile_from_name,
)
from tdcm_ros.model.sections import BandSection, OneSidedCut, PolygonSection, Section
from tdcm_ros.model.settings import ROUTINGS
from tdcm_ros.model.tendons import (
    GUIDES,
    MAX_EXTERNAL_OFFSET_M,
    MAX_SLACK_M,
    MAX_STIFFNESS_N_PER_M,
    MAX_TENDONS,
    Tendon,
)
from tdcm_ros.model.uncertainty import InvalidUncertaintyError, ParameterCovariance
from tdcm_ros.spec import Spec
from tdcm_ros.yamlio import load_yaml

#: Most segments a body may expand to (``repeat`` included).
MAX_SEGMENTS = 10_000
#: A tendon's name: a ROS name token (it names its joint and topic).
NAME_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
SECTION_KEYS = ("band", "cut", "polygon", "section")
#: Keys of a section given by its numbers (SI units).
GIVEN_SECTION_KEYS = ("area", "centroid_x", "second_moment", "x_low", "x_high")
#: A notch's profile where the file names none: the paper's circular band, a laser cut's
#: rectangular slot.
DEFAULT_PROFILE = {"band": "circular", "cut": "rectangular"}


@dataclass(frozen=True)
class TubeSpec:
    """A plain tube segment of ``length`` (m); ``where`` is its path in the file."""

    length: float
    where: str


@dataclass(frozen=True, eq=False)
class NotchSpec:
    """A notch segment: ``width`` along the body (m) and its section, one of ``band`` (backbone
    width, m, ``offset`` from the axis toward +x, m), ``cut`` (depth, m), ``polygon``
    (``shell``, ``holes``, m) or ``section`` (given by its numbers, or a mesh's slice:
    ``given``); a band or cut has a ``profile``."""

    width: float
    kind: str
    band: float = math.nan
    offset: float = 0.0
    profile: str = "circular"
    cut: float = math.nan
    shell: tuple[tuple[float, float], ...] = ()
    holes: tuple[tuple[tuple[float, float], ...], ...] = ()
    given: SectionProfile | SlicedProfile | None = None
    where: str = ""

    def section(self, r_outer: float, r_inner: float) -> Section:
        """The notch's section at its narrowest (the band's centre) as a section type (a band
        off the axis is checked by the design it makes)."""
        if self.kind == "band":
            return BandSection(self.band / 2.0, r_outer, r_inner)
        if self.kind == "cut":
            return OneSidedCut(self.cut, r_outer, r_inner)
        return PolygonSection(self.shell, r_outer, self.holes)

    def backbone(self, r_outer: float) -> float:
        """The width of the material left at the notch's centre (m): the band, the tube less
        the cut (``2 R_outer - cut``), or the polygon's extent in ``x``."""
        if self.kind in ("polygon", "section"):
            low, high = self.given_profile().x_extent()
            return high - low
        return 2.0 * r_outer - self.cut if self.kind == "cut" else self.band

    def given_profile(self) -> PrismaticProfile | SlicedProfile:
        """The section of a polygon notch, or one given by its numbers (or a mesh's slices)."""
        return self.given if self.given is not None else PolygonProfile(self.shell, self.holes)

    def profile_object(self) -> NotchProfile:
        """The notch's profile for the solver: the named one of a band or cut, the polygon or
        the mesh's slice."""
        if self.kind in ("polygon", "section"):
            return self.given_profile()
        return profile_from_name(self.profile)


Segment = TubeSpec | NotchSpec


@dataclass(frozen=True)
class BodySpec:
    """A body file's contents, checked (SI units): the tube, ``E`` (Pa), the tendons (their
    ``routing`` None where the file gives none) and the segments base to tip (``repeat``
    expanded)."""

    R_outer: float
    r_inner: float
    E: float
    tendons: tuple[Tendon, ...]
    segments: tuple[Segment, ...]
    source: str
    material: Material
    friction_mu: float = 0.0
    """A model file's capstan friction coefficient (0: none)."""
    uncertainty: ParameterCovariance | None = None
    """A model file's fitted parameters' covariance (None: none)."""

    @property
    def routing(self) -> str:
        """The solver's routing the file asks for: its first tendon's (``paper`` if none)."""
        return self.tendons[0].routing or "paper"

    @property
    def is_paper_tendon(self) -> bool:
        """Whether the file has the paper's one tendon: on +x, through the wall, to the tip."""
        only = self.tendons[0]
        return (len(self.tendons) == 1 and only.offset > 0.0 and only.anchor is None
                and only.guides == "internal" and only.name in ("", "tendon_1")
                and only.stiffness is None and only.slack == 0.0)

    def design(self) -> Design:
        """The body as the solver's :class:`Design`: a base tube (or none), N band, cut or
        polygon notches, each with its own width and section, a tube (or none) between adjacent
        notches and a tip tube (or none). A band off the axis past the tube's wall, or a polygon
        reaching outside the tube, raises :class:`InvalidDesignError` naming its segment."""
        merged = _merged_tubes(self.segments)
        notches = [s for s in merged if isinstance(s, NotchSpec)]
        if not notches:
            raise InvalidDesignError(f"{self.source}: segments has no notch; allowed: at least "
                                     "one", parameter="segments", value=0, allowed="[1, inf) notches")
        for notch in notches:
            if notch.kind == "polygon":  # named by its path here, not as the design's profile[i]
                PolygonProfile(notch.shell, notch.holes).check_inside(
                    self.R_outer, f"{self.source}: {notch.where}.polygon")
                continue
            room = self.R_outer - notch.backbone(self.R_outer) / 2.0
            if abs(notch.offset) > room + OFFSET_SLACK * self.R_outer:
                raise out_of_range(f"{self.source}: {notch.where}.offset", notch.offset,
                                   f"[-{room:g}, {room:g}] m (the band inside the tube: "
                                   "|offset| <= R_outer - band/2)", error=InvalidDesignError)
        head = merged[0].length if isinstance(merged[0], TubeSpec) else 0.0
        tail = merged[-1].length if isinstance(merged[-1], TubeSpec) else 0.0
        at = [k for k, segment in enumerate(merged) if isinstance(segment, NotchSpec)]
        gaps = tuple(after.length if isinstance(after := merged[k + 1], TubeSpec) else 0.0
                     for k in at[:-1])
        tendons = () if self.is_paper_tendon else self.tendons
        try:
            return Design(w_base=head, w_tip=tail, w_n=tuple(n.width for n in notches),
                          w_t=gaps, w_d=tuple(n.backbone(self.R_outer) for n in notches),
                          N=len(notches), w_o=tuple(n.offset for n in notches),
                          R_outer=self.R_outer, r_inner=self.r_inner,
                          R_c=abs(self.tendons[0].offset), E=self.E,
                          profile=tuple(n.profile_object() for n in notches), tendons=tendons,
                          material=self.material)
        except InvalidDesignError as error:
            if not (error.parameter or "").startswith(("tendons", "material")):
                raise
            raise InvalidDesignError(f"{self.source}: {error}", parameter=error.parameter,
                                     value=error.value, allowed=error.allowed) from error


def _merged_tubes(segments: Sequence[Segment]) -> list[Segment]:
    """Consecutive tubes joined into one (their lengths summed, the first one's path kept)."""
    out: list[Segment] = []
    for segment in segments:
        if isinstance(segment, TubeSpec) and out and isinstance(out[-1], TubeSpec):
            out[-1] = TubeSpec(out[-1].length + segment.length, out[-1].where)
        else:
            out.append(segment)
    return out


def read_body_file(path: str | Path) -> BodySpec:
    """The checked :class:`BodySpec` of the body file at ``path`` (read through the package's
    bounded YAML loader)."""
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise InvalidDesignError(f"cannot read body file {source}: {error}", parameter="design",
                                 value=source, allowed="a readable UTF-8 YAML file") from error
    return body_from_mapping(load_yaml(text, source, parameter="design",
                                       error=InvalidDesignError), source)


def body_from_mapping(data: Any, source: str = "body") -> BodySpec:
    """The checked :class:`BodySpec` of a body file's parsed YAML ``data``."""
    top = _mapping(data, "the body file", source)
    reject_unknown("body file key", top, ("tube", "material", "tendons", "segments", "mesh",
                                          "friction", "uncertainty"), error=InvalidDesignError)
    if "mesh" in top:
        for key in ("tube", "segments"):
            if key in top:
                raise InvalidDesignError(
                    f"{source}: {key} goes with segments, not with mesh (the mesh gives the tube "
                    "and the segments)", parameter=key, value=top[key],
                    allowed="mesh, or tube and segments")
        r_outer, r_inner, segments = _mesh(_mapping(top["mesh"], "mesh", source), source)
    else:
        tube = _mapping(_required(top, "tube", "", source), "tube", source)
        reject_unknown("tube key", tube, ("R_outer", "r_inner"), error=InvalidDesignError)
        r_outer = _number(tube, "R_outer", "tube.", source, low=0.0, high=0.5, open_low=True)
        r_inner = _number(tube, "r_inner", "tube.", source, low=0.0, high=r_outer,
                          open_high=True, default=0.0)
        segments = _segments(_required(top, "segments", "", source), "segments", source,
                             r_outer, r_inner)
    material = _mapping(_required(top, "material", "", source), "material", source)
    reject_unknown("material key", material, ("E", "law", "plateau_strain", "E_plateau",
                                              "recoverable_strain"), error=InvalidDesignError)
    modulus = _number(material, "E", "material.", source, low=0.0, high=1e12, open_low=True)
    law = material.get("law", "linear")
    if law not in LAWS:
        raise out_of_range(f"{source}: material.law", law, " | ".join(LAWS),
                           error=InvalidDesignError)
    bilinear = law == "bilinear"
    for key in ("plateau_strain", "E_plateau"):
        if (key in material) != bilinear:
            raise InvalidDesignError(
                f"{source}: material.{key} {'is missing' if bilinear else 'goes with law: '}"
                f"{'' if bilinear else 'bilinear'}; allowed: plateau_strain and E_plateau with law"
                " bilinear only", parameter=f"material.{key}", value=material.get(key),
                allowed="law: bilinear")
    law_of = Material(
        str(law),
        _number(material, "plateau_strain", "material.", source, low=0.0, high=1.0,
                open_low=True, open_high=True) if bilinear else math.inf,
        _number(material, "E_plateau", "material.", source, low=0.0, high=modulus,
                open_low=True) if bilinear else math.nan,
        _number(material, "recoverable_strain", "material.", source, low=0.0, high=1.0,
                open_low=True, default=math.inf) if "recoverable_strain" in material
        else math.inf)
    tendons = _tendons(_required(top, "tendons", "", source), source, r_outer)
    return BodySpec(R_outer=r_outer, r_inner=r_inner, E=modulus, tendons=tendons,
                    segments=tuple(segments), source=source, material=law_of,
                    friction_mu=_friction(top.get("friction"), source),
                    uncertainty=_uncertainty(top.get("uncertainty"), source))


def _friction(section: Any, source: str) -> float:
    """A model file's ``friction``: the capstan coefficient ``mu`` (0 without the section)."""
    if section is None:
        return 0.0
    friction = _mapping(section, "friction", source)
    reject_unknown("friction key", friction, ("mu",), error=InvalidDesignError)
    return _number(friction, "mu", "friction.", source, low=0.0, high=MAX_MU)


def _uncertainty(section: Any, source: str) -> ParameterCovariance | None:
    """A model file's ``uncertainty`` (``tdcm calibrate --out``): the fitted ``parameters``,
    their ``values``, ``covariance`` and the fit's ``residual_m``; None without the section."""
    if section is None:
        return None
    entry = _mapping(section, "uncertainty", source)
    reject_unknown("uncertainty key", entry, ("parameters", "values", "covariance",
                                              "residual_m"), error=InvalidDesignError)
    names = _list(_required(entry, "parameters", "uncertainty.", source),
                  "uncertainty.parameters", source)
    try:
        values = np.array(_required(entry, "values", "uncertainty.", source), dtype=float)
        covariance = np.array(_required(entry, "covariance", "uncertainty.", source),
                              dtype=float)
    except (TypeError, ValueError) as error:
        raise InvalidDesignError(f"{source}: uncertainty.values and .covariance must be numbers "
                                 f"({error})", parameter="uncertainty", value=section,
                                 allowed="lists of numbers") from error
    residual = _number(entry, "residual_m", "uncertainty.", source, low=0.0, high=1.0)
    try:
        return ParameterCovariance(tuple(str(n) for n in names), values, covariance, residual)
    except InvalidUncertaintyError as error:
        raise InvalidUncertaintyError(f"{source}: {error}", parameter=error.parameter,
                                      value=error.value, allowed=error.allowed) from error


def _tendons(items: Any, source: str, r_outer: float) -> tuple[Tendon, ...]:
    """The body file's ``tendons``: each with its signed ``offset`` (m), ``routing`` (None
    where not given), ``anchor`` (m, None: the tip), ``guides`` and ``name``; where an anchor
    falls is checked with the segments (:class:`~tdcm_ros.model.design.Design`)."""
    if not isinstance(items, list) or not 1 <= len(items) <= MAX_TENDONS:
        count = len(items) if isinstance(items, list) else items
        raise out_of_range(f"{source}: tendons", count, f"a list of 1 to {MAX_TENDONS} tendons",
                           error=InvalidDesignError)
    out = []
    for k, item in enumerate(items):
        here = f"tendons[{k}]"
        tendon = _mapping(item, here, source)
        reject_unknown("tendon key", tendon, ("offset", "routing", "anchor", "guides", "name",
                                              "stiffness", "slack"), error=InvalidDesignError)
        guides = tendon.get("guides", "internal")
        if guides not in GUIDES:
            raise out_of_range(f"{source}: {here}.guides", guides, " | ".join(GUIDES),
                               error=InvalidDesignError)
        limit = r_outer if guides == "internal" else MAX_EXTERNAL_OFFSET_M
        offset = _number(tendon, "offset", f"{here}.", source, low=-limit, high=limit,
                         open_low=True, open_high=True)
        if offset == 0.0:
            raise out_of_range(f"{source}: {here}.offset", offset, f"0 < |offset| < {limit:g} m "
                               "(+ on the +x side, - on the -x side)", error=InvalidDesignError)
        routing = tendon.get("routing")
        if routing is not None and routing not in ROUTINGS:
            raise out_of_range(f"{source}: {here}.routing", routing, " | ".join(ROUTINGS),
                               error=InvalidDesignError)
        anchor = (_number(tendon, "anchor", f"{here}.", source, low=0.0, high=1.0,
                          open_low=True) if "anchor" in tendon else None)
        name = tendon.get("name", f"tendon_{k + 1}")
        if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
            raise out_of_range(f"{source}: {here}.name", name, "a ROS name token: a letter, "
                               "then letters, digits or _", error=InvalidDesignError)
        stiffness = (_number(tendon, "stiffness", f"{here}.", source, low=0.0,
                             high=MAX_STIFFNESS_N_PER_M, open_low=True)
                     if "stiffness" in tendon else None)
        slack = _number(tendon, "slack", f"{here}.", source, low=0.0, high=MAX_SLACK_M,
                        default=0.0)
        out.append(Tendon(offset, routing, anchor, str(guides), name, stiffness, slack))
    return tuple(out)


def _mesh(entry: Mapping[str, Any], source: str) -> tuple[float, float, list[Segment]]:
    """``R_outer``, ``r_inner`` (m) and the segments of the body file's ``mesh`` (its ``file``
    relative to the body file's folder, its ``unit``), sliced by :mod:`~tdcm_ros.model.mesh_body`."""
    from tdcm_ros.model.mesh_body import read_mesh_body

    reject_unknown("mesh key", entry, ("file", "unit"), error=InvalidDesignError)
    name = _required(entry, "file", "mesh.", source)
    if not isinstance(name, str) or not name:
        raise out_of_range(f"{source}: mesh.file", name, "a mesh file's path",
                           error=InvalidDesignError)
    path = Path(name) if Path(name).is_absolute() else Path(source).parent / name
    body = read_mesh_body(path, str(entry.get("unit", "m")), f"{source}: mesh")
    segments: list[Segment] = [
        TubeSpec(s.length, s.where) if s.section is None else
        NotchSpec(width=s.length, kind="section", given=s.section, where=s.where)
        for s in body.segments]
    return body.R_outer, body.r_inner, segments


def _segments(items: Any, where: str, source: str, r_outer: float, r_inner: float
              ) -> list[Segment]:
    if not isinstance(items, list) or not items:
        raise out_of_range(f"{source}: {where}", items, "a non-empty list of segments",
                           error=InvalidDesignError)
    out: list[Segment] = []
    for index, item in enumerate(items):
        here = f"{where}[{index}]"
        entry = _mapping(item, here, source)
        kinds = [k for k in ("tube", "notch", "repeat") if k in entry]
        if len(kinds) != 1:
            raise InvalidDesignError(
                f"{source}: {here} has {kinds or 'none'} of tube, notch, repeat; allowed: "
                "exactly one", parameter=here, value=sorted(entry), allowed="tube | notch | repeat")
        if kinds[0] == "tube":
            reject_unknown(f"{here} key", entry, ("tube",), error=InvalidDesignError)
            out.append(TubeSpec(_number(entry, "tube", f"{here}.", source, low=MIN_SEGMENT_M,
                                        high=1.0), f"{here}.tube"))
        elif kinds[0] == "notch":
            reject_unknown(f"{here} key", entry, ("notch",), error=InvalidDesignError)
            out.append(_notch(_mapping(entry["notch"], f"{here}.notch", source),
                              f"{here}.notch", source, r_outer, r_inner))
        else:
            reject_unknown(f"{here} key", entry, ("repeat", "segments"), error=InvalidDesignError)
            count = entry["repeat"]
            if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= \
                    MAX_SEGMENTS:
                raise out_of_range(f"{source}: {here}.repeat", count, f"an integer in [1, "
                                   f"{MAX_SEGMENTS}]", error=InvalidDesignError)
            inner = _segments(_required(entry, "segments", f"{here}.", source),
                              f"{here}.segments", source, r_outer, r_inner)
            if len(out) + count * len(inner) > MAX_SEGMENTS:
                raise out_of_range(f"{source}: {here}.repeat", count, f"at most {MAX_SEGMENTS}"
                                   " segments in the body", error=InvalidDesignError)
            out.extend(inner * count)
        if len(out) > MAX_SEGMENTS:
            raise out_of_range(f"{source}: {where}", len(out), f"at most {MAX_SEGMENTS} segments",
                               error=InvalidDesignError)
    return out


def _notch(entry: Mapping[str, Any], where: str, source: str, r_outer: float, r_inner: float
           ) -> NotchSpec:
    reject_unknown(f"{where} key", entry, ("width", "band", "offset", "profile", "cut",
                                           "polygon", "holes", "section"),
                   error=InvalidDesignError)
    width = _number(entry, "width", f"{where}.", source, low=MIN_SEGMENT_M, high=1.0)
    kinds = [k for k in SECTION_KEYS if k in entry]
    if len(kinds) != 1:
        raise InvalidDesignError(
            f"{source}: {where} has {kinds or 'none'} of band, cut, polygon, section; allowed: "
            "exactly one section", parameter=where, value=sorted(entry),
            allowed="band | cut | polygon | section")
    kind = kinds[0]
    if kind in ("polygon", "section") and "profile" in entry:
        raise InvalidDesignError(f"{source}: {where}.profile goes with band or cut only",
                                 parameter=f"{where}.profile", value=entry["profile"],
                                 allowed="profile with band or cut")
    if kind != "band" and "offset" in entry:
        raise InvalidDesignError(f"{source}: {where}.offset goes with band only (a cut's is "
                                 "-cut/2)", parameter=f"{where}.offset",
                                 value=entry["offset"], allowed="offset with band")
    if kind != "polygon" and "holes" in entry:
        raise InvalidDesignError(f"{source}: {where}.holes goes with polygon only",
                                 parameter=f"{where}.holes", value=entry["holes"],
                                 allowed="holes with polygon")
    if kind == "section":
        return NotchSpec(width=width, kind=kind, where=where, given=_given_section(
            _mapping(entry["section"], f"{where}.section", source), f"{where}.section", source,
            r_outer))
    notch = _notch_of_kind(entry, kind, width, where, source, r_outer)
    try:
        notch.section(r_outer, r_inner).properties()
    except InvalidDesignError as error:
        raise InvalidDesignError(f"{source}: {where}: {error}", parameter=f"{where}.{kind}",
                                 value=error.value, allowed=error.allowed) from error
    return notch


def _notch_of_kind(entry: Mapping[str, Any], kind: str, width: float, where: str, source: str,
                   r_outer: float) -> NotchSpec:
    profile = entry.get("profile", DEFAULT_PROFILE.get(kind, ""))
    if kind in DEFAULT_PROFILE and profile not in PROFILE_NAMES:
        raise out_of_range(f"{source}: {where}.profile", profile, " | ".join(PROFILE_NAMES),
                           error=InvalidDesignError)
    if kind == "band":
        band = _number(entry, "band", f"{where}.", source, low=0.0, high=2.0 * r_outer,
                       open_low=True, open_high=True)
        offset = _number(entry, "offset", f"{where}.", source, low=-r_outer, high=r_outer,
                         open_low=True, open_high=True, default=0.0)
        return NotchSpec(width=width, kind=kind, band=band, offset=offset, profile=str(profile),
                         where=where)
    if kind == "cut":
        cut = _number(entry, "cut", f"{where}.", source, low=0.0, high=2.0 * r_outer,
                      open_low=True, open_high=True)
        return NotchSpec(width=width, kind=kind, cut=cut, offset=-0.5 * cut,
                         profile=str(profile), where=where)
    return NotchSpec(width=width, kind=kind, shell=_points(entry["polygon"], f"{where}.polygon",
                                                           source),
                     holes=tuple(_points(h, f"{where}.holes[{k}]", source)
                                 for k, h in enumerate(_list(entry.get("holes", []),
                                                             f"{where}.holes", source))),
                     where=where)


def _given_section(entry: Mapping[str, Any], where: str, source: str, r_outer: float
                   ) -> SectionProfile:
    """A section given by its numbers (SI units), each in range and the centroid inside the
    extent."""
    reject_unknown(f"{where} key", entry, GIVEN_SECTION_KEYS, error=InvalidDesignError)
    prefix = f"{where}."
    area = _number(entry, "area", prefix, source, low=0.0, high=math.pi * r_outer**2,
                   open_low=True)
    second = _number(entry, "second_moment", prefix, source, low=0.0, high=1.0, open_low=True)
    low = _number(entry, "x_low", prefix, source, low=-r_outer, high=r_outer)
    high = _number(entry, "x_high", prefix, source, low=low, high=r_outer, open_low=True)
    centroid = _number(entry, "centroid_x", prefix, source, low=low, high=high, open_low=True,
                       open_high=True)
    return SectionProfile(area=area, centroid_x=centroid, second_moment=second, x_low=low,
                         x_high=high)


def _points(value: Any, where: str, source: str) -> tuple[tuple[float, float], ...]:
    points = _list(value, where, source)
    out = []
    for point in points:
        if not (isinstance(point, list) and len(point) == 2 and all(
                isinstance(c, (int, float)) and not isinstance(c, bool) for c in point)):
            raise out_of_range(f"{source}: {where}", point, "[x, y] in m", error=InvalidDesignError)
        out.append((float(point[0]), float(point[1])))
    return tuple(out)


def _list(value: Any, where: str, source: str) -> list[Any]:
    if not isinstance(value, list):
        raise out_of_range(f"{source}: {where}", value, "a list", error=InvalidDesignError)
    return value


def _mapping(value: Any, where: str, source: str) -> Mapping[str, Any]:
    if not isinstance(value, dict):
        raise out_of_range(f"{source}: {where}", value, "a mapping of keys to values",
                           error=InvalidDesignError)
    return value


def _required(entry: Mapping[str, Any], key: str, prefix: str, source: str) -> Any:
    if key not in entry:
        raise InvalidDesignError(f"{source}: {prefix}{key} is missing", parameter=prefix + key,
                                 value=None, allowed="a value")
    return entry[key]


#: Units of the body file's numbers that are not lengths in m.
_UNITS = {"E": "Pa", "E_plateau": "Pa", "area": "m^2", "second_moment": "m^4",
          "plateau_strain": "", "recoverable_strain": "", "stiffness": "N/m", "mu": ""}


def _number(entry: Mapping[str, Any], key: str, prefix: str, source: str, *, low: float,
            high: float, open_low: bool = False, open_high: bool = False,
            default: float | None = None) -> float:
    """``entry[key]`` as a finite float in the range (SI units), else a named error."""
    if key not in entry and default is not None:
        return default
    spec = Spec(key, unit=_UNITS.get(key, "m"), low=low, high=high, low_open=open_low,
                high_open=open_high)
    return float(spec.check(_required(entry, key, prefix, source), f"{source}: {prefix}{key}",
                            error=InvalidDesignError))


def yaml_number(value: float) -> str:
    """``value`` in its shortest round-trip form, with a ``.`` before any exponent (``1.0e-05``:
    YAML 1.1 readers take ``1e-05`` for a string)."""
    text = repr(float(value))
    return text.replace("e", ".0e", 1) if "e" in text and "." not in text else text


def body_file_text(design: Design, routing: str = "paper") -> str:
    """The body file of ``design`` whose tendons without their own routing have ``routing``
    (the paper's one tendon: ``R_c`` on +x): reading it back gives
    ``design`` bit for bit (every number written as its shortest round-trip form). A uniform
    design is written with ``repeat``, a per-notch one segment by segment."""
    def points(ring: Sequence[tuple[float, float]]) -> str:
        return "[" + ", ".join(f"[{yaml_number(x)}, {yaml_number(y)}]" for x, y in ring) + "]"

    def notch(width: float, band: float, offset: float, profile: NotchProfile) -> str:
        if isinstance(profile, SlicedProfile):
            raise InvalidDesignError(
                "a notch whose section changes along it (sliced from a mesh) has no body-file "
                "form; allowed: the body file naming the mesh", parameter="profile",
                value=profile.name, allowed="band, cut, polygon or section notches")
        if isinstance(profile, SectionProfile):
            numbers = ", ".join(f"{key}: {yaml_number(getattr(profile, key))}"
                                for key in GIVEN_SECTION_KEYS)
            return f"{{width: {yaml_number(width)}, section: {{{numbers}}}}}"
        if isinstance(profile, PolygonProfile):
            holes = (", holes: [" + ", ".join(points(h) for h in profile.holes) + "]"
                     if profile.holes else "")
            return f"{{width: {yaml_number(width)}, polygon: {points(profile.shell)}{holes}}}"
        at = f", offset: {yaml_number(offset)}" if offset != 0.0 else ""
        return f"{{width: {yaml_number(width)}, band: {yaml_number(band)}{at}, profile: {profile.name}}}"

    def material() -> str:
        law = design.material
        keys = [f"E: {yaml_number(design.E)}"]
        if not law.is_linear:
            keys += ["law: bilinear", f"plateau_strain: {yaml_number(law.plateau_strain)}",
                     f"E_plateau: {yaml_number(law.E_plateau)}"]
        if math.isfinite(law.recoverable_strain):
            keys.append(f"recoverable_strain: {yaml_number(law.recoverable_strain)}")
        return ", ".join(keys)

    def tendon(one: Tendon) -> str:
        keys = [f"offset: {yaml_number(one.offset)}"]
        if one.routing or not design.tendons:
            keys.append(f"routing: {one.routing or routing}")
        if one.anchor is not None:
            keys.append(f"anchor: {yaml_number(one.anchor)}")
        if one.guides != "internal":
            keys.append(f"guides: {one.guides}")
        if one.stiffness is not None:
            keys.append(f"stiffness: {yaml_number(one.stiffness)}")
        if one.slack != 0.0:
            keys.append(f"slack: {yaml_number(one.slack)}")
        return "  - {" + ", ".join([*keys, f"name: {one.name}"] if design.tendons else keys) + "}"

    lines = [f"tube: {{R_outer: {yaml_number(design.R_outer)}, r_inner: {yaml_number(design.r_inner)}}}",
             f"material: {{{material()}}}", "tendons:",
             *(tendon(one) for one in design.tendon_list()), "segments:"]
    if design.w_base > 0.0:
        lines.append(f"  - tube: {yaml_number(design.w_base)}")
    if design.is_uniform:
        one = notch(design.uniform("w_n"), design.uniform("w_d"), design.uniform("w_o"),
                    design.uniform_profile())
        if design.N > 1:
            lines += [f"  - repeat: {design.N - 1}", "    segments:", f"      - notch: {one}"]
            if design.uniform("w_t") > 0.0:
                lines.append(f"      - tube: {yaml_number(design.uniform('w_t'))}")
        lines.append(f"  - notch: {one}")
    else:
        gaps = [*design.per_notch("w_t").tolist(), 0.0]
        for width, band, offset, profile, gap in zip(
                design.per_notch("w_n").tolist(), design.per_notch("w_d").tolist(),
                design.per_notch("w_o").tolist(), design.notch_profiles(), gaps, strict=True):
            lines.append(f"  - notch: {notch(width, band, offset, profile)}")
            if gap > 0.0:
                lines.append(f"  - tube: {yaml_number(gap)}")
    if design.w_tip > 0.0:
        lines.append(f"  - tube: {yaml_number(design.w_tip)}")
    return "\n".join(lines) + "\n"


def is_body_file(name: str | None) -> bool:
    """Whether ``name`` is a body file's path (``.yaml``/``.yml``) rather than a preset name."""
    return name is not None and name.lower().endswith((".yaml", ".yml"))


def named_design(name: str) -> Design:
    """The design ``name`` names: a body file if it is one (:func:`is_body_file`; read now),
    else a preset."""
    return read_body_file(name).design() if is_body_file(name) else preset(name)
