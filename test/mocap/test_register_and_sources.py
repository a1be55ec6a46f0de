"""Registration (given and estimated from CSV recordings) and the CSV/scene sources."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tdcm_ros.mocap import (
    CsvReplay,
    LabelError,
    NameMap,
    SimSource,
    SourceError,
    estimate_from_recordings,
    given_registration,
    read_nexus_csv,
)
from tdcm_ros.mocap.registration import Registration, RegistrationError
from test.mocap.mocap_helpers import DATA, nexus_text, straight_and_bent

LABELS = ("m1", "m2", "m3")
ARCS = (0.015, 0.033, 0.053)
RADIUS = 0.00492


def test_given_registration_from_quaternion_or_rpy():
    quarter = given_registration([1.0, 2.0, 3.0], rpy=[0.0, 0.0, math.pi / 2])
    assert np.allclose(quarter.quaternion, [0, 0, math.sin(math.pi / 4), math.cos(math.pi / 4)])
    assert np.allclose(quarter.to_mocap([[1.0, 0.0, 0.0]]), [[1.0, 3.0, 3.0]])
    same = given_registration([1.0, 2.0, 3.0], quaternion=[0, 0, 2.0, 2.0])   # normalised
    assert np.allclose(same.quaternion, quarter.quaternion)
    roll_pitch = given_registration([0, 0, 0], rpy=[0.3, -0.2, 0.0])
    expected = Rotation.from_euler("z", 0.0) * Rotation.from_euler("y", -0.2) * \
        Rotation.from_euler("x", 0.3)     # ROS setRPY: R = Rz(yaw) Ry(pitch) Rx(roll)
    assert np.allclose(roll_pitch.rotation, expected.as_matrix())
    for bad in ({"quaternion": [0, 0, 0, 0]}, {"rpy": [0, math.nan, 0]}, {},
                {"rpy": [0, 0, 0], "quaternion": [0, 0, 0, 1]}):
        with pytest.raises(RegistrationError):
            given_registration([0, 0, 0], **bad)


def test_registration_estimated_from_zero_and_bent_recordings(tmp_path):
    truth = Registration((0.25, -0.12, 0.81),
                         tuple(Rotation.from_euler("xyz", [2.9, 0.1, 0.3]).as_quat()))
    zero, bent = straight_and_bent(truth)
    names = ["R:M1", "R:M2", "R:M3"]
    zero_rows = np.repeat(zero[None], 5, axis=0)
    zero_rows[1, 2] = np.nan                         # a gap
    bent_rows = np.stack([zero + 0.2 * (bent - zero), bent, zero + 0.5 * (bent - zero)])
    (tmp_path / "zero.csv").write_text(nexus_text(names, zero_rows))
    (tmp_path / "bent.csv").write_text(nexus_text(names, bent_rows, delimiter=";"))
    name_map = NameMap.parse(["M1=m1", "M2=m2", "M3=m3"], LABELS)
    estimate = estimate_from_recordings(tmp_path / "zero.csv", name_map, ARCS, radius=RADIUS,
                                        side_rad=math.pi, bent_csv=tmp_path / "bent.csv")
    assert estimate.method == "estimated"
    assert np.allclose(estimate.translation, truth.translation, atol=1e-9)
    assert np.allclose(estimate.rotation, truth.rotation, atol=1e-9)
    # Registration applied: the bent markers land on the hand geometry in tdcm_base.
    assert np.allclose(estimate.to_base(bent), truth.to_base(bent), atol=1e-9)
    with pytest.raises(RegistrationError, match="roll"):
        estimate_from_recordings(tmp_path / "zero.csv", name_map, ARCS, radius=RADIUS,
                                 side_rad=math.pi)
    hinted = estimate_from_recordings(tmp_path / "zero.csv", name_map, ARCS, radius=RADIUS,
                                      side_rad=math.pi, x_hint=truth.rotation[:, 0])
    assert np.allclose(hinted.rotation, truth.rotation, atol=1e-9)
    with pytest.raises(LabelError, match="'m3'"):
        estimate_from_recordings(tmp_path / "zero.csv", NameMap.parse(
            ["M1=m1", "M2=m2", "Tip=m3"], LABELS), ARCS, radius=RADIUS, side_rad=math.pi)


def test_csv_replay_is_due_on_replay_time_scaled_and_loops():
    traj = read_nexus_csv(DATA / "nexus_trial.csv")       # 30 rows at 100 Hz: a 0.3 s pass
    start = 10**18
    replay = CsvReplay(traj, rate_scale=2.0, loop=False, start_ns=start)
    assert replay.due(start - 1) == []
    first = replay.due(start)
    assert [f.frame_number for f in first] == [101]
    upto = replay.due(start + 50_000_000)                  # 0.1 s of recording at 2x
    assert [f.frame_number for f in upto] == list(range(102, 112))
    assert upto[-1].stamp_ns == start + 50_000_000 and upto[-1].names == traj.names
    assert np.array_equal(upto[-1].positions, traj.positions[10], equal_nan=True)
    rest = replay.due(start + 10**10)
    assert len(rest) == 19 and replay.finished and replay.due(start + 10**11) == []

    looped = CsvReplay(traj, rate_scale=1.0, loop=True, start_ns=0)
    frames = looped.due(3 * 300_000_000 + 1)              # three passes of 0.3 s and one row
    assert len(frames) == 91 and not looped.finished
    assert frames[30].frame_number == 101 and frames[30].stamp_ns == 300_000_000
    burst = CsvReplay(traj, rate_scale=1.0, loop=True, start_ns=0).due(10**13)
    assert len(burst) == 1000                             # a stalled clock never hangs the node


class FakeFrame:
    def __init__(self, labels, positions):
        self.labels, self.positions = labels, positions


class FakeWorld:
    """Test double of a scene world: marker x = tension (mm), NaN tip when stamp is odd."""

    def __init__(self):
        self.calls: list[tuple[float, float]] = []
        self.rolls: list[float] = []

    def markers(self, stamp_s: float, true_tension: float, roll: float = 0.0) -> FakeFrame:
        self.calls.append((stamp_s, true_tension))
        self.rolls.append(roll)
        p = np.array([[1e-3 * true_tension, 0.0, s] for s in ARCS])
        if int(stamp_s) % 2:
            p[2] = np.nan
        return FakeFrame(LABELS, p)


def test_sim_source_samples_the_world_and_delays_frames():
    world = FakeWorld()
    delays = iter([0.25, 0.5])
    source = SimSource(world, delay=lambda: next(delays))
    source.sample(2_000_000_000, 5.0)
    source.sample(3_000_000_000, 7.0)
    assert world.calls == [(2.0, 5.0), (3.0, 7.0)]
    assert source.due(2_200_000_000) == []
    (first,) = source.due(2_250_000_000)
    assert first.stamp_ns == 2_000_000_000 and first.frame_number == 1
    assert first.names == LABELS and np.allclose(first.positions[:, 0], 5e-3)
    assert source.due(3_400_000_000) == []
    (second,) = source.due(3_500_000_000)
    assert second.frame_number == 2 and np.isnan(second.positions[2]).all()
    with pytest.raises(SourceError, match="delay_s"):
        SimSource(world, delay=lambda: -1.0).sample(0, 0.0)

    class Broken(FakeWorld):
        def markers(self, stamp_s, true_tension, roll=0.0):
            return FakeFrame(LABELS, np.zeros((2, 3)))

    with pytest.raises(SourceError, match="shape"):
        SimSource(Broken()).sample(0, 0.0)


def test_sim_source_hands_the_true_roll_to_the_world():
    world = FakeWorld()
    source = SimSource(world)
    source.sample(1_000_000_000, 5.0)
    source.sample(2_000_000_000, 5.0, 0.4)
    assert world.rolls == [0.0, 0.4]
