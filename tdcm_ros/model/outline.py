"""The body's outline in the bending plane, as it is cut: where its material ends on each side
of the midline along a solved shape (for drawing the notches as they are).

Outside the notches the material reaches the tube's surface, ``R_outer`` from the midline on
either side; inside a notch it ends at the backbone's edges, ``w_o + h1`` on the +x side and
``h1 - w_o`` on the -x side (eq. 13's profile, the backbone offset ``w_o`` from the axis; each at
most ``R_outer``: a one-sided cut leaves the -x side whole; a notch sliced from a mesh, its
slices' extent). Each edge is a polyline of points ``(x, z)`` in ``tdcm_base`` (m), base to tip, with
the segment boundaries ``l_i`` and ``r_i`` twice (the tube's and the notch's width there), so
the cut's step shows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.model.profiles import SlicedProfile
from tdcm_ros.model.result import SolveResult

Array = NDArray[np.float64]

#: Stations per segment (tube or notch), both ends included.
STATIONS_PER_SEGMENT = 24


@dataclass(frozen=True, eq=False)
class BodyOutline:
    """Stations ``s`` (m, base to tip, boundaries repeated), the material's half-width there on
    the +x and -x sides (m), and the two edges' points ``(x, z)`` in ``tdcm_base`` (m), (k, 2)."""

    s: Array
    half_width_tendon_side: Array
    half_width_far_side: Array
    tendon_side: Array
    far_side: Array


def body_outline(result: SolveResult, stations: int = STATIONS_PER_SEGMENT) -> BodyOutline:
    """The cut body's edges along ``result``'s shape (module docstring); ``stations`` per
    segment (at least 2)."""
    design = result.design
    left, right = design.notch_bounds()
    u = np.linspace(0.0, 1.0, max(2, int(stations)))
    w_n, w_d, w_o = design.per_notch("w_n"), design.per_notch("w_d"), design.per_notch("w_o")
    profiles = design.notch_profiles()
    s_parts, widths, far_widths = [], [], []
    starts = [0.0, *right]
    ends = [*left, design.length]
    for k, (start, end) in enumerate(zip(starts, ends, strict=True)):
        if end > start:
            s_parts.append(np.linspace(start, end, u.size))
            widths.append(np.full(u.size, design.R_outer))
            far_widths.append(widths[-1])
        if k < left.size:
            sigma = profiles[k].sigma(u, w_n[k])
            sigma[-1] = w_n[k]  # the notch's end exactly, whatever the profile's rounding
            s_parts.append(left[k] + sigma)
            profile = profiles[k]
            if isinstance(profile, SlicedProfile):  # the extent of each slice
                _, _, _, low, high = profile.section_at(u)
                widths.append(np.minimum(high, design.R_outer))
                far_widths.append(np.minimum(-low, design.R_outer))
                continue
            h1 = profile.h1(u, w_n[k], w_d[k])
            widths.append(np.minimum(h1 + w_o[k], design.R_outer))
            far_widths.append(np.minimum(h1 - w_o[k], design.R_outer))
    s = np.concatenate(s_parts)
    width, far = np.concatenate(widths), np.concatenate(far_widths)
    positions, quaternions = result.pose_at(np.clip(s, 0.0, design.length))
    theta = 2.0 * np.arctan2(quaternions[:, 1], quaternions[:, 3])
    normal = np.stack([np.cos(theta), -np.sin(theta)], axis=1)  # +x of the body frame, (x, z)
    midline = positions[:, [0, 2]]
    return BodyOutline(s=s, half_width_tendon_side=width, half_width_far_side=far,
                       tendon_side=midline + width[:, None] * normal,
                       far_side=midline - far[:, None] * normal)
