"""Sensing, timing and actuation effects: statistics, reproducibility and the plant mapping."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tdcm_ros.device.plant import PlantConfig
from tdcm_ros.scenes import InvalidSceneError
from tdcm_ros.scenes.effects.timing import LATENCY_TOPICS
from test.scenes.scene_helpers import make_scene


def _frames(scene, count: int, tension: float = 8.0, rate: float = 100.0):  # type: ignore[no-untyped-def]
    world = scene.world()
    return np.stack([world.markers(k / rate, tension).positions for k in range(count)]), world


def test_noise_has_the_declared_std_and_zero_mean() -> None:
    std = 2e-4
    noisy, _ = _frames(make_scene({"marker_noise": {"std_m": std}}), 3000)
    clean, _ = _frames(make_scene(), 1)
    error = (noisy - clean[0]).reshape(-1)
    assert np.std(error) == pytest.approx(std, rel=0.03)  # 27000 draws: sd of estimate ~0.4 %
    assert abs(np.mean(error)) < 5 * std / math.sqrt(error.size)


def test_same_seed_same_frames_other_seed_other_frames() -> None:
    effects = {"marker_noise": {"std_m": 1e-4},
               "marker_dropout": {"probability": 0.2, "burst_rate_hz": 2.0}}
    first, _ = _frames(make_scene(effects), 200)
    second, _ = _frames(make_scene(effects), 200)
    other, _ = _frames(make_scene(effects, seed=12), 200)
    np.testing.assert_array_equal(first, second)
    assert not np.array_equal(np.isnan(first), np.isnan(other))


def test_effects_draw_from_their_own_streams() -> None:
    noise_only, _ = _frames(make_scene({"marker_noise": {"std_m": 1e-4}}), 50)
    with_dropout, _ = _frames(make_scene({"marker_noise": {"std_m": 1e-4},
                                          "marker_dropout": {"probability": 0.3}}), 50)
    seen = ~np.isnan(with_dropout)
    np.testing.assert_array_equal(with_dropout[seen], noise_only[seen])


def test_random_dropout_gives_nan_rows_at_the_declared_rate() -> None:
    frames, _ = _frames(make_scene({"marker_dropout": {"probability": 0.25}}), 2000)
    lost = np.isnan(frames)
    assert np.array_equal(lost.any(axis=2), lost.all(axis=2))  # whole rows
    assert np.mean(lost[:, :, 0]) == pytest.approx(0.25, abs=0.02)


def test_bursts_hide_markers_for_runs_of_frames() -> None:
    scene = make_scene({"marker_dropout": {"probability": 0.0, "burst_rate_hz": 1.0,
                                           "burst_duration_s": 0.2, "burst_scope": "all"}})
    frames, _ = _frames(scene, 3000)  # 30 s at 100 Hz
    hidden = np.isnan(frames[:, :, 0])
    assert np.array_equal(hidden[:, 0], hidden[:, 1]) and np.array_equal(hidden[:, 0], hidden[:, 2])
    runs = np.diff(np.flatnonzero(np.diff(np.concatenate([[0], hidden[:, 0], [0]]))))[::2]
    assert 10 <= runs.size <= 60  # ~30 bursts expected
    assert np.mean(runs) == pytest.approx(20, rel=0.5)  # 0.2 s at 100 Hz
    one = make_scene({"marker_dropout": {"probability": 0.0, "burst_rate_hz": 1.0,
                                         "burst_scope": "one"}})
    frames_one, _ = _frames(one, 3000)
    assert not np.any(np.all(np.isnan(frames_one[:, :, 0]), axis=1))


def test_marker_offset_moves_the_true_markers() -> None:
    clean = make_scene().world()
    shifted = make_scene({"marker_offset": {"arc_offset_m": [0.0, 0.0, -0.002],
                                            "radial_offset_m": 0.0005}}).world()
    result = clean.solve(0.0)
    a, b = clean.body_markers(result), shifted.body_markers(result)
    np.testing.assert_allclose(b[:, 2] - a[:, 2], [0.0, 0.0, -0.002], atol=1e-12)
    np.testing.assert_allclose(b[:, 0] - a[:, 0], [-0.0005] * 3, atol=1e-12)  # side 180 deg: -x


def test_registration_error_changes_only_the_published_transform() -> None:
    scene = make_scene({"registration_error": {"translation_m": [0.001, 0.0, 0.0],
                                               "rotation_deg": [0.0, 1.0, 0.0]}})
    world = scene.world()
    true_t, true_q = scene.mocap_pose
    pub_t, pub_q = world.mocap_to_base
    np.testing.assert_allclose(pub_t - true_t, Rotation.from_quat(true_q).apply([0.001, 0, 0]),
                               atol=1e-15)
    relative = Rotation.from_quat(true_q).inv() * Rotation.from_quat(pub_q)
    np.testing.assert_allclose(relative.as_euler("xyz", degrees=True), [0.0, 1.0, 0.0], atol=1e-9)
    np.testing.assert_array_equal(world.markers(0.0, 4.0).positions,
                                  make_scene().world().markers(0.0, 4.0).positions)


def test_latency_draws_stay_in_range_with_the_declared_mean() -> None:
    world = make_scene({"latency": {"markers_s": 0.008, "markers_jitter_s": 0.002,
                                    "tension_s": 0.004}}).world()
    delays = np.array([world.delay_s("markers") for _ in range(4000)])
    assert delays.min() >= 0.006 and delays.max() <= 0.010
    assert np.mean(delays) == pytest.approx(0.008, abs=1e-4)
    assert np.std(delays) == pytest.approx(0.002 / math.sqrt(3), rel=0.05)  # uniform
    assert world.delay_s("tension") == 0.004
    with pytest.raises(InvalidSceneError, match="markers, tension"):
        world.delay_s("midline")
    assert set(LATENCY_TOPICS) == {"markers", "tension"}


def test_plant_config_maps_the_actuation_effects() -> None:
    plain = make_scene().plant_config()
    assert plain == PlantConfig(noise=0.0, sample_period=1 / 80.0, seed=11)
    scene = make_scene({
        "actuator_dynamics": {"lag_s": 0.05, "rate_m_per_s": 0.01, "deadband_m": 1e-4},
        "load_cell": {"noise_n": 0.02, "bias_n": 0.05, "quantum_counts": 50,
                      "drift_n_per_s": 1e-3},
        "tendon_compliance": {"stiffness_n_per_m": 3000.0, "slack_m": 0.001},
    }, sensors={"tension_hz": 100.0})
    config = scene.plant_config()
    assert (config.lag, config.rate, config.deadband) == (0.05, 0.01, 1e-4)
    assert (config.noise, config.bias, config.quantum, config.drift) == (0.02, 0.05, 50, 1e-3)
    assert (config.stiffness, config.slack) == (3000.0, 0.001)
    assert config.sample_period == pytest.approx(0.01)
    effects = scene.build_effects("actuation")
    assert [e.name for e in effects] == ["actuator_dynamics", "load_cell", "tendon_compliance"]
