"""Reader of the ``Trajectories`` section of a Vicon Nexus CSV export.

Layout read (cells separated by ``,`` or ``;``, the same in the whole file)::

    Trajectories                      section header (other cells empty)
    100                               frame rate (Hz)
    ,,Sub:M1,,,Sub:M2,,,              marker names, each above its X column
    Frame,Sub Frame,X,Y,Z,X,Y,Z       axis line
    ,,mm,mm,mm,mm,mm,mm               units: mm, cm or m
    1,0,12.5,-3.1,80.2,,,             rows; an empty cell is a gap

Other sections (``Devices``, ``Model Outputs``, ``Joints``, ``Events`` ...) before or after it are
skipped. The section ends at a blank line, another section header or the end of the file.
Columns other than X, Y, Z of a marker (e.g. the derivatives ``X'``) are ignored. With ``;`` as
the delimiter a decimal comma (``12,5``) is accepted. Positions come out in m; gaps and cells
``nan`` are NaN rows (see :mod:`tdcm_ros.mocap.occlusion`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tdcm_ros.mocap.errors import CsvFormatError

Array = NDArray[np.float64]
SECTION = "Trajectories"
UNITS_M = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
AXES = ("X", "Y", "Z")
_SPLIT = re.compile(r"[,;]")


@dataclass(frozen=True)
class Trajectories:
    """Marker trajectories of one export.

    ``names`` (k,) as in the file (``Subject:Marker`` or unlabelled ``*12``); ``frames`` (n,)
    frame numbers; ``positions`` (n, k, 3) m in the Vicon world frame, NaN where the file had a
    gap; ``rate_hz`` the frame rate.
    """

    path: str
    rate_hz: float
    names: tuple[str, ...]
    frames: NDArray[np.int64]
    positions: Array

    @property
    def times_s(self) -> Array:
        """Time of each row from the first frame (s)."""
        return (self.frames - self.frames[0]) / self.rate_hz


def read_nexus_csv(path: str | Path) -> Trajectories:
    """Read the ``Trajectories`` section of the Nexus CSV export at ``path``."""
    where = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as error:
        raise CsvFormatError(f"cannot read file: {error}", path=where, line=None,
                             value=where) from error
    return parse_nexus_csv(text, source=where)


def _cells(line: str, delimiter: str) -> list[str]:
    return [cell.strip() for cell in line.split(delimiter)]


def _blank(line: str) -> bool:
    return not _SPLIT.sub("", line).strip()


def _find_section(lines: list[str], source: str) -> int:
    for index, line in enumerate(lines):
        first, *rest = _SPLIT.split(line)
        if first.strip() == SECTION and not "".join(rest).strip():
            return index
    raise CsvFormatError(f"no {SECTION!r} section in {len(lines)} lines", path=source, line=None,
                         parameter="csv", allowed=f"a Nexus CSV export with a {SECTION} section")


def _delimiter(axis_line: str, source: str, line_no: int) -> str:
    match = re.match(r"\s*Frame\s*([,;])", axis_line)
    if match is None:
        raise CsvFormatError(f"expected the axis line 'Frame,Sub Frame,X,Y,Z,...', got "
                             f"{axis_line[:60]!r}", path=source, line=line_no,
                             value=axis_line[:60], allowed="Frame,Sub Frame,X,Y,Z,...")
    return match.group(1)


def _number(cell: str, delimiter: str, source: str, line_no: int, column: int) -> float:
    text = cell.replace(",", ".") if delimiter == ";" else cell
    try:
        return float(text)
    except ValueError:
        raise CsvFormatError(f"column {column + 1}: {cell!r} is not a number", path=source,
                             line=line_no, value=cell, allowed="a decimal number or empty"
                             ) from None


def _marker_columns(names: list[str], axes: list[str], units: list[str], source: str,
                    first_line: int) -> tuple[list[str], list[tuple[int, int, int]], list[float]]:
    """Names, (x, y, z) column indices and unit scale (m per unit) of each marker."""
    starts = [i for i, name in enumerate(names) if i >= 2 and name]
    if not starts:
        raise CsvFormatError("no marker names on the names line", path=source,
                             line=first_line + 2, allowed="Subject:Marker above each X column")
    if axes[:2] != ["Frame", "Sub Frame"]:
        raise CsvFormatError(f"axis line starts with {axes[:2]!r}; expected 'Frame', "
                             "'Sub Frame'", path=source,
                             line=first_line + 3, value=axes[:2], allowed="Frame, Sub Frame")
    marker_names: list[str] = []
    columns: list[tuple[int, int, int]] = []
    scales: list[float] = []
    for number, start in enumerate(starts):
        stop = starts[number + 1] if number + 1 < len(starts) else max(len(axes), start + 1)
        name = names[start]
        if name in marker_names:
            raise CsvFormatError(f"marker {name!r} appears twice", path=source,
                                 line=first_line + 2, value=name, allowed="unique marker names")
        found = {axis: i for i in range(start, min(stop, len(axes))) for axis in AXES
                 if axes[i] == axis}
        missing = [axis for axis in AXES if axis not in found]
        if missing:
            raise CsvFormatError(f"marker {name!r} (column {start + 1}) has no "
                                 f"{'/'.join(missing)} column", path=source, line=first_line + 3,
                                 parameter="csv", value=name, allowed="X, Y and Z per marker")
        xyz = (found["X"], found["Y"], found["Z"])
        marker_units = {units[i] if i < len(units) else "" for i in xyz}
        if len(marker_units) != 1 or (unit := marker_units.pop()) not in UNITS_M:
            raise CsvFormatError(f"marker {name!r} has units {sorted(marker_units)!r}",
                                 path=source, line=first_line + 4, value=name,
                                 allowed=", ".join(UNITS_M))
        marker_names.append(name)
        columns.append(xyz)
        scales.append(UNITS_M[unit])
    return marker_names, columns, scales


def parse_nexus_csv(text: str, *, source: str = "<csv>") -> Trajectories:
    """Parse the text of a Nexus CSV export (see the module docstring); ``source`` names it in
    errors."""
    lines = text.splitlines()
    head = _find_section(lines, source)
    if head + 4 >= len(lines):
        raise CsvFormatError(f"{SECTION} section ends after {len(lines) - head - 1} lines; "
                             "expected rate, names, axis and units lines", path=source,
                             line=len(lines), allowed="5 header lines")
    delimiter = _delimiter(lines[head + 3], source, head + 4)
    rate_cell = _cells(lines[head + 1], delimiter)[0]
    rate = _number(rate_cell, delimiter, source, head + 2, 0)
    if not (math.isfinite(rate) and rate > 0.0):
        raise CsvFormatError(f"frame rate {rate_cell!r} is not a positive number", path=source,
                             line=head + 2, value=rate_cell, allowed="(0, inf) Hz")
    names, columns, scales = _marker_columns(
        _cells(lines[head + 2], delimiter), _cells(lines[head + 3], delimiter),
        _cells(lines[head + 4], delimiter), source, head + 1)
    needed = max(max(c) for c in columns) + 1
    frames: list[int] = []
    rows: list[list[list[float]]] = []
    for index in range(head + 5, len(lines)):
        line, line_no = lines[index], index + 1
        if _blank(line):
            break
        cells = _cells(line, delimiter)
        if not re.fullmatch(r"[+-]?\d+(\.0*)?", cells[0]):
            break   # the next section's header
        if len(cells) < needed:
            raise CsvFormatError(f"row has {len(cells)} cells; the header needs {needed}",
                                 path=source, line=line_no, value=len(cells),
                                 allowed=f">= {needed} cells")
        frame = int(float(cells[0]))
        sub = _number(cells[1], delimiter, source, line_no, 1) if cells[1] else 0.0
        if sub != 0.0:
            raise CsvFormatError(f"Sub Frame {cells[1]!r} is not supported in {SECTION}",
                                 path=source, line=line_no, value=cells[1], allowed="0")
        if frames and frame <= frames[-1]:
            raise CsvFormatError(f"frame {frame} does not follow frame {frames[-1]}",
                                 path=source, line=line_no, value=frame,
                                 allowed=f"> {frames[-1]}")
        frames.append(frame)
        rows.append([[_number(cells[i], delimiter, source, line_no, i) * scale
                      if cells[i] else math.nan for i in xyz]
                     for xyz, scale in zip(columns, scales, strict=True)])
    if not frames:
        raise CsvFormatError(f"{SECTION} section has no data rows", path=source, line=head + 6,
                             allowed="rows 'Frame,Sub Frame,x,y,z,...'")
    return Trajectories(path=source, rate_hz=rate, names=tuple(names),
                        frames=np.asarray(frames, dtype=np.int64),
                        positions=np.asarray(rows, dtype=float))
