"""Scene keys that set a package dataclass's field are that field's spec, renamed: a scene spec
that drifts from its source (a unit, a meaning, a default or a range typed again by hand) fails
here. Each difference a scene keeps is listed below with the reason given in the source."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import pytest

from tdcm_ros.device import PLANT_SPECS, SCHEDULE_SPECS
from tdcm_ros.model import FIELD_SPECS, MARKER_SPECS
from tdcm_ros.scenes import REGISTRY
from tdcm_ros.scenes.schema import SECTIONS
from tdcm_ros.spec import Spec

#: scene key -> (source spec, the one change the scene makes: a default and/or a cap, or the
#: former names it still reads)
DERIVED: dict[str, tuple[Spec, dict[str, Any]]] = {
    "material.E": (FIELD_SPECS["E"], {"default": None}),
    "schedule.levels": (SCHEDULE_SPECS["levels"], {"high": 22.0}),
    "schedule.trials": (SCHEDULE_SPECS["trials"], {"default": 3, "high": 1000}),
    "markers.labels": (MARKER_SPECS["labels"], {}),
    "markers.arc_lengths": (MARKER_SPECS["arc_lengths"], {"formerly": ("arc_lengths_m",)}),
    "markers.ball_radius": (MARKER_SPECS["ball_radius"], {"formerly": ("ball_radius_m",)}),
    "markers.side_deg": (MARKER_SPECS["side_deg"], {}),
    "markers.radial_offset": (MARKER_SPECS["radial_offset"], {"formerly": ("radial_offset_m",)}),
    "effects.actuator_dynamics.lag_s": (PLANT_SPECS["lag"], {"high": 10.0}),
    "effects.actuator_dynamics.rate_m_per_s": (PLANT_SPECS["rate"], {"high": 10.0}),
    "effects.actuator_dynamics.deadband_m": (PLANT_SPECS["deadband"], {"high": 0.01}),
    "effects.load_cell.noise_n": (PLANT_SPECS["noise"], {"high": 10.0}),
    "effects.load_cell.bias_n": (PLANT_SPECS["bias"], {"low": -10.0, "high": 10.0}),
    "effects.load_cell.quantum_counts": (PLANT_SPECS["quantum"], {"high": 10000}),
    "effects.load_cell.drift_n_per_s": (PLANT_SPECS["drift"], {"low": -1.0, "high": 1.0}),
    "effects.tendon_compliance.stiffness_n_per_m": (PLANT_SPECS["stiffness"], {"high": 1e7}),
    "effects.tendon_compliance.slack_m": (PLANT_SPECS["slack"], {"high": 0.02}),
}
#: scene keys whose range legitimately differs from the source's (schema.py says why)
OWN_RANGE = {"schedule.hold_s": (SCHEDULE_SPECS["hold"], {"default": 4.0, "low": 0.0,
                                                          "low_open": True, "high": 3600.0})}
#: sections and effects whose every key sets a field of these dataclasses
COVERED = ("schedule", "markers", "actuator_dynamics", "load_cell", "tendon_compliance")


def scene_specs() -> dict[str, Spec]:
    """Every scene spec by its full key (``schedule.hold_s``, ``effects.load_cell.bias_n``)."""
    specs = {f"{section}.{s.name}": s for section, group in SECTIONS.items() for s in group}
    specs.update({f"effects.{name}.{s.name}": s for name, cls in REGISTRY.items()
                  for s in cls.params})
    return specs


def expected(key: str) -> Spec:
    if key in OWN_RANGE:
        source, changes = OWN_RANGE[key]
        return replace(source, name=key.rsplit(".", 1)[1], **changes)
    derived_from, derived = DERIVED[key]
    default = derived.get("default", derived_from.default)
    return replace(derived_from.renamed(key.rsplit(".", 1)[1], default=default).narrowed(
        low=derived.get("low"), high=derived.get("high")),
        formerly=derived.get("formerly", derived_from.formerly))


@pytest.mark.parametrize("key", [*DERIVED, *OWN_RANGE])
def test_a_derived_scene_spec_equals_its_source_up_to_name_default_and_cap(key: str) -> None:
    assert scene_specs()[key] == expected(key)


@pytest.mark.parametrize("key", [k for k in scene_specs() if k.split(".")[-2] in COVERED])
def test_every_schedule_marker_and_actuation_key_is_derived(key: str) -> None:
    """A key added to these sections by hand, without a source spec, fails here."""
    assert key in DERIVED or key in OWN_RANGE

