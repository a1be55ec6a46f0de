"""A bag from another lab, through the CLI as a user runs it: written by ``rosbags``' own rosbag2
writer (not the package's), mocap4r2 markers named as a Vicon subject names them, virtual markers
on the midline and a trailing unloading. The layout is mapped with ``--set`` and Table I comes
out as the simulated truth gives it."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from tdcm_ros.metrics.evaluation import evaluate_series
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.series import MarkerSeries, TensionSeries
from tdcm_ros.metrics.synthetic import Recording, simulate
from tdcm_ros.model import MarkerLayout, preset, solve
from test.support.cli import tdcm as run_tdcm

REPO = Path(__file__).resolve().parents[2]
VICON = ("tdcm:M15", "tdcm:M33", "tdcm:M53")
VICON_TIP_S = 0.053  #: m, arc length of tdcm:M53 (the default layout's tip marker)
#: The --set a user gives for this bag: the lab's names, base to tip, and midline markers.
MAPPING = ("--set", "markers.labels=" + ",".join(VICON), "--set", "markers.radial_offset=0")
DESIGN = preset("paper-experiment")  # the truth is the default model: no design --set needed
EPOCH_NS = 1_600_000_000 * 10**9
#: Each trial loads 0 -> 20 N in 5 N steps, then unloads to 10 N; the last returns to 0 N.
LEVELS = (0.0, 5.0, 10.0, 15.0, 20.0, 10.0)


def _typestore() -> Typestore:
    """Jazzy's types plus mocap4r2_msgs, read from the .msg files as any lab's tool would."""
    store = get_typestore(Stores.ROS2_JAZZY)
    folder = REPO / "msg_defs" / "mocap4r2_msgs" / "msg"
    for name in ("Marker", "Markers"):
        store.register(get_types_from_msg((folder / f"{name}.msg").read_text(),
                                          f"mocap4r2_msgs/msg/{name}"))
    return store


def bag_stamps(stamps_s: np.ndarray) -> np.ndarray:
    """Stamps (s) as the bag holds them: integer ns since the epoch, read back as s."""
    return (EPOCH_NS + np.round(stamps_s * 1e9).astype(np.int64)).astype(np.float64) * 1e-9


def write_foreign_bag(rec: Recording, path: Path) -> Path:
    """``rec`` as a rosbag2 MCAP bag by rosbags' writer: /force (WrenchStamped), /vicon/markers
    (mocap4r2 Markers, frame ``vicon``, occluded markers left out), no /tf_static."""
    store = _typestore()
    types = store.types
    header, time = types["std_msgs/msg/Header"], types["builtin_interfaces/msg/Time"]
    vector, point = types["geometry_msgs/msg/Vector3"], types["geometry_msgs/msg/Point"]
    wrench, stamped = types["geometry_msgs/msg/Wrench"], types["geometry_msgs/msg/WrenchStamped"]
    marker, markers = types["mocap4r2_msgs/msg/Marker"], types["mocap4r2_msgs/msg/Markers"]

    def hdr(ns: int, frame: str) -> object:
        return header(stamp=time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=frame)

    messages: list[tuple[int, str, object, str]] = []
    for t, x in zip(rec.tension.stamps_s.tolist(), rec.tension.tension_n.tolist(), strict=True):
        ns = EPOCH_NS + round(t * 1e9)
        messages.append((ns, "/force", stamped(header=hdr(ns, "load_cell"), wrench=wrench(
            force=vector(x=0.0, y=0.0, z=x), torque=vector(x=0.0, y=0.0, z=0.0))),
            "geometry_msgs/msg/WrenchStamped"))
    for n, (t, rows) in enumerate(zip(rec.markers.stamps_s.tolist(),
                                      rec.markers.positions.tolist(), strict=True)):
        ns = EPOCH_NS + round(t * 1e9)
        seen = [marker(id_type=0, marker_index=i, marker_name=VICON[i],
                       translation=point(x=r[0], y=r[1], z=r[2]))
                for i, r in enumerate(rows) if not np.isnan(r[0])]
        messages.append((ns, "/vicon/markers", markers(header=hdr(ns, "vicon"), frame_number=n,
                                                       markers=seen),
                         "mocap4r2_msgs/msg/Markers"))
    messages.sort(key=lambda m: m[0])
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connections = {topic: writer.add_connection(topic, kind, typestore=store)
                       for topic, kind in (("/force", "geometry_msgs/msg/WrenchStamped"),
                                           ("/vicon/markers", "mocap4r2_msgs/msg/Markers"))}
        for ns, topic, message, kind in messages:
            writer.write(connections[topic], ns, store.serialize_cdr(message, kind))
    return path


@pytest.fixture(scope="module")
def recording() -> Recording:
    midline = MarkerLayout(labels=VICON, radial_offset=0.0)
    return simulate(DESIGN, layout=midline, levels=LEVELS, hold_s=2.0, trials=2,
                    tension_hz=200.0, mocap_hz=50.0, marker_noise_m=5e-5, occlusion=0.05, seed=8)


@pytest.fixture(scope="module")
def bag(recording: Recording, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_foreign_bag(recording, tmp_path_factory.mktemp("foreign") / "lab_bag")


def tdcm(*args: str) -> subprocess.CompletedProcess[str]:
    return run_tdcm(*args, cwd=REPO)


TOPICS = ("--tension-topic", "/force", "--markers-topic", "/vicon/markers")


@pytest.mark.parametrize("command", ["evaluate", "calibrate"])
def test_unknown_marker_names_are_listed_with_the_option_that_maps_them(
        bag: Path, command: str) -> None:
    done = tdcm(command, str(bag), *TOPICS)
    assert done.returncode == 2, done.stderr
    err = done.stderr.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "markers m1, m2, m3 never come into view" in err
    for label in VICON:
        assert f"{label} (" in err and " frames)" in err
    assert "--set markers.labels=tdcm:M15,tdcm:M33,tdcm:M53" in err


def test_a_foreign_bag_gives_the_true_table_after_the_mapping(
        bag: Path, recording: Recording) -> None:
    done = tdcm("evaluate", str(bag), *TOPICS, *MAPPING, "--json")
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    # 2 trials loading 0, 5, 10, 15, 20 N: 10 Table I steps; unloading to 10 N twice and the
    # final return to 0 N are reported apart
    assert (doc["n_trials"], doc["n_steps"], doc["unloading"]["n_steps"]) == (2, 10, 3)
    phases = [(round(s["tension_n"]), s["phase"]) for s in doc["steps"]]
    assert phases == [(0, "loading"), (5, "loading"), (10, "loading"), (15, "loading"),
                      (20, "loading"), (10, "unloading")] * 2 + [(0, "unloading")]
    # the same recording evaluated in memory with its true layout (on the bag's stamps, s since
    # the epoch as the reader makes them): the very same Table I
    tension = TensionSeries.of(bag_stamps(recording.tension.stamps_s),
                               recording.tension.tension_n)
    frames = MarkerSeries.of(bag_stamps(recording.markers.stamps_s), VICON,
                             recording.markers.positions)
    truth = evaluate_series(tension, frames, options_from_sets(
        ["markers.labels=" + ",".join(VICON), "markers.radial_offset=0"]))
    for key in ("mape_pct", "rmse_m", "mae_m", "shape_error_m", "deflection_mean_m"):
        assert doc[key] == pytest.approx(getattr(truth.metrics, key), rel=1e-6, abs=1e-12), key
    # and against the simulated truth: the model is the world, only marker noise is left
    true_tip = solve(DESIGN, 20.0).pose_at(np.array([VICON_TIP_S]))[0][0]  # rest: (0, 0, s)
    assert doc["deflection_mean_m"] == pytest.approx(abs(true_tip[0]), abs=5e-5)
    assert doc["rmse_m"] < 3e-5 and doc["mae_m"] < 3e-5 and doc["mape_pct"] < 1.0
    assert doc["shape_error_m"] < 1e-4
    # no friction in the simulation: unloading meets loading at 10 N and 0 N within the noise
    paired = [s["hysteresis_m"] for s in doc["steps"] if s["phase"] == "unloading"]
    assert len(paired) == 3 and max(abs(h) for h in paired) < 3e-5


def test_calibrate_takes_the_same_mapping(bag: Path) -> None:
    done = tdcm("calibrate", str(bag), *TOPICS, *MAPPING, "--json")
    assert done.returncode == 0, done.stderr
    fitted = json.loads(done.stdout)["parameters"]["E"]["value"]
    assert fitted == pytest.approx(DESIGN.E, rel=0.01)  # the simulated truth
