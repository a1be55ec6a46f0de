"""Body files: the presets through a body file are the presets bit for bit, a hand-written file
is read as written, and every bad input names its key by its path in the file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tdcm_ros.model import (
    PRESETS,
    InvalidDesignError,
    body_file_text,
    body_from_mapping,
    preset,
    read_body_file,
    solve,
)
from tdcm_ros.model.profiles import PolygonProfile, SectionProfile
from tdcm_ros.yamlio import load_yaml
from test.support.cli import tdcm

REPO = Path(__file__).resolve().parents[2]
PAPER = """\
tube: {R_outer: 3.92e-3, r_inner: 1.55e-3}
material: {E: 1.85e9}
tendons:
  - {offset: 2.75e-3, routing: paper}
segments:
  - tube: 5.0e-3
  - repeat: 8
    segments:
      - notch: {width: 2.0e-3, band: 1.4e-3, profile: circular}
      - tube: 4.0e-3
"""


@pytest.mark.parametrize("name", sorted(PRESETS))
@pytest.mark.parametrize("profile", ["circular", "rectangular"])
def test_every_preset_through_its_body_file_is_the_preset(name: str, profile: str,
                                                          tmp_path: Path) -> None:
    design = preset(name).with_overrides(profile=profile)
    path = tmp_path / "body.yaml"
    path.write_text(body_file_text(design), encoding="utf-8")
    assert read_body_file(path).design() == design


def test_the_shipped_paper_body_is_written_from_the_preset_and_solves_bit_for_bit() -> None:
    design = preset("paper-experiment")
    path = REPO / "config" / "bodies" / "paper_experiment.yaml"
    text = path.read_text(encoding="utf-8")
    assert text.split("\n", 2)[2] == body_file_text(design)  # after its two comment lines
    through_file = solve(read_body_file(path).design(), 20.0)
    direct = solve(design, 20.0)
    assert np.array_equal(through_file.positions, direct.positions)
    assert np.array_equal(through_file.theta, direct.theta)


def test_a_hand_written_body_is_read_as_written() -> None:
    body = body_from_mapping(load_yaml(PAPER, "paper.yaml"), "paper.yaml")
    design = body.design()
    want = preset("paper-experiment")
    for field in ("w_base", "w_tip", "w_n", "w_t", "w_d", "R_outer", "r_inner", "R_c", "E"):
        assert getattr(design, field) == pytest.approx(getattr(want, field), rel=1e-15), field
    assert design.N == 8 and design.profile.name == "circular"
    assert len(body.segments) == 17 and body.routing == "paper"


def with_changes(**changes: object) -> dict[str, object]:
    data = load_yaml(PAPER, "paper.yaml")
    for path, value in changes.items():
        *parents, leaf = path.split("__")
        node = data
        for key in parents:
            node = node[int(key)] if key.isdigit() else node[key]
        if value is None:
            del node[int(leaf) if leaf.isdigit() else leaf]
        else:
            node[int(leaf) if leaf.isdigit() else leaf] = value
    return data


NOTCH = "segments__1__segments__0__notch"
BAD = [
    (with_changes(tube=None), r"tube is missing"),
    (with_changes(tube__R_outer=0.0), r"tube\.R_outer = 0\.0 is out of range; allowed: \(0, 0\.5\]"),
    (with_changes(tube__r_inner=4e-3), r"tube\.r_inner = 0\.004 .*allowed: \[0, 0\.00392\)"),
    (with_changes(material__E="stiff"), r"material\.E = 'stiff' .*a number"),
    (with_changes(material__E=float("nan")), r"material\.E = nan"),
    (with_changes(material__E=True), r"material\.E = True"),
    (with_changes(tendons=[]), r"tendons = 0 .*a list of 1 to 16 tendons"),
    (with_changes(tendons__0__offset=3.92e-3), r"tendons\[0\]\.offset = 0\.00392"),
    (with_changes(tendons__0__offset=-3.92e-3), r"tendons\[0\]\.offset = -0\.00392"),
    (with_changes(tendons__0__offset=0.0), r"tendons\[0\]\.offset = 0\.0 .*0 < \|offset\|"),
    (with_changes(tendons=[{"offset": 1e-3}, {"offset": 0.6, "guides": "external"}]),
     r"tendons\[1\]\.offset = 0\.6 .*\(-0\.5, 0\.5\)"),
    (with_changes(tendons__0__routing="around"), r"tendons\[0\]\.routing = 'around'"),
    (with_changes(tendons__0__guides="rails"), r"tendons\[0\]\.guides = 'rails'"),
    (with_changes(tendons__0__anchor=0.01),
     (r"body\.yaml: tendons\[0\]\.anchor = 0\.01 .*a segment boundary after the base, m "
     r"\(0\.005, 0\.007, 0\.011")),
    (with_changes(tendons__0__anchor=0.06), r"tendons\[0\]\.anchor = 0\.06 .*segment boundary"),
    (with_changes(tendons__0__name="1st"), r"tendons\[0\]\.name = '1st' .*ROS name token"),
    (with_changes(tendons=[{"offset": 1e-3, "name": "a"}, {"offset": -1e-3, "name": "a"}]),
     r"tendons\[\]\.name = \['a', 'a'\] .*distinct names"),
    (with_changes(tendons__0__stiffness=0.0), r"tendons\[0\]\.stiffness = 0\.0 .*\(0, 1e\+12\]"),
    (with_changes(tendons__0__slack=-1.0), r"tendons\[0\]\.slack = -1\.0 .*\[0, 1\]"),
    (with_changes(tendons__0__spring=1.0), r"unknown tendon key 'spring'"),
    (with_changes(segments=[]), r"segments = \[\] .*non-empty"),
    (with_changes(segments__0={"tube": 1e-3, "notch": {}}), r"segments\[0\] has \['tube', 'notch'\]"),
    (with_changes(segments__0={"tube": 0.0}), r"segments\[0\]\.tube = 0\.0 is out of range"),
    (with_changes(segments__1__repeat=0), r"segments\[1\]\.repeat = 0 .*\[1, 10000\]"),
    (with_changes(segments__1__repeat=True), r"segments\[1\]\.repeat = True"),
    (with_changes(segments__1__repeat=6000), r"segments\[1\]\.repeat = 6000 .*at most 10000"),
    (with_changes(**{f"{NOTCH}__band": None}), r"segments\[1\]\.segments\[0\]\.notch has none"),
    (with_changes(**{f"{NOTCH}__cut": 1e-3}), r"notch has \['band', 'cut'\]"),
    (with_changes(**{f"{NOTCH}__band": 7.84e-3}), r"notch\.band = 0\.00784 .*\(0, 0\.00784\)"),
    (with_changes(**{f"{NOTCH}__width": -1.0}), r"notch\.width = -1"),
    (with_changes(**{f"{NOTCH}__profile": "oval"}), r"notch\.profile = 'oval'"),
    (with_changes(**{f"{NOTCH}__depth": 1.0}), r"unknown segments\[1\]\.segments\[0\]\.notch key"),
    (with_changes(**{f"{NOTCH}": {"width": 1e-3, "cut": 8e-3}}), r"notch\.cut = 0\.008 .*\(0, 0\.00784\)"),
    (with_changes(**{f"{NOTCH}": {"width": 1e-3, "cut": 1e-3, "offset": 0.0}}),
     r"notch\.offset goes with band only"),
    (with_changes(**{f"{NOTCH}": {"width": 1e-3, "polygon": [[0, -1e-3], [1e-3, 0], [0, 1e-3]],
                                  "profile": "circular"}}),
     r"notch\.profile goes with band or cut only"),
    (with_changes(**{f"{NOTCH}__offset": -3.3e-3}),
     r"segments\[1\]\.segments\[0\]\.notch\.offset = -0\.0033 .*\[-0\.00322, 0\.00322\] m"),
    (with_changes(**{f"{NOTCH}__offset": "left"}), r"notch\.offset = 'left'"),
    (with_changes(**{f"{NOTCH}": {"width": 1e-3, "polygon": [[0, 0], [1e-3, 1e-3], [1e-3, 0],
                                                            [0, 1e-3]]}}),
     r"segments\[1\]\.segments\[0\]\.notch: polygon is not a simple polygon.*Self-intersection"),
    (with_changes(**{f"{NOTCH}": {"width": 1e-3, "polygon": [[0, 0], [1e-3]]}}),
     r"notch\.polygon = \[1e-3\]|notch\.polygon = \[0\.001\]"),
]


@pytest.mark.parametrize(("data", "message"), BAD, ids=[m for _, m in BAD])
def test_bad_bodies_name_the_key_by_its_path(data: dict[str, object], message: str) -> None:
    with pytest.raises(InvalidDesignError, match=message):
        body_from_mapping(data, "body.yaml").design()


BAND = {"notch": {"width": 2.0e-3, "band": 1.4e-3}}


TEE = [[-3.5e-3, -1.5e-3], [-2.5e-3, -1.5e-3], [-2.5e-3, -0.3e-3], [0.5e-3, -0.3e-3],
       [0.5e-3, 0.3e-3], [-2.5e-3, 0.3e-3], [-2.5e-3, 1.5e-3], [-3.5e-3, 1.5e-3]]


def test_a_polygon_notch_is_read_as_its_polygon_and_written_back_bit_for_bit() -> None:
    """A polygon notch becomes a prismatic :class:`PolygonProfile` whose ``w_d`` and ``w_o``
    are its extent in x and that extent's middle; holes are kept; the body file written from
    the design reads back to the same design."""
    box = [[-1e-3, -1e-3], [1e-3, -1e-3], [1e-3, 1e-3], [-1e-3, 1e-3]]
    lumen = [[-0.4e-3, -0.4e-3], [0.4e-3, -0.4e-3], [0.4e-3, 0.4e-3], [-0.4e-3, 0.4e-3]]
    data = with_changes(segments=[
        BAND, {"tube": 4e-3}, {"notch": {"width": 2.0e-3, "polygon": TEE}},
        {"notch": {"width": 1.0e-3, "polygon": box, "holes": [lumen]}}])
    design = body_from_mapping(data, "body.yaml").design()
    profiles = design.notch_profiles()
    assert isinstance(profiles[1], PolygonProfile) and isinstance(profiles[2], PolygonProfile)
    assert profiles[1].shell == tuple(tuple(p) for p in TEE)
    assert profiles[2].holes == (tuple(tuple(p) for p in lumen),)
    assert design.w_d == (1.4e-3, 4.0e-3, 2.0e-3)
    assert design.w_o == (0.0, -1.5e-3, 0.0)
    again = body_from_mapping(load_yaml(body_file_text(design), "again.yaml"), "again.yaml").design()
    assert again == design


def test_a_section_given_by_its_numbers_is_read_and_a_mesh_body_written_back_as_them() -> None:
    """``section:`` (area, centroid, I, extent: SI units) is a prismatic notch; a mesh body's
    design is written with its slices as such sections and reads back bit for bit."""
    given = {"area": 6.7e-6, "centroid_x": -2.3e-3, "second_moment": 3.2e-12, "x_low": -3.5e-3,
             "x_high": 0.5e-3}
    data = with_changes(segments=[BAND, {"tube": 4e-3}, {"notch": {"width": 2e-3,
                                                                   "section": given}}])
    design = body_from_mapping(data, "body.yaml").design()
    section = design.notch_profiles()[1]
    assert isinstance(section, SectionProfile) and section.area == 6.7e-6
    assert design.w_d == (1.4e-3, 4.0e-3) and design.w_o == (0.0, -1.5e-3)
    mesh = read_body_file(Path(__file__).resolve().parents[2] / "config" / "bodies"
                          / "tee_mesh.yaml").design()
    again = body_from_mapping(load_yaml(body_file_text(mesh), "again.yaml"), "again.yaml").design()
    assert again == mesh
    bad = dict(given, centroid_x=1e-3)
    with pytest.raises(InvalidDesignError, match=r"notch\.section\.centroid_x = 0\.001 is out of "
                       r"range; allowed: \(-0\.0035, 0\.0005\)"):
        body_from_mapping(with_changes(segments=[{"notch": {"width": 2e-3, "section": bad}}]),
                          "body.yaml")
    for key, value, unit in (("area", 1.0, "m\\^2"), ("second_moment", 2.0, "m\\^4")):
        with pytest.raises(InvalidDesignError, match=rf"section\.{key} = {value} is out of range;"
                           rf" allowed: \(0, .*\] {unit}$"):
            body_from_mapping(with_changes(segments=[{"notch": {"width": 2e-3, "section": dict(
                given, **{key: value})}}]), "body.yaml")


def test_a_polygon_outside_the_tube_is_refused_naming_its_segment() -> None:
    data = with_changes(segments=[BAND, {"tube": 4e-3}, {"notch": {
        "width": 2.0e-3, "polygon": [[-3.5e-3, -2e-3], [0.5e-3, -2e-3], [0.5e-3, 2e-3]]}}])
    with pytest.raises(InvalidDesignError, match=r"segments\[2\]\.notch\.polygon = 0\.00403"
                       r".* within R_outer = 0\.00392 m"):
        body_from_mapping(data, "body.yaml").design()


def test_a_cut_is_a_band_of_the_rest_of_the_tube_off_the_axis_and_an_offset_band_is_read(
        ) -> None:
    """``cut: c`` leaves ``2 R_outer - c`` of the tube on the -x side (a band that wide at
    ``offset = -c/2``, rectangular unless the file says otherwise); a band may be moved off
    the axis with ``offset``; the written body file reads back bit for bit."""
    data = with_changes(segments=[
        BAND, {"tube": 4e-3}, {"notch": {"width": 2.0e-3, "cut": 6.4e-3}},
        {"notch": {"width": 1.5e-3, "band": 1.2e-3, "offset": 0.5e-3}},
        {"notch": {"width": 1.0e-3, "cut": 5e-3, "profile": "circular"}}])
    design = body_from_mapping(data, "body.yaml").design()
    assert design.w_d == (1.4e-3, 2 * 3.92e-3 - 6.4e-3, 1.2e-3, 2 * 3.92e-3 - 5e-3)
    assert design.w_o == (0.0, -3.2e-3, 0.5e-3, -2.5e-3)
    assert [p.name for p in design.notch_profiles()] == ["circular", "rectangular", "circular",
                                                        "circular"]
    again = body_from_mapping(load_yaml(body_file_text(design), "again.yaml"), "again.yaml").design()
    assert again == design


def test_notches_of_different_profiles_are_read_per_notch() -> None:
    data = with_changes(segments=[
        BAND, {"tube": 4e-3}, {"notch": {"width": 2.0e-3, "band": 1.4e-3,
                                         "profile": "rectangular"}}])
    design = body_from_mapping(data, "body.yaml").design()
    assert [p.name for p in design.notch_profiles()] == ["circular", "rectangular"]
    assert not design.is_uniform


def test_notches_that_differ_are_read_per_notch_with_the_tubes_between_them() -> None:
    data = with_changes(segments=[
        {"tube": 5e-3}, BAND, {"tube": 4e-3}, {"notch": {"width": 2.5e-3, "band": 1.2e-3}},
        {"notch": {"width": 2.0e-3, "band": 1.0e-3}}, {"tube": 1e-3}, {"tube": 2e-3}, BAND,
        {"tube": 4e-3}])
    design = body_from_mapping(data, "body.yaml").design()
    assert (design.N, design.w_base, design.w_tip) == (4, 5e-3, 4e-3)
    assert design.w_n == (2.0e-3, 2.5e-3, 2.0e-3, 2.0e-3)
    assert design.w_d == (1.4e-3, 1.2e-3, 1.0e-3, 1.4e-3)
    assert design.w_t == (4e-3, 0.0, 1e-3 + 2e-3)   # adjacent notches: no tube; tubes joined
    assert design.profile.name == "circular"   # every notch the default: one profile
    left, right = design.notch_bounds()
    assert left.tolist() == pytest.approx([5e-3, 11e-3, 13.5e-3, 18.5e-3], abs=1e-15)
    assert design.length == pytest.approx(right[-1] + 4e-3, abs=1e-15)


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6).flatmap(lambda n: st.tuples(
    st.lists(st.sampled_from([1.0e-3, 1.5e-3, 2.0e-3]), min_size=n, max_size=n),
    st.lists(st.sampled_from([0.8e-3, 1.1e-3, 1.4e-3]), min_size=n, max_size=n),
    st.lists(st.sampled_from([0.0, 2.0e-3, 4.0e-3]), min_size=n - 1, max_size=n - 1),
    st.sampled_from([0.0, 3.0e-3]),
    st.lists(st.sampled_from(["circular", "rectangular"]), min_size=n, max_size=n),
    st.lists(st.sampled_from([0.0, -3.22e-3 + 0.4e-3, 0.3e-3]), min_size=n, max_size=n))))
def test_a_per_notch_design_round_trips_through_its_body_file(case: tuple) -> None:
    widths, bands, gaps, ends, profile, offsets = case
    design = preset("paper-experiment").with_overrides(
        N=len(widths), w_n=widths, w_d=bands, w_t=gaps, w_base=ends, w_tip=ends,
        profile=profile, w_o=offsets)
    text = body_file_text(design)
    assert body_from_mapping(load_yaml(text, "body"), "body").design() == design


def test_solve_takes_a_body_file_and_its_routing(tmp_path: Path) -> None:
    path = tmp_path / "paper.yaml"
    path.write_text(body_file_text(preset("paper-experiment"), routing="free"), encoding="utf-8")
    from_file = tdcm("solve", "--design", str(path), "--tension", "20", "--json")
    assert from_file.returncode == 0, from_file.stderr
    as_preset = tdcm("solve", "--design", "paper-experiment", "--routing", "free", "--tension",
                     "20", "--json")
    summary = json.loads(from_file.stdout)
    assert summary["settings"]["routing"] == "free"
    assert summary["tip_position_m"] == json.loads(as_preset.stdout)["tip_position_m"]
    overridden = tdcm("solve", "--design", str(path), "--routing", "paper", "--set", "E=1.2e9",
                      "--tension", "20", "--json")
    assert json.loads(overridden.stdout)["settings"]["routing"] == "paper"
    assert json.loads(overridden.stdout)["design"]["E"] == 1.2e9
    bad = tmp_path / "bad.yaml"
    bad.write_text(PAPER.replace("3.92e-3", "-1"), encoding="utf-8")
    refused = tdcm("solve", "--design", str(bad), "--tension", "20")
    assert refused.returncode == 2
    assert f"{bad}: tube.R_outer = -1 is out of range" in refused.stderr


def test_the_shipped_variable_depth_wrist_bends_its_tip_first() -> None:
    design = read_body_file(REPO / "config" / "bodies" / "variable_depth.yaml").design()
    assert design == preset("paper-experiment").with_overrides(
        r_inner=1.55e-3, w_d=[1.6e-3, 1.5e-3, 1.4e-3, 1.3e-3, 1.2e-3, 1.1e-3, 1.0e-3, 0.9e-3])
    angles = solve(design, 10.0).notch_angles_rad
    assert np.all(np.diff(angles) > 0.0) and angles[-1] > 4.0 * angles[0]


def test_the_shipped_tip_first_wrist_is_four_one_sided_cuts_that_bend_the_tip_first() -> None:
    design = read_body_file(REPO / "config" / "bodies" / "tip_first_wrist.yaml").design()
    depths = [1.36e-3, 1.39e-3, 1.42e-3, 1.45e-3]
    assert design.w_o == tuple(-c / 2 for c in depths)
    assert design.w_d == tuple(2 * 0.81e-3 - c for c in depths)
    assert [p.name for p in design.notch_profiles()] == ["rectangular"] * 4
    result = solve(design, 1.0)
    assert np.all(np.diff(result.notch_angles_rad) > 0.0)
    centred = solve(design.with_overrides(w_o=0.0), 1.0)  # the same backbones on the axis
    assert result.tip_angle_rad > 1.1 * centred.tip_angle_rad
    assert np.all(result.notch_stop_margins_rad + result.notch_angles_rad
                  < 0.8 * (centred.notch_stop_margins_rad + centred.notch_angles_rad))
