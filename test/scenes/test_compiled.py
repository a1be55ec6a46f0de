"""The compile step: listed effects built per stage in file order, typed parts merged, a conflict
between two effects is a typed scene error, and the world runs the compiled bundle."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.model.loading import Loading, NotchContact
from tdcm_ros.scenes import (
    CONSTRUCTED,
    REGISTRY,
    STAGES,
    CompiledScene,
    EffectConflictError,
    InvalidSceneError,
    LoadingPart,
    PlantPart,
    World,
)
from tdcm_ros.scenes.compiled import WORLD_STAGES
from tdcm_ros.scenes.effects.actuation import ActuationEffect
from tdcm_ros.scenes.effects.mechanics import MechanicsEffect
from tdcm_ros.scenes.parts import Part
from test.scenes.scene_helpers import make_scene

#: the fields each shipped mechanics/actuation effect sets, from its documented job
SETS = {
    "tendon_friction": {"tension_profile"}, "gravity": {"body_force_density"},
    "tip_load": {"tip_force", "tip_moment"}, "notch_contact": {"notch_contact"},
    "actuator_dynamics": {"lag", "rate", "deadband"},
    "load_cell": {"noise", "bias", "quantum", "drift"},
    "tendon_compliance": {"stiffness", "slack"},
}


class Wind(MechanicsEffect):
    """A test effect that sets the same loading field as gravity."""

    name = "wind"
    summary = "test: a body force"

    def loading_part(self) -> LoadingPart:
        return LoadingPart(body_force_density=(5.0, 0.0))


class BenchNoise(ActuationEffect):
    """A test effect that sets the same plant field as the load cell."""

    name = "bench_noise"
    summary = "test: load-cell noise"

    def plant_part(self) -> PlantPart:
        return PlantPart(noise=0.5)


@pytest.fixture
def extra_effects(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(REGISTRY, "wind", Wind)
    monkeypatch.setitem(REGISTRY, "bench_noise", BenchNoise)


@pytest.mark.parametrize("name", sorted(SETS))
def test_each_effect_returns_a_typed_part_of_its_own_fields(name: str) -> None:
    compiled = make_scene({name: {}}).compile()
    loading_parts = [effect.loading_part() for effect in compiled.mechanics]
    plant_parts = [effect.plant_part() for effect in compiled.actuation]
    part: Part
    if REGISTRY[name].stage == "mechanics":
        assert plant_parts == [] and isinstance(compiled.loading, Loading)
        (part,) = loading_parts
        assert type(part) is LoadingPart
    else:
        assert loading_parts == [] and compiled.loading is None
        (part,) = plant_parts
        assert type(part) is PlantPart
    assert set(part.set_fields()) == SETS[name]


def test_the_merged_loading_holds_every_listed_part() -> None:
    scene = make_scene({"tip_load": {"force_n": [0.1, 0.0, 0.2], "moment_nm": 0.003},
                        "notch_contact": {"stiffness_factor": 3.0},
                        "gravity": {"direction": [-1, 0, 0], "g": 2.0}})
    loading = scene.compile().loading
    weight = scene.density * 2.0
    assert loading == Loading(tip_force=(0.1, 0.2), tip_moment=0.003,
                              body_force_density=(-weight, 0.0), notch_contact=NotchContact(3.0))


def test_plant_part_fields_land_on_the_plant_config() -> None:
    scene = make_scene({"load_cell": {"noise_n": 0.02, "bias_n": 0.05, "quantum_counts": 50,
                                      "drift_n_per_s": 1e-3}})
    assert scene.compile(("actuation",)).plant == PlantPart(noise=0.02, bias=0.05, quantum=50,
                                                            drift=1e-3)


def test_stages_are_built_in_file_order() -> None:
    order = ["marker_noise", "tip_load", "latency", "load_cell", "gravity", "marker_offset",
             "tendon_friction", "actuator_dynamics"]
    for names in (order, order[::-1]):
        compiled = make_scene({n: {} for n in names}).compile()
        for stage in STAGES:
            assert [e.name for e in compiled.stage(stage)] == \
                [n for n in names if REGISTRY[n].stage == stage]
        assert [e.name for e in compiled.mechanics] == \
            [n for n in names if n in ("tip_load", "gravity", "tendon_friction")]


@pytest.mark.usefixtures("extra_effects")
@pytest.mark.parametrize(("effects", "first", "second"), [
    (("gravity", "wind"), "gravity", "wind"), (("wind", "gravity"), "wind", "gravity")])
def test_two_effects_setting_one_loading_field_raise_naming_both(
        effects: tuple[str, str], first: str, second: str) -> None:
    scene = make_scene({n: {} for n in effects})
    with pytest.raises(EffectConflictError) as raised:
        scene.world()
    error = raised.value
    assert (error.first, error.second, error.field) == (first, second,
                                                        "Loading.body_force_density")
    assert f"effects.{first} and effects.{second} both set Loading.body_force_density" in \
        str(error)
    assert isinstance(error, InputError) and error.kind == "effect_conflict"
    scene.plant_config()  # the twin's plant does not compile the mechanics stage


@pytest.mark.usefixtures("extra_effects")
def test_two_effects_setting_one_plant_field_raise_naming_both() -> None:
    scene = make_scene({"load_cell": {}, "gravity": {}, "bench_noise": {}})
    with pytest.raises(EffectConflictError, match=r"effects\.load_cell and effects\.bench_noise "
                                                  r"both set PlantConfig\.noise"):
        scene.plant_config()
    scene.world()  # the world does not compile the actuation stage


def test_compile_builds_only_the_chosen_stages_of_the_listed_effects() -> None:
    scene = make_scene({"gravity": {}, "load_cell": {}, "marker_noise": {}, "latency": {}})
    before = dict(CONSTRUCTED)
    compiled = scene.compile(("actuation",))
    built = {n: CONSTRUCTED[n] - before.get(n, 0) for n in CONSTRUCTED}
    assert {n: c for n, c in built.items() if c} == {"load_cell": 1}
    assert compiled.mechanics == compiled.sensing == compiled.timing == ()
    assert compiled.loading is None and compiled.histories == ()
    with pytest.raises(InvalidSceneError, match="stage 'physics' unknown; allowed: mechanics"):
        scene.compile(("physics",))


def test_the_world_runs_the_bundle_it_is_given() -> None:
    scene = make_scene({"tendon_friction": {"mu": 0.2}, "marker_noise": {"std_m": 1e-4}})
    compiled = scene.compile(WORLD_STAGES)
    assert isinstance(compiled, CompiledScene) and compiled.actuation == ()
    world = World(compiled)
    assert world.mechanics is compiled.mechanics and world.loading is compiled.loading
    again = scene.world()
    for level in (4.0, 12.0, 8.0):
        np.testing.assert_array_equal(world.markers(0.1, level).positions,
                                      again.markers(0.1, level).positions)


def test_world_and_bundle_do_not_import_the_scene() -> None:
    root = Path(__file__).resolve().parents[2] / "tdcm_ros" / "scenes"
    for module in ("world.py", "compiled.py", "stages.py", "parts.py"):
        tree = ast.parse((root / module).read_text(encoding="utf-8"))
        imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
        assert "tdcm_ros.scenes.scene" not in imported, module
        assert "tdcm_ros.scenes.world" not in imported or module == "world.py", module
