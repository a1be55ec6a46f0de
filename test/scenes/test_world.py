"""The world: equal to the base model without effects, effects built only when listed, and each
mechanics effect moving the answer the right way."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tdcm_ros.errors import InputError, PhysicsError
from tdcm_ros.model import NotchClosureError, solve, surface_points
from tdcm_ros.scenes import CONSTRUCTED, REGISTRY, load_scene
from test.scenes.scene_helpers import make_scene

LEVELS = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0)


def test_no_effects_equals_the_base_model() -> None:
    scene = make_scene()
    world = scene.world()
    assert world.loading is None
    for tension in (0.0, 3.0, 20.0, 7.5, 20.0):
        expected = solve(scene.design, tension)
        got = world.solve(tension)
        assert np.max(np.abs(got.positions - expected.positions)) <= 1e-12
        body, _ = surface_points(expected, np.asarray(scene.marker_arc_lengths),
                                 scene.marker_radius, scene.marker_side_rad)
        translation, quaternion = scene.mocap_pose
        mocap = Rotation.from_quat(quaternion).apply(body) + translation
        frame = world.markers(1.0, tension)
        assert frame.labels == ("m1", "m2", "m3")
        assert np.max(np.abs(frame.positions - mocap)) <= 1e-12
    assert world.mocap_to_base[0] is scene.mocap_pose[0]
    assert world.delay_s("markers") == 0.0 and world.delay_s("tension") == 0.0


def test_unlisted_effects_are_never_constructed_or_called(monkeypatch: pytest.MonkeyPatch
                                                          ) -> None:
    listed = "marker_noise"

    class Forbidden:
        def __init__(self, *args: object, **kwargs: object) -> None:
            raise AssertionError("an unlisted effect was constructed")

    for name in REGISTRY:
        if name != listed:
            monkeypatch.setitem(REGISTRY, name, Forbidden)
    before = dict(CONSTRUCTED)
    scene = make_scene({listed: {"std_m": 1e-4}})
    world = scene.world()
    for k in range(5):
        world.markers(k * 0.01, 4.0 * k)
    scene.plant_config()
    world.delay_s("markers")
    built = {n: CONSTRUCTED[n] - before.get(n, 0) for n in CONSTRUCTED}
    assert {n: c for n, c in built.items() if c} == {listed: 1}
    assert world.effects[0].calls == 5


def test_world_is_built_from_listed_effects_only() -> None:
    before = dict(CONSTRUCTED)
    make_scene({"gravity": {}, "latency": {"markers_s": 0.01}}).world()
    built = {n: CONSTRUCTED[n] - before.get(n, 0) for n in CONSTRUCTED}
    assert {n: c for n, c in built.items() if c} == {"gravity": 1, "latency": 1}


def _tips(scene, levels):  # type: ignore[no-untyped-def]
    world = scene.world()
    return [world.solve(level).tip_position for level in levels]


def test_friction_less_deflection_loading_and_hysteresis_unloading() -> None:
    up_down = (0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 16.0, 12.0, 8.0, 4.0, 0.0)
    design = {"preset": "paper-experiment", "overrides": {"E": 7e8}}
    friction = _tips(make_scene({"tendon_friction": {"mu": 0.3}}, design=design), up_down)
    base = _tips(make_scene(design=design), up_down)
    loading = {lvl: friction[i][0] for i, lvl in enumerate(up_down[:6])}
    unloading = {lvl: friction[i][0] for i, lvl in enumerate(up_down) if i >= 5}
    for i, level in enumerate(up_down[1:6], start=1):
        assert friction[i][0] < base[i][0] * 0.99  # tension lost toward the tip
    for level in (16.0, 12.0, 8.0, 4.0):
        assert unloading[level] > loading[level] * 1.01  # the tip lags on the way back
        assert unloading[level] > dict(zip(up_down, base, strict=True))[level][0]
    assert abs(friction[-1][0]) < 1e-12  # released: straight again


def test_friction_with_zero_coefficient_is_the_base_model() -> None:
    scene = make_scene({"tendon_friction": {"mu": 0.0}})
    world = scene.world()
    for level in LEVELS:
        got = world.solve(level)
        assert np.max(np.abs(got.positions - solve(scene.design, level).positions)) < 1e-9


def test_friction_world_is_stateful_and_others_cache() -> None:
    world = make_scene({"tendon_friction": {"mu": 0.2}}).world()
    first = world.solve(12.0)
    assert world.solve(12.0) is first  # same tension again: same state
    world.solve(20.0)
    again = world.solve(12.0)
    assert again is not first and again.tip_position[0] > first.tip_position[0]
    cached = make_scene({"gravity": {}}).world()
    shape = cached.solve(12.0)
    cached.solve(20.0)
    assert cached.solve(12.0) is shape and cached.solves == 2


@pytest.mark.parametrize("direction", [(-1.0, 0.0, 0.0), (1.0, 0.0, 0.0), (-0.6, 0.0, 0.8)])
def test_gravity_sags_toward_gravity(direction: tuple[float, float, float]) -> None:
    scene = make_scene({"gravity": {"direction": list(direction), "g": 9.81}})
    unloaded = np.array([0.0, 0.0, scene.design.length])
    tip = scene.world().solve(0.0).tip_position
    sag = tip - unloaded
    g = np.asarray(direction) / np.linalg.norm(direction)
    lateral = sag[0]
    assert np.sign(lateral) == np.sign(g[0])
    assert 1e-7 < abs(lateral) < 1e-3  # a 2 g body sags micrometres, not millimetres


def test_gravity_along_the_body_does_not_bend_it() -> None:
    tip = make_scene({"gravity": {"direction": [0, 0, -1]}}).world().solve(0.0).tip_position
    assert abs(tip[0]) < 1e-15


def test_gravity_against_the_tendon_reduces_deflection() -> None:
    base = make_scene().world().solve(8.0).tip_position[0]
    down = make_scene({"gravity": {"direction": [-1, 0, 0]}}).world().solve(8.0).tip_position[0]
    assert down < base


def test_tip_load_small_load_response_is_linear_beam_theory() -> None:
    scene = make_scene()
    grid = solve(scene.design, 0.0).grid
    length = scene.design.length
    compliance = float(np.sum(grid.w_q * (length - grid.s_q) ** 2 * grid.c_q))  # int (L-s)^2/EI
    deflections = []
    for force in (1e-4, 2e-4, -1e-4):
        tip = make_scene({"tip_load": {"force_n": [force, 0.0, 0.0]}}).world().solve(0.0)
        deflections.append(tip.tip_position[0])
        assert tip.tip_position[0] == pytest.approx(force * compliance, rel=1e-3)
    assert deflections[1] / deflections[0] == pytest.approx(2.0, rel=1e-4)
    assert deflections[2] == pytest.approx(-deflections[0], rel=1e-4)


def test_tip_moment_adds_to_the_tendon() -> None:
    base = make_scene().world().solve(4.0).tip_position[0]
    with_moment = make_scene({"tip_load": {"moment_nm": 0.005}}).world().solve(4.0)
    assert with_moment.tip_position[0] > base


CLOSING = {"preset": "paper-experiment",
           "overrides": {"profile": "rectangular", "w_n": 5e-4, "w_d": 8e-4, "E": 5e8}}
SHORT = {"arc_lengths": [0.01, 0.025, 0.041]}  # this design is 41 mm long


def test_notch_contact_replaces_the_closure_error() -> None:
    with pytest.raises(NotchClosureError):
        make_scene(design=CLOSING, markers=SHORT).world().solve(12.0)
    world = make_scene({"notch_contact": {"stiffness_factor": 1.0}}, design=CLOSING,
                       markers=SHORT).world()
    closed = world.solve(12.0)
    more = world.solve(16.0)
    assert np.all(np.isfinite(closed.positions))
    assert 0.0 < more.tip_position[0] - closed.tip_position[0] < 1e-3  # stiff once closed


@settings(max_examples=25, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.floats(0.0, 30.0, allow_nan=False), min_size=1, max_size=4))
@example([5e-324, 1.0])  # a warm start from ~0 N once overflowed into NaN wrap angles
def test_near_singular_converges_or_raises_the_typed_limit(tensions: list[float]) -> None:
    world = load_scene("near_singular").world()
    for tension in tensions:
        try:
            result = world.solve(tension)
        except PhysicsError:
            continue
        assert result.converged
        assert np.all(np.isfinite(result.positions))
        frame = world.markers(0.0, tension)
        assert np.all(np.isfinite(frame.positions))


def test_near_singular_schedule_solves_and_is_near_the_limit() -> None:
    scene = load_scene("near_singular")
    world = scene.world()
    top = world.solve(0.0)
    for level in scene.schedule.levels:
        top = world.solve(level)
    assert top.converged and abs(top.tip_angle_rad) > 2.5  # curled past ~145 degrees
    with pytest.raises(PhysicsError):
        scene.without("tendon_friction").world().solve(19.0)


def test_midline_markers_of_a_scene_sit_on_the_midline() -> None:
    """``markers.radial_offset: 0``: the simulated mocap sees the midline points (virtual
    markers, as a fitted spline gives them), not the surface."""
    scene = make_scene(markers={"radial_offset": 0.0})
    assert scene.marker_radius == 0.0
    assert make_scene().marker_radius == pytest.approx(scene.design.R_outer + 0.001)
    midline, _ = solve(scene.design, 12.0).pose_at(np.asarray(scene.marker_arc_lengths))
    translation, quaternion = scene.mocap_pose
    mocap = Rotation.from_quat(quaternion).apply(midline) + translation
    assert np.max(np.abs(scene.world().markers(1.0, 12.0).positions - mocap)) <= 1e-12


@settings(max_examples=25, suppress_health_check=[HealthCheck.too_slow])
@given(tension=st.sampled_from([0.0, 6.0, 20.0]), roll=st.floats(-np.pi, np.pi))
def test_markers_roll_with_the_body_about_the_base_z_axis(tension: float, roll: float) -> None:
    """At roll phi the markers are the phi = 0 markers turned by phi about tdcm_base's z axis,
    an axis through the base origin that the mocap frame sees along R_mocap z."""
    scene = make_scene()
    translation, quaternion = scene.mocap_pose
    mocap = Rotation.from_quat(quaternion)
    about_base_z = Rotation.from_rotvec(roll * mocap.apply([0.0, 0.0, 1.0]))
    world = scene.world()
    flat = world.markers(0.0, tension).positions
    rolled = world.markers(0.0, tension, roll=roll).positions
    expected = about_base_z.apply(flat - translation) + translation
    assert np.max(np.abs(rolled - expected)) <= 1e-12
    assert np.array_equal(world.markers(0.0, tension, roll=0.0).positions, flat)


def test_a_bad_roll_is_refused_by_name() -> None:
    with pytest.raises(InputError, match="roll"):
        make_scene().world().markers(0.0, 4.0, roll=float("nan"))


def test_horizontal_gravity_acts_in_the_rolled_plane_only() -> None:
    """Gravity along base -x: rolled by pi/2 the bending plane is horizontal-normal, the planar
    model sees no in-plane weight (the out-of-plane sag is not modelled); rolled by pi the
    weight pulls the other way in the plane, toward the tendon."""
    scene = make_scene({"gravity": {"direction": [-1.0, 0.0, 0.0]}})
    world = scene.world()
    free = solve(scene.design, 8.0).tip_position[0]
    against = world.solve(8.0).tip_position[0]
    assert against < free
    across = world.solve(8.0, roll=np.pi / 2)
    assert abs(across.tip_position[0] - free) < 1e-12
    assert world.solve(8.0, roll=np.pi).tip_position[0] > free
    assert world.solve(8.0, roll=-np.pi / 2) is across  # cached by the in-plane load factor
    plain = make_scene().world()
    assert plain.solve(8.0, roll=1.0) is plain.solve(8.0) and plain.solves == 1
