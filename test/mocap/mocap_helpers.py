"""Helpers of the mocap tests (uniquely named module): write Nexus-shaped CSV text."""

from __future__ import annotations

import math
from collections.abc import Sequence

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
