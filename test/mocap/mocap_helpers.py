"""Helpers of the mocap tests (uniquely named module): write Nexus-shaped CSV text."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

DATA = __import__("pathlib").Path(__file__).resolve().parent / "data"


def nexus_text(names: Sequence[str], positions_m: np.ndarray, *, rate: float = 100.0,
               first_frame: int = 1, delimiter: str = ",", decimal_comma: bool = False,
               before: str = "", after: str = "") -> str:
    """A Trajectories section (mm, repr floats, NaN as empty cells) between ``before``/``after``."""
    d = delimiter

    def number(value: float) -> str:
        text = "" if math.isnan(value) else repr(float(value))
        return text.replace(".", ",") if decimal_comma else text

    lines = ["Trajectories" + d * (2 + 3 * len(names) - 1), f"{rate:g}",
             d * 2 + d.join(f"{n}{d}{d}" for n in names),
             d.join(["Frame", "Sub Frame", *["X", "Y", "Z"] * len(names)]),
             d * 2 + d.join(["mm"] * 3 * len(names))]
    for row, frame in enumerate(range(first_frame, first_frame + len(positions_m))):
        cells = [number(v * 1000.0) for v in np.asarray(positions_m[row]).ravel()]
        lines.append(d.join([str(frame), "0", *cells]))
    return before + "\n".join(lines) + "\n" + after


def straight_and_bent(truth: Any, arcs: Sequence[float] = (0.015, 0.033, 0.053),
                      radius: float = 0.00492) -> tuple[np.ndarray, np.ndarray]:
    """Markers (mocap, m) of a straight body and one bent toward +x in a plane (hand geometry:
    the body bends on a circle of radius 0.1 m in the x-z plane; markers on the -x surface)."""
    s = np.array(arcs)
    straight = np.column_stack([np.full(len(s), -radius), np.zeros(len(s)), s])
    rho = 0.1
    phi = s / rho
    mid = np.column_stack([rho * (1 - np.cos(phi)), np.zeros(len(s)), rho * np.sin(phi)])
    body_x = np.column_stack([np.cos(phi), np.zeros(len(s)), -np.sin(phi)])
    bent = mid - radius * body_x
    return truth.to_mocap(straight), truth.to_mocap(bent)
