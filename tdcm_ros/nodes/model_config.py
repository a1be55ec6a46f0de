"""The model node's configuration as one typed value: read from its parameters once per change.

``model_node`` builds a :class:`ModelConfig` at start and again for each accepted parameter
change, and swaps it whole; the per-input path reads its fields and never a parameter by name.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.errors import InputError, exact_number
from tdcm_ros.model import Design, SolverSettings, joint_names

#: m: a marker arc length up to this far past the tip (a length rounded in a file) is the tip.
TIP_TOLERANCE_M = 1e-9


@dataclass(frozen=True, eq=False)
class ModelConfig:
    """What the model node needs per input, from its design, solver and tunable parameters."""

    design: Design
    settings: SolverSettings
    frame_id: str
    """Frame of every output, ``frame_prefix`` included."""
    samples: int
    """Poses along the drawn midline."""
    visual_period_ns: int
    """ns between drawn solves by their stamps (``output.visual_rate_hz``); 0: every solve."""
    marker_s: NDArray[np.float64]
    """Arc lengths of the predicted markers (m), at most the design's length; read-only."""
    marker_radius_m: float
    """Markers' distance from the midline (m): the tube's radius plus the ball's on the
    surface, 0 on the midline."""
    marker_side_rad: float
    tension_max_n: float
    max_age_s: float
    """Inputs older than this are stale (s); 0 disables."""
    max_future_s: float
    mu: float
    """Capstan friction coefficient (``friction.mu``)."""
    band_confidence: float
    joint_names: tuple[str, ...]
    """The body's URDF joints, less the driver's roll."""
    tendon_names: tuple[str, ...]

    @classmethod
    def of(cls, design: Design, settings: SolverSettings, tunable: Mapping[str, Any],
           prefix: str) -> ModelConfig:
        """The configuration of ``design`` and ``settings`` with the node's tunable parameters
        (``tunable``: checked values by name, e.g. ``output.samples``) and ``frame_prefix``;
        :class:`InputError` if a marker lies beyond the tip."""
        arcs = tunable["markers.arc_lengths"]
        end = design.length + TIP_TOLERANCE_M
        if not arcs or any(not 0.0 <= float(s) <= end for s in arcs):
            allowed = (f"values in [0, {exact_number(design.length)}] m (up to "
                       f"{TIP_TOLERANCE_M:g} m past the tip: at the tip)")
            raise InputError(f"markers.arc_lengths = {arcs!r} out of range; allowed: {allowed}",
                             parameter="markers.arc_lengths", value=arcs, allowed=allowed)
        marker_s = np.minimum(np.asarray(arcs, dtype=float), design.length)
        marker_s.flags.writeable = False
        rate = float(tunable["output.visual_rate_hz"])
        surface = tunable["markers.placement"] == "surface"
        return cls(
            design=design, settings=settings, frame_id=prefix + str(tunable["frame_id"]),
            samples=int(tunable["output.samples"]),
            visual_period_ns=round(1e9 / rate) if rate > 0.0 else 0, marker_s=marker_s,
            marker_radius_m=(design.R_outer + float(tunable["markers.ball_radius"])
                             if surface else 0.0),
            marker_side_rad=math.radians(float(tunable["markers.side_deg"])),
            tension_max_n=float(tunable["input.tension_max"]),
            max_age_s=float(tunable["input.max_age_s"]),
            max_future_s=float(tunable["input.max_future_s"]),
            mu=float(tunable["friction.mu"]), band_confidence=float(tunable["band.confidence"]),
            joint_names=tuple(joint_names(design)[1:]),
            tendon_names=tuple(t.name for t in design.tendon_list()))
