"""Where the markers sit on the body: the marker layout (labels, arc lengths, ball radius,
side, radial offset) and its specs, SI units.

Markers sit at arc lengths ``arc_lengths`` (m), ``radial_offset`` off the midline (default: on
the body surface, ``R_outer + ball_radius``; 0: virtual markers on the midline, as a fitted
spline or a marker tree gives them), at ``side_deg`` around the body z axis from the body x axis
(0 = tendon side; the default 180 deg is opposite the tendon).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import out_of_range
from tdcm_ros.spec import check_fields, spec_field, specs_of

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MarkerLayout:
    """Where the markers sit: ``labels`` (last = tip marker), ``arc_lengths`` (m, increasing),
    ``ball_radius`` (m), ``side_deg`` (deg from the tendon side) and ``radial_offset`` (m from
    the midline; ``None``: on the surface, ``R_outer + ball_radius``)."""

    labels: tuple[str, ...] = spec_field(("m1", "m2", "m3"), description=(
        "marker labels, base to tip (the last is the tip marker)"))
    arc_lengths: tuple[float, ...] = spec_field((0.015, 0.033, 0.053), unit="m", low=0.0,
                                                low_open=True, description=(
                                                    "marker arc lengths from the base, increasing"))
    ball_radius: float = spec_field(0.001, unit="m", low=0.0, high=0.05,
                                    description="marker ball radius")
    side_deg: float = spec_field(180.0, unit="deg", low=-360.0, high=360.0, description=(
        "marker side around the body z axis from the tendon side"))
    radial_offset: float | None = spec_field(None, unit="m", low=0.0, high=0.05, description=(
        "distance of the marker centres from the midline (default: R_outer + ball_radius, on "
        "the surface; 0: on the midline)"))

    def __post_init__(self) -> None:
        given = {k: s for k, s in MARKER_SPECS.items()
                 if k != "radial_offset" or self.radial_offset is not None}
        check_fields(self, given, prefix="markers.")
        if len(self.labels) != len(self.arc_lengths):
            raise out_of_range("markers.labels", list(self.labels),
                               f"{len(self.arc_lengths)} distinct labels, one per arc length")
        if any(b <= a for a, b in zip(self.arc_lengths, self.arc_lengths[1:], strict=False)):
            raise out_of_range("markers.arc_lengths", list(self.arc_lengths),
                               "increasing values > 0", unit="m")

    @property
    def side_rad(self) -> float:
        """Marker side around the body z axis (rad)."""
        return math.radians(self.side_deg)

    @property
    def s(self) -> Array:
        """Arc lengths (k,) m."""
        return np.asarray(self.arc_lengths)

    def radius(self, r_outer: float) -> float:
        """Distance of the marker centres from the midline (m) for a body of radius ``r_outer``
        (m): ``radial_offset`` if given, else on the surface."""
        return r_outer + self.ball_radius if self.radial_offset is None else self.radial_offset

    def rest_offset(self, r_outer: float) -> Array:
        """Offset (3,) m of every marker from the midline at zero tension (straight body)."""
        r = self.radius(r_outer)
        return np.array([r * math.cos(self.side_rad), r * math.sin(self.side_rad), 0.0])

    def check_within(self, length: float) -> None:
        """Every marker must lie on a body of ``length`` (m)."""
        if self.arc_lengths[-1] > length + 1e-12:
            raise out_of_range("markers.arc_lengths", list(self.arc_lengths),
                               f"values in (0, L = {length:g}] m")


#: Specs of the marker layout, by field name.
MARKER_SPECS = specs_of(MarkerLayout)
