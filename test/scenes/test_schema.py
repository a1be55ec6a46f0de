"""Scene files: validation messages, shipped scenes and where they are found."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import yaml

from tdcm_ros.errors import InputError
from tdcm_ros.scenes import (
    REGISTRY,
    SCENE_NAMES,
    InvalidSceneError,
    load_scene,
    scene_from_text,
)
from tdcm_ros.scenes.paths import SCENES_ENV, shipped_scenes
from test.scenes.scene_helpers import make_scene

REQUIRED = {"ideal", "paper_experiment", "friction_hysteresis", "gravity_horizontal", "tip_load",
            "mocap_dropout", "near_singular"}


def test_required_scenes_are_shipped() -> None:
    assert REQUIRED <= set(SCENE_NAMES)


@pytest.mark.parametrize("name", sorted(shipped_scenes()))
def test_every_shipped_scene_loads(name: str) -> None:
    scene = load_scene(name)
    assert scene.name == name
    assert scene.description
    assert set(scene.effects) <= set(REGISTRY)
    assert scene.schedule.levels and scene.tension_rate_hz > 0 and scene.mocap_rate_hz > 0
    assert max(scene.marker_arc_lengths) <= scene.design.length


def test_defaults_are_the_papers_protocol() -> None:
    scene = scene_from_text("{}")
    assert scene.schedule.levels == (0.0, 4.0, 8.0, 12.0, 16.0, 20.0)
    assert scene.schedule.trials == 3
    assert scene.marker_arc_lengths == (0.015, 0.033, 0.053)
    assert scene.marker_labels == ("m1", "m2", "m3")
    assert scene.marker_radius == pytest.approx(scene.design.R_outer + 0.001)
    assert scene.true_design == scene.design
    assert scene.effects == {}


def test_true_and_nominal_material_differ_in_paper_experiment() -> None:
    scene = load_scene("paper_experiment")
    assert scene.design.E == pytest.approx(1.85e9)
    assert scene.true_design.E < scene.design.E
    assert scene.true_design.with_overrides(E=scene.design.E) == scene.design


def _error(text: str) -> InvalidSceneError:
    with pytest.raises(InvalidSceneError) as info:
        scene_from_text(text)
    assert isinstance(info.value, InputError)
    return info.value


def test_unknown_top_key_lists_the_valid_ones() -> None:
    error = _error("sede: 3\n")
    assert "'sede'" in str(error) and "seed" in str(error) and "effects" in str(error)


def test_unknown_key_in_a_section_lists_the_valid_ones() -> None:
    error = _error("schedule: {level: [1, 2]}\n")
    assert "'level'" in str(error) and "levels" in str(error) and "hold_s" in str(error)


def test_unknown_effect_lists_every_registered_effect() -> None:
    error = _error("effects: {friction: {mu: 0.1}}\n")
    assert "'friction'" in str(error)
    for name in REGISTRY:
        assert name in str(error)


def test_unknown_effect_parameter_lists_the_valid_ones() -> None:
    error = _error("effects: {tendon_friction: {muu: 0.1}}\n")
    assert "'muu'" in str(error) and "mu" in str(error)


@pytest.mark.parametrize(("text", "key", "allowed"), [
    ("effects: {tendon_friction: {mu: 5}}", "effects.tendon_friction.mu", "[0, 2]"),
    ("effects: {marker_noise: {std_m: -1e-4}}", "effects.marker_noise.std_m", "[0, 0.01] m"),
    ("effects: {load_cell: {quantum_counts: 0.5}}", "effects.load_cell.quantum_counts",
     "integer in [1, 10000]"),
    ("effects: {marker_dropout: {burst_scope: some}}", "effects.marker_dropout.burst_scope",
     "one | all"),
    ("schedule: {hold_s: 0}", "schedule.hold_s", "(0, 3600] s"),
    ("schedule: {levels: [0, 30]}", "schedule.levels", "[0, 22] N"),
    ("sensors: {mocap_hz: .nan}", "sensors.mocap_hz", "(0, 10000] Hz"),
    ("seed: -1", "seed", "[0, 4294967295]"),
    ("mocap_frame: {rpy_deg: [1, 2]}", "mocap_frame.rpy_deg", "3 numbers"),
    ("material: {E: abc}", "material.E", "(0, 1e+12] Pa"),
])
def test_bad_value_names_the_parameter_and_range(text: str, key: str, allowed: str) -> None:
    error = _error(text)
    assert error.parameter == key
    assert key in str(error) and allowed in str(error)


@pytest.mark.parametrize(("text", "key"), [
    ("effects: {gravity: {direction: [0, 1, 0]}}", "effects.gravity.direction"),
    ("effects: {gravity: {direction: [0, 0, 0]}}", "effects.gravity.direction"),
    ("effects: {tip_load: {force_n: [0, 0.1, 0]}}", "effects.tip_load.force_n"),
    ("effects: {latency: {markers_s: 0.001, markers_jitter_s: 0.002}}",
     "effects.latency.markers_jitter_s"),
    ("effects: {marker_offset: {arc_offset_m: [0.001, 0.0]}}", "effects.marker_offset.arc_offset_m"),
    ("effects: {marker_offset: {arc_offset_m: [0.001]}}", "effects.marker_offset.arc_offset_m"),
    ("markers: {labels: [a, b]}", "markers.labels"),
    ("markers: {labels: [a, a, b]}", "markers.labels"),
    ("markers: {arc_lengths: [0.01, 0.02, 0.06]}", "markers.arc_lengths"),
])
def test_inconsistent_values_are_rejected(text: str, key: str) -> None:
    assert _error(text).parameter == key


def test_design_errors_name_the_field() -> None:
    with pytest.raises(InputError, match="w_d"):
        scene_from_text("design: {overrides: {w_d: -1}}")
    with pytest.raises(InputError, match="unknown design field 'wd'"):
        scene_from_text("design: {overrides: {wd: 0.001}}")
    with pytest.raises(InputError, match="unknown design preset"):
        scene_from_text("design: {preset: nope}")


def test_yaml_11_exponent_without_sign_is_a_number() -> None:
    scene = scene_from_text("design: {overrides: {E: 1.2e9}}\nmaterial: {E: 7e8}\n")
    assert scene.design.E == 1.2e9 and scene.true_design.E == 7e8


def test_not_yaml_and_not_a_mapping() -> None:
    assert "not valid YAML" in str(_error("effects: [\n"))
    assert _error("- 1\n- 2\n").parameter == "scene"
    assert _error("effects: [gravity]\n").parameter == "effects"


def test_unknown_scene_name_lists_the_shipped_ones() -> None:
    with pytest.raises(InvalidSceneError) as info:
        load_scene("paper")
    assert "paper_experiment" in str(info.value) and "ideal" in str(info.value)
    with pytest.raises(InvalidSceneError, match="cannot be read"):
        load_scene("/nonexistent/scene.yaml")


def test_scene_found_through_env_and_installed_share(tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    env_dir = tmp_path / "mine"
    env_dir.mkdir()
    (env_dir / "custom.yaml").write_text("description: from TDCM_SCENES\n")
    monkeypatch.setenv(SCENES_ENV, str(env_dir))
    assert load_scene("custom").description == "from TDCM_SCENES"
    monkeypatch.delenv(SCENES_ENV)
    share = tmp_path / "prefix" / "share" / "tdcm_ros" / "config" / "scenes"
    share.mkdir(parents=True)
    (share / "installed_only.yaml").write_text("description: installed\n")
    monkeypatch.setattr(sys, "prefix", str(tmp_path / "prefix"))
    assert load_scene("installed_only").description == "installed"
    with pytest.raises(InvalidSceneError):
        load_scene("custom")


def test_load_from_path_uses_the_stem_as_name(tmp_path: Path) -> None:
    path = tmp_path / "bench_a.yaml"
    path.write_text(yaml.safe_dump({"effects": {"marker_noise": {"std_m": 2e-4}}}))
    scene = load_scene(path)
    assert scene.name == "bench_a" and scene.source == path
    assert scene.effects == {"marker_noise": {"std_m": 2e-4}}


def test_without_and_effect_names() -> None:
    scene = make_scene({"gravity": {}, "marker_noise": {}, "latency": {}})
    assert scene.effect_names("mechanics") == ("gravity",)
    assert scene.without("gravity").effect_names() == ("marker_noise", "latency")
    with pytest.raises(InvalidSceneError, match="tip_load"):
        scene.without("tip_load")


@pytest.mark.parametrize(("old", "new", "value", "field"), [
    ("ball_radius_m", "ball_radius", 0.002, "marker_ball_radius"),
    ("radial_offset_m", "radial_offset", 0.006, "marker_radial_offset"),
    ("arc_lengths_m", "arc_lengths", [0.01, 0.02, 0.04], "marker_arc_lengths"),
])
def test_a_former_marker_key_still_reads_and_warns(old: str, new: str, value: object,
                                                   field: str) -> None:
    """The markers keys are the node parameters' names; a scene file's former ``*_m`` name
    gives the same scene, with a DeprecatedNameWarning naming the new key."""
    from tdcm_ros.spec import DeprecatedNameWarning

    current = scene_from_text(f"markers: {{{new}: {value}}}")
    with pytest.warns(DeprecatedNameWarning, match=f"markers.{old} is deprecated; use "
                                                   f"markers.{new}"):
        former = scene_from_text(f"markers: {{{old}: {value}}}")
    assert getattr(former, field) == getattr(current, field)
    assert getattr(current, field) != getattr(scene_from_text(""), field)


def test_a_former_key_beside_the_current_one_is_ignored_and_warned() -> None:
    from tdcm_ros.spec import DeprecatedNameWarning

    with pytest.warns(DeprecatedNameWarning, match=r"ball_radius_m is deprecated; use markers"
                      r"\.ball_radius \(same meaning\); ignored, markers\.ball_radius is set too"):
        scene = scene_from_text("markers: {ball_radius: 0.002, ball_radius_m: 0.003}")
    assert scene.marker_ball_radius == 0.002


def test_a_scene_takes_its_design_from_a_body_file_beside_it(tmp_path: Path) -> None:
    from tdcm_ros.model import body_file_text, preset
    from tdcm_ros.scenes import load_scene

    (tmp_path / "bodies").mkdir()
    (tmp_path / "bodies" / "fig3.yaml").write_text(body_file_text(preset("fig3-wd-2")), "utf-8")
    scene = tmp_path / "scene.yaml"
    scene.write_text("design: {file: bodies/fig3.yaml, overrides: {E: 1.2e9}}\n", "utf-8")
    assert load_scene(scene).design == preset("fig3-wd-2").with_overrides(E=1.2e9)
    scene.write_text("design: {file: bodies/fig3.yaml, preset: fig2-wn-1}\n", "utf-8")
    with pytest.raises(InputError, match="design has both preset and file"):
        load_scene(scene)
    scene.write_text("design: {file: bodies/none.yaml}\n", "utf-8")
    with pytest.raises(InputError, match="cannot read body file .*none.yaml"):
        load_scene(scene)
