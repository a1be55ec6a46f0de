"""The scene file schema: top-level keys and the parameters of every section (SI units).

A scene file is a YAML mapping with the keys of :data:`TOP_KEYS`; each section's parameters
are :class:`~tdcm_ros.scenes.params.Param` tuples below, effects are checked against their
own. :func:`schema_rows` lists everything for documentation.
"""

from __future__ import annotations

from tdcm_ros.scenes.params import Param

PAPER_LEVELS = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0)
NYLON12_DENSITY = 1010.0  # kg/m^3, Formlabs Nylon 12 powder, printed part

TOP_KEYS: dict[str, str] = {
    "name": "scene name (defaults to the file's stem)",
    "description": "one line on what the scene is for",
    "seed": "random seed of every stochastic effect (integer >= 0)",
    "design": "the estimator's design: preset + SI overrides (nominal material)",
    "material": "the world's true material (defaults: the design's)",
    "schedule": "tension staircase the driver runs",
    "sensors": "sensor rates",
    "markers": "nominal marker placement (the estimator's and, without marker_offset, the world's)",
    "mocap_frame": "true pose of tdcm_base in the mocap frame",
    "effects": "mapping effect name -> parameters (empty mapping: defaults); only these run",
}

DESIGN = (
    Param("preset", "", "design preset of tdcm_ros.model", "paper-experiment", kind="str"),
)  # plus ``overrides``: Design fields in SI units, checked by Design.with_overrides

MATERIAL = (
    Param("E", "Pa", "true Young's modulus of the world (default: the design's E)", None,
          low=0.0, low_open=True, high=1e12),
    Param("density", "kg/m^3", "density of the body (for gravity)", NYLON12_DENSITY, low=0.0,
          low_open=True, high=1e5),
)

SCHEDULE = (
    Param("levels", "N", "tension setpoints of one trial, in order", PAPER_LEVELS, kind="list",
          low=0.0, high=22.0),
    Param("hold_s", "s", "time each level is held", 4.0, low=0.0, low_open=True, high=3600.0),
    Param("trials", "", "repetitions of the levels", 3, kind="int", low=1, high=1000),
)

SENSORS = (
    Param("tension_hz", "Hz", "load-cell sample rate", 80.0, low=0.0, low_open=True,
          high=10000.0),
    Param("mocap_hz", "Hz", "motion-capture frame rate", 100.0, low=0.0, low_open=True,
          high=10000.0),
)

MARKERS = (
    Param("labels", "", "marker labels, one per arc length", ("m1", "m2", "m3"), kind="names"),
    Param("arc_lengths_m", "m", "arc lengths of the marker cross-sections", (0.015, 0.033, 0.053),
          kind="list", low=0.0, high=10.0),
    Param("ball_radius_m", "m", "marker ball radius (centre = R_outer + this off the midline)",
          0.001, low=0.0, high=0.05),
    Param("side_deg", "deg", "angle around the body z axis from the tendon side (+x)", 180.0,
          low=-360.0, high=360.0),
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
            rows.append({"key": "design.overrides", "unit": "SI", "default": "{}",
                         "allowed": "Design fields (w_base, ..., E, profile)",
                         "description": "overrides of the preset, SI units"})
    return rows
