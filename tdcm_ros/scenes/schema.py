"""The scene file schema: top-level keys and the parameters of every section (SI units).

A scene file is a YAML mapping with the keys of :data:`TOP_KEYS`; each section's parameters
are :class:`~tdcm_ros.scenes.params.Param` tuples below, effects are checked against their
own. A key that sets a field of a package dataclass is derived from that field's spec (unit,
meaning, range and default declared once there): renamed to the scene key where it differs, its default replaced or its range narrowed where a scene differs, as said
beside it. :func:`schema_rows` lists everything for documentation.
"""

from __future__ import annotations

from dataclasses import replace

from tdcm_ros.device import SCHEDULE_SPECS
from tdcm_ros.device.constants import SETPOINT_MAX_MN
from tdcm_ros.model import FIELD_SPECS, MARKER_SPECS
from tdcm_ros.scenes.params import Param
from tdcm_ros.scenes.trajectory import TRAJECTORY

NYLON12_DENSITY = 1010.0  # kg/m^3, Formlabs Nylon 12 powder, printed part

TOP_KEYS: dict[str, str] = {
    "name": "scene name (defaults to the file's stem)",
    "description": "one line on what the scene is for",
    "seed": "random seed of every stochastic effect (integer >= 0)",
    "design": "the estimator's design: preset or body file + SI overrides (nominal material)",
    "material": "the world's true material (defaults: the design's)",
    "schedule": "tension staircase the driver runs",
    "sensors": "sensor rates",
    "markers": "nominal marker placement (the estimator's and, without marker_offset, the world's)",
    "mocap_frame": "true pose of tdcm_base in the mocap frame",
    "effects": "mapping effect name -> parameters (empty mapping: defaults); only these run",
    "trajectory": "optional: a circle of tip targets the demo follows (tdcm demo tracks it)",
}

DESIGN = (
    Param("preset", "", "design preset of tdcm_ros.model", "paper-experiment", kind="str"),
)  # plus ``overrides``: Design fields in SI units, checked by Design.with_overrides

MATERIAL = (
    FIELD_SPECS["E"].renamed("E", default=None),  # the world's true E; None: the design's
    Param("density", "kg/m^3", "density of the body (for gravity)", NYLON12_DENSITY, low=0.0,
          low_open=True, high=1e5),
)

SCHEDULE = (
    # the paper's staircase, at most the device's largest setpoint: the driver leaves that
    # check to the device (its node parameters keep their own range and messages), a scene
    # refuses a level the twin's device would reject when the file is loaded
    SCHEDULE_SPECS["levels"].narrowed(high=SETPOINT_MAX_MN / 1000),
    # range kept from the scene files' own, (0, 3600] s, not the driver's [0.01 s, 1 day]: a
    # scene is simulated, so the cap bounds a world's run, and the range scene files and
    # `tdcm scene` have always shown stays; StepSchedule still refuses a hold under 0.01 s
    replace(SCHEDULE_SPECS["hold"], default=4.0, low=0.0, low_open=True, high=3600.0),
    # a scene repeats the paper's 3 trials by default; at most 1000 bounds a simulated run
    SCHEDULE_SPECS["trials"].renamed("trials", default=3).narrowed(high=1000),
)

SENSORS = (
    Param("tension_hz", "Hz", "load-cell sample rate", 80.0, low=0.0, low_open=True,
          high=10000.0),
    Param("mocap_hz", "Hz", "motion-capture frame rate", 100.0, low=0.0, low_open=True,
          high=10000.0),
)

MARKERS = (
    MARKER_SPECS["labels"],
    # the node parameters' names (markers.<field>); the scene files' former *_m names still read
    replace(MARKER_SPECS["arc_lengths"], formerly=("arc_lengths_m",)),
    replace(MARKER_SPECS["ball_radius"], formerly=("ball_radius_m",)),
    MARKER_SPECS["side_deg"],
    replace(MARKER_SPECS["radial_offset"], formerly=("radial_offset_m",)),
)

MOCAP_FRAME = (
    Param("translation_m", "m", "origin of tdcm_base in mocap", (0.0, 0.0, 0.0), kind="vector",
          low=-100.0, high=100.0),
    Param("rpy_deg", "deg", "roll, pitch, yaw of tdcm_base in mocap (fixed axes x, y, z)",
          (0.0, 0.0, 0.0), kind="vector", low=-360.0, high=360.0),
)

SECTIONS: dict[str, tuple[Param, ...]] = {
    "design": DESIGN, "material": MATERIAL, "schedule": SCHEDULE, "sensors": SENSORS,
    "markers": MARKERS, "mocap_frame": MOCAP_FRAME,
    "trajectory": TRAJECTORY,  # optional: parsed only when the file has it
}


def schema_rows() -> list[dict[str, str]]:
    """One row per key: ``key, unit, default, allowed, description``."""
    rows = [{"key": key, "unit": "", "default": "", "allowed": "", "description": text}
            for key, text in TOP_KEYS.items() if key not in SECTIONS]
    for section, specs in SECTIONS.items():
        for spec in specs:
            rows.append({"key": f"{section}.{spec.name}", "unit": spec.unit,
                         "default": repr(spec.default), "allowed": spec.allowed(),
                         "description": spec.description})
        if section == "design":
            rows.append({"key": "design.file", "unit": "", "default": "",
                         "allowed": "a body file (.yaml), relative to the scene file",
                         "description": "instead of design.preset: a body file (read with the "
                                        "scene)"})
            rows.append({"key": "design.overrides", "unit": "SI", "default": "{}",
                         "allowed": "Design fields (w_base, ..., E, profile)",
                         "description": "overrides of the preset or file, SI units"})
    return rows
