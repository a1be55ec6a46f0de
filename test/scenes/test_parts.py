"""Partial records: they mirror Loading and PlantConfig, and merge in order or name a conflict."""

from __future__ import annotations

from dataclasses import fields
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.device.errors import DeviceInputError
from tdcm_ros.device.plant import PlantConfig
from tdcm_ros.errors import InputError
from tdcm_ros.model.loading import Loading, NotchContact
from tdcm_ros.scenes import EffectConflictError, LoadingPart, PlantPart, SceneError
from tdcm_ros.scenes.parts import merge

PLANT_FIELDS = tuple(f.name for f in fields(PlantPart))
#: a value each PlantPart field accepts in PlantConfig
VALID: dict[str, Any] = {"stroke": 0.03, "lag": 0.05, "rate": 0.01, "stiffness": 3000.0, "slack": 0.001,
         "counts_per_newton": 900.0, "tare_counts": 7000, "noise": 0.0, "quantum": 5,
         "deadband": 1e-4, "bias": 0.05, "drift": 1e-3}


def test_parts_mirror_the_records_they_set() -> None:
    assert [f.name for f in fields(LoadingPart)] == [f.name for f in fields(Loading)]
    scene_owned = {f.name for f in fields(PlantConfig)} - set(PLANT_FIELDS)
    assert scene_owned == {"sample_period", "seed"}
    assert set(VALID) == set(PLANT_FIELDS)


def test_a_zero_is_set_and_none_is_not() -> None:
    assert PlantPart(noise=0.0, bias=None).set_fields() == {"noise": 0.0}
    assert LoadingPart().set_fields() == {}
    assert LoadingPart().loading() == Loading()


def test_parts_build_their_records() -> None:
    contact = NotchContact(2.0)
    loading = LoadingPart(tip_force=(0.1, 0.0), notch_contact=contact).loading()
    assert loading == Loading(tip_force=(0.1, 0.0), notch_contact=contact)
    base = PlantConfig(noise=0.0, sample_period=0.01, seed=4)
    plant = PlantPart(lag=0.05, quantum=50).over(base)
    assert (plant.lag, plant.quantum, plant.noise, plant.sample_period, plant.seed) == \
        (0.05, 50, 0.0, 0.01, 4)
    with pytest.raises(DeviceInputError, match="deadband"):
        PlantPart(deadband=0.5).over(base)  # PlantConfig still validates the merged plant


@given(st.lists(st.lists(st.sampled_from(PLANT_FIELDS), unique=True, max_size=4), max_size=5))
def test_merge_is_the_union_or_names_a_conflict(claims: list[list[str]]) -> None:
    parts = [(f"e{i}", PlantPart(**{name: VALID[name] for name in names}))
             for i, names in enumerate(claims)]
    claimed = [name for names in claims for name in names]
    if len(set(claimed)) == len(claimed):
        assert merge(PlantPart, parts).set_fields() == {name: VALID[name] for name in claimed}
        return
    with pytest.raises(EffectConflictError) as raised:
        merge(PlantPart, parts)
    error = raised.value
    first, second = int(error.first[1:]), int(error.second[1:])
    name = error.field.removeprefix("PlantConfig.")
    assert first < second and name in claims[first] and name in claims[second]
    earlier = [n for names in claims[:second] for n in names]
    assert len(set(earlier)) == len(earlier)  # raised at the first effect that repeats a field
    assert f"effects.e{first} and effects.e{second} both set PlantConfig.{name}" in str(error)
    assert isinstance(error, SceneError) and isinstance(error, InputError)
    assert error.parameter == f"effects.e{second}"
