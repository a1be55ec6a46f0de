"""Vicon Nexus CSV reader: a file shaped like a real export (CRLF, Devices and Model Outputs
sections, gaps, an unlabelled trajectory), both delimiters, and typed errors with line numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.errors import InputError
from tdcm_ros.mocap import CsvFormatError, parse_nexus_csv, read_nexus_csv
from test.mocap.mocap_helpers import DATA, nexus_text

SAMPLE = DATA / "nexus_trial.csv"


def sample_lines() -> list[str]:
    return SAMPLE.read_text().splitlines()


def test_sample_export_reads_trajectories_in_metres_with_gaps():
    traj = read_nexus_csv(SAMPLE)
    assert traj.rate_hz == 100.0
    assert traj.names == ("TDCM:M1", "TDCM:M2", "TDCM:M3", "*17")
    assert traj.frames[0] == 101 and traj.frames[-1] == 130 and len(traj.frames) == 30
    assert traj.positions.shape == (30, 4, 3)
    # first Trajectories row: 101,0,245.72,-120.12,797.25,245.7,-120.13,779.33,245.71,-120.12,...
    assert np.allclose(traj.positions[0, 0], [0.24572, -0.12012, 0.79725], rtol=0, atol=1e-12)
    assert np.allclose(traj.positions[0, 1], [0.2457, -0.12013, 0.77933], rtol=0, atol=1e-12)
    assert np.allclose(traj.times_s, np.arange(30) / 100.0)
    gaps = np.isnan(traj.positions).all(axis=2)
    assert np.array_equal(np.flatnonzero(gaps[:, 2]), [10, 11, 12])      # tip marker gap
    assert np.array_equal(np.flatnonzero(gaps[:, 0]), [20])
    assert np.array_equal(np.flatnonzero(~gaps[:, 3]), [5, 6, 7, 8])     # short unlabelled
    assert not np.isnan(traj.positions[~gaps]).any()


def test_every_cell_of_the_sample_matches_the_text():
    traj = read_nexus_csv(SAMPLE)
    lines = sample_lines()
    head = lines.index("Trajectories")
    for row, line in enumerate(lines[head + 5:head + 35]):
        cells = line.split(",")[2:]
        expected = [float(c) / 1000.0 if c else math.nan for c in cells]
        assert np.allclose(traj.positions[row].ravel(), expected, equal_nan=True, rtol=0,
                           atol=1e-15)


def test_semicolon_delimiter_and_decimal_comma_read_the_same():
    text = SAMPLE.read_text()
    reference = parse_nexus_csv(text)
    semicolon = parse_nexus_csv(text.replace(",", ";"))
    decimal_comma = parse_nexus_csv(text.replace(",", ";").replace(".", ","))
    for other in (semicolon, decimal_comma):
        assert other.names == reference.names
        assert np.array_equal(other.frames, reference.frames)
        assert np.array_equal(other.positions, reference.positions, equal_nan=True)


def test_section_after_trajectories_is_skipped_even_without_a_blank_line():
    positions = np.array([[[0.1, 0.2, 0.3]], [[0.4, 0.5, 0.6]]])
    after = "Segments\n100\n,,TDCM:Body,,\nFrame,Sub Frame,RX,RY,RZ\n,,deg,deg,deg\n1,0,1,2,3\n"
    traj = parse_nexus_csv(nexus_text(["A:m"], positions, after=after))
    assert len(traj.frames) == 2 and np.allclose(traj.positions, positions)


@settings(max_examples=40)
@given(st.integers(1, 5), st.integers(1, 12), st.sampled_from([",", ";"]), st.booleans(),
       st.floats(1.0, 2000.0), st.data())
def test_written_trajectories_round_trip(k, n, delimiter, comma, rate, data):
    values = data.draw(st.lists(st.one_of(st.floats(-5.0, 5.0), st.just(math.nan)),
                                min_size=n * k * 3, max_size=n * k * 3))
    positions = np.array(values).reshape(n, k, 3)
    names = [f"S:M{i}" for i in range(k)]
    text = nexus_text(names, positions, rate=rate, first_frame=7, delimiter=delimiter,
                      decimal_comma=comma and delimiter == ";")
    traj = parse_nexus_csv(text)
    assert traj.names == tuple(names) and traj.rate_hz == pytest.approx(float(f"{rate:g}"))
    assert np.array_equal(traj.frames, np.arange(7, 7 + n))
    assert np.allclose(traj.positions, positions, equal_nan=True, rtol=1e-12, atol=1e-15)


def broken(replace: tuple[int, str, str]) -> tuple[str, int]:
    """The sample with one Trajectories line edited: (offset from the header, old, new)."""
    lines = sample_lines()
    head = lines.index("Trajectories")
    offset, old, new = replace
    assert old in lines[head + offset]
    lines[head + offset] = lines[head + offset].replace(old, new)
    return "\n".join(lines), head + offset + 1


@pytest.mark.parametrize(("edit", "phrase"), [
    ((3, "X,Y,Z,X,Y,Z", "X,Y,Z,X,Y,"), "has no Z column"),           # axis line lacks a column
    ((3, "Frame,Sub Frame", "Frame,Subframe"), "Sub Frame"),
    ((4, "mm,mm,mm,mm,mm,mm,mm,mm,mm,mm,mm,mm", "mm,mm,mm,mm,mm,mm,mm,mm,mm,in,in,in"), "units"),
    ((1, "100", "fast"), "not a number"),
    ((1, "100", "0"), "frame rate"),
    ((5, "245.72", "24x5.72"), "not a number"),
    ((6, ",,,", ""), "cells"),                                         # short row
    ((8, "104,0", "102,0"), "does not follow"),
    ((2, "TDCM:M2", "TDCM:M1"), "twice"),
])
def test_bad_files_raise_a_typed_error_with_the_line(edit, phrase):
    text, line = broken(edit)
    with pytest.raises(CsvFormatError) as caught:
        parse_nexus_csv(text, source="trial.csv")
    assert isinstance(caught.value, InputError)
    assert caught.value.line == line and phrase in str(caught.value)
    assert str(caught.value).startswith(f"trial.csv:{line}: ")


def test_missing_section_and_missing_file_are_typed_errors(tmp_path):
    text = SAMPLE.read_text().replace("Trajectories", "Trajectory")
    with pytest.raises(CsvFormatError, match="no 'Trajectories' section") as caught:
        parse_nexus_csv(text)
    assert caught.value.line is None
    with pytest.raises(CsvFormatError, match="cannot read"):
        read_nexus_csv(tmp_path / "absent.csv")
    cut = "\n".join(sample_lines()[:sample_lines().index("Trajectories") + 3])
    with pytest.raises(CsvFormatError, match="section ends"):
        parse_nexus_csv(cut)
    header_only = "\n".join(sample_lines()[:sample_lines().index("Trajectories") + 5])
    with pytest.raises(CsvFormatError, match="no data rows"):
        parse_nexus_csv(header_only)
