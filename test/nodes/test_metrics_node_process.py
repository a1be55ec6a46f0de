"""metrics_node in its own process, on the embedded runtime and on rclpy (see conftest.py).

The test peer plays tension_driver (``tension``) and mocap_node (``markers`` in ``mocap``,
occluded markers left out, the registration on transient-local ``/tf_static`` sent before the
node starts); the node's outputs are checked against the library (:mod:`tdcm_ros.metrics`) run on
the same samples in the test. The logic in detail is tested in-process in
test/metrics/test_metrics_node.py.
"""

from __future__ import annotations

import json
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.metrics.evaluation import evaluate_series, metrics_of
from tdcm_ros.metrics.lookup import MarkerTable
from tdcm_ros.metrics.options import EvaluateOptions
from tdcm_ros.metrics.series import MarkerSeries, TensionSeries
from tdcm_ros.metrics.synthetic import Recording, simulate
from tdcm_ros.mocap.registration import Registration
from tdcm_ros.model import preset
from tdcm_ros.runtime.port import QoS
from test.support.waiting import eventually

METRICS = "tdcm_ros.nodes.metrics_node:MetricsNode"
TRUTH = preset("paper-experiment").with_overrides(E=0.8e9)   # the node models the preset's E
BASE_NS = 1_700_000_000 * 10**9                              # stamp of the recording's t = 0
CHUNK_S = 0.4                                                # data sent per burst (s of stamps)
TABLE_KEYS = ("mape_pct", "rmse_m", "mae_m", "shape_error_m", "deflection_mean_m")
Spawn = Callable[..., subprocess.Popen[bytes]]


def params_file(tmp_path: Path, values: dict[str, Any]) -> str:
    path = tmp_path / "metrics.yaml"
    path.write_text(yaml.safe_dump({"metrics_node": {"ros__parameters": values}}))
    return str(path)


def header(stamp_ns: int, frame_id: str) -> dict[str, Any]:
    return {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9},
            "frame_id": frame_id}


def stamp_s(message: Any) -> float:
    """A header stamp in s, as the node computes it."""
    return int(message.header.stamp.sec) + int(message.header.stamp.nanosec) * 1e-9


def stamps_ns(stamps: np.ndarray) -> list[int]:
    return [BASE_NS + round(float(t) * 1e9) for t in stamps]


def as_received(stamps: np.ndarray) -> np.ndarray:
    """The recording's stamps (s) as the node sees them after the trip through a header."""
    return np.array([ns // 10**9 + (ns % 10**9) * 1e-9 for ns in stamps_ns(stamps)])


class Peer:
    """The test side: publishes tension, markers and ``/tf_static``; collects the outputs."""

    def __init__(self, ctx: Any) -> None:
        self.ctx = ctx
        port = ctx.create_port("metrics_peer")
        self.port = port
        self.errors: list[Any] = []
        self.tips: list[Any] = []
        self.tables: list[Any] = []
        self.values: dict[str, list[float]] = {key: [] for key in TABLE_KEYS}
        self.diagnostics: list[Any] = []
        port.create_subscription("metrics/marker_errors", "mocap4r2_msgs/msg/Markers",
                                 self.errors.append, QoS(depth=1000))
        port.create_subscription("metrics/tip_error", "geometry_msgs/msg/Vector3Stamped",
                                 self.tips.append, QoS(depth=1000))
        port.create_subscription("metrics/table", "std_msgs/msg/String", self.tables.append,
                                 QoS(depth=1, durability="transient_local"))
        for key, sink in self.values.items():
            port.create_subscription(f"metrics/{key}", "std_msgs/msg/Float64",
                                     lambda m, sink=sink: sink.append(float(m.data)))
        port.create_subscription("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                                 self.diagnostics.append)
        self.tension = port.create_publisher("tension", "geometry_msgs/msg/WrenchStamped",
                                             QoS(depth=1000))
        self.markers = port.create_publisher("markers", "mocap4r2_msgs/msg/Markers",
                                             QoS(depth=1000))
        self.tf = port.create_publisher("/tf_static", "tf2_msgs/msg/TFMessage",
                                        QoS(depth=1, durability="transient_local"))

    def send_registration(self, reg: Registration) -> None:
        self.tf.publish(from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
            "header": header(BASE_NS, "mocap"), "child_frame_id": "tdcm_base",
            "transform": {"translation": dict(zip("xyz", reg.translation, strict=True)),
                          "rotation": dict(zip("xyzw", reg.quaternion, strict=True))}}]}))

    def send_tension(self, stamp_ns: int, tension_n: float) -> None:
        self.tension.publish(from_dict("geometry_msgs/msg/WrenchStamped", {
            "header": header(stamp_ns, "tdcm_tendon"), "wrench": {"force": {"z": tension_n}}}))

    def send_frame(self, stamp_ns: int, number: int, labels: tuple[str, ...],
                   rows: np.ndarray) -> None:
        """One marker frame as mocap_node publishes it: NaN (occluded) rows left out."""
        self.markers.publish(from_dict("mocap4r2_msgs/msg/Markers", {
            "header": header(stamp_ns, "mocap"), "frame_number": number,
            "markers": [{"id_type": 2, "marker_index": i, "marker_name": labels[i],
                         "translation": dict(zip("xyz", row, strict=True))}
                        for i, row in enumerate(rows.tolist()) if not np.isnan(row[0])]}))

    def stream(self, rec: Recording) -> None:
        """Send the recording in stamp order, in bursts of ``CHUNK_S``: each burst's tension
        first, then, once the node's diagnostics count it received, the burst's frames, so a
        frame's tension is always there (as live, where mocap lags the load cell)."""
        t_ns, f_ns = stamps_ns(rec.tension.stamps_s), stamps_ns(rec.markers.stamps_s)
        ti = fi = 0
        for end in np.arange(CHUNK_S, rec.tension.stamps_s[-1] + CHUNK_S, CHUNK_S):
            while ti < len(t_ns) and rec.tension.stamps_s[ti] < end:
                self.send_tension(t_ns[ti], float(rec.tension.tension_n[ti]))
                ti += 1
            self.spin_until(lambda sent=ti: self.diagnostic("tension") == str(sent), 10.0,
                            f"the node to count {ti} tension samples")
            while fi < len(f_ns) and rec.markers.stamps_s[fi] < end:
                self.send_frame(f_ns[fi], fi, rec.markers.labels, rec.markers.positions[fi])
                fi += 1
            self.ctx.spin_for(0.05)

    def spin_until(self, predicate: Callable[[], bool], timeout: float, what: str) -> None:
        """:func:`eventually`, spinning the probe's context; a timeout shows the last status."""
        eventually(predicate, timeout, what, spin=self.ctx,
                   detail=lambda: f"last status {self.status()}")

    def status(self) -> Any | None:
        return self.diagnostics[-1].status[0] if self.diagnostics else None

    def level(self) -> int:
        """The latest status level (a ``byte``: ``bytes`` from rosidl, an int from rosbags)."""
        level = self.status().level
        return level[0] if isinstance(level, bytes) else int(level)

    def diagnostic(self, key: str) -> str | None:
        status = self.status()
        values = {kv.key: kv.value for kv in status.values} if status else {}
        return values.get(key)


@pytest.fixture(scope="module")
def recording() -> Recording:
    """One trial 0 -> 6 -> 12 -> 0 N, 2 s holds, 100 Hz tension, 25 Hz mocap, 10 % occlusion."""
    return simulate(TRUTH, levels=(0.0, 6.0, 12.0), hold_s=2.0, trials=1, tension_hz=100.0,
                    mocap_hz=25.0, occlusion=0.1, seed=11)


def vector(point: Any) -> list[float]:
    return [point.x, point.y, point.z]


def test_errors_and_running_table_equal_the_library(runtime, context, spawn, tmp_path,
                                                    recording):
    peer = Peer(context)
    reg = recording.registration
    peer.send_registration(reg)
    peer.ctx.spin_for(0.2)
    # /tf_static went out before the node existed: it reaches the node as a late joiner.
    spawn("tdcm_ros.runtime.run_node", METRICS, "--params", params_file(tmp_path, {
        "update_period_s": 0.1, "diagnostics_period_s": 0.05}))
    # the node's start and DDS discovery took 16-20 s on rclpy with the machine loaded
    peer.spin_until(lambda: peer.diagnostic("registration") == "tf_static", 60.0,
                    "the registration from /tf_static")
    peer.stream(recording)
    peer.spin_until(lambda: len(peer.tables) > 0 and json.loads(
        peer.tables[-1].data)["n_steps"] == 3, 20.0, "three finished steps")

    options = EvaluateOptions()
    table = MarkerTable(options.design, options.layout, settings=options.solver)
    tension_by_ns = dict(zip(stamps_ns(recording.tension.stamps_s),
                             recording.tension.tension_n.tolist(), strict=True))
    frames = dict(zip(stamps_ns(recording.markers.stamps_s), recording.markers.positions,
                      strict=True))
    tip_seen = int(np.count_nonzero(~np.isnan(recording.markers.positions[:, -1, 0])))
    peer.spin_until(lambda: len(peer.errors) == len(frames) and len(peer.tips) == tip_seen, 10.0,
                    "an error message per frame and a tip error per frame with the tip")
    for message in peer.errors:
        ns = int(message.header.stamp.sec) * 10**9 + int(message.header.stamp.nanosec)
        expected = reg.to_base(frames[ns]) - table.markers(max(tension_by_ns[ns], 0.0))
        visible = [i for i in range(3) if not np.isnan(expected[i, 0])]
        assert message.header.frame_id == "tdcm_base"
        assert [m.marker_name for m in message.markers] == [options.layout.labels[i]
                                                           for i in visible]
        errors = np.array([vector(m.translation) for m in message.markers]).reshape(-1, 3)
        assert np.allclose(errors, expected[visible], rtol=0, atol=1e-12)
    # tip_error: the m3 error of each frame where the tip marker is visible, and only those.
    with_tip = {stamp_s(m): vector(m.markers[-1].translation) for m in peer.errors
                if m.markers and m.markers[-1].marker_name == "m3"}
    assert {stamp_s(m): vector(m.vector) for m in peer.tips} == with_tip

    # Table I: the library's offline evaluation of the same samples; the final zero hold never
    # finishes live, so the live table covers the first three steps.
    offline = evaluate_series(
        TensionSeries.of(as_received(recording.tension.stamps_s), recording.tension.tension_n),
        MarkerSeries.of(as_received(recording.markers.stamps_s), options.layout.labels,
                        recording.markers.positions), options, registration=reg)
    assert len(offline.records) == 4
    expected_table = metrics_of(offline.records[:3], options)
    got = json.loads(peer.tables[-1].data)
    assert (got["n_steps"], got["n_trials"]) == (3, 1)
    for live, off in zip(got["steps"], (r.to_json() for r in offline.records[:3]), strict=True):
        for key in ("trial", "tension_n", "measured_deflection_m", "predicted_deflection_m",
                    "frames", "start_s", "end_s"):
            assert live[key] == pytest.approx(off[key], rel=1e-12), key
    assert got["details"]["sources"][0]["registration"]["method"] == "tf_static"
    for key in TABLE_KEYS:
        assert got[key] == pytest.approx(getattr(expected_table, key), rel=1e-9, abs=1e-15), key
    assert got["rmse_m"] > 1e-5     # the node's E differs from the truth: a real error
    peer.spin_until(lambda: all(peer.values.values()), 10.0, "the Float64 topics")
    for key, values in peer.values.items():
        assert values[-1] == pytest.approx(got[key], rel=1e-12), key


def test_stale_inputs_warn_and_stale_s_changes_at_runtime(runtime, context, spawn, params,
                                                          tmp_path):
    peer = Peer(context)
    spawn("tdcm_ros.runtime.run_node", METRICS, "--params", params_file(tmp_path, {
        "registration": {"source": "parameter", "translation": [0.1, 0.0, 0.5],
                         "rotation": [0, 0, 0, 1]},     # integers widen to a float list
        "stale_s": 0.5, "diagnostics_period_s": 0.2}))
    peer.spin_until(lambda: peer.status() is not None, 20.0, "diagnostics")
    status = peer.status()
    assert peer.level() == 1
    assert "no tension for more than 0.5 s" in status.message
    assert "no markers for more than 0.5 s" in status.message
    assert "registration" not in status.message and peer.diagnostic("registration") == "parameter"

    node = params("/metrics_node")
    assert {"stale_s", "registration.source", "design.E", "steps.tolerance_n"} <= set(node.names())
    assert node.get("registration.translation") == [0.1, 0.0, 0.5]
    assert node.set("stale_s", 30.0) == {"successful": True, "reason": ""}
    assert node.get("stale_s") == 30.0
    # re-sent until seen: on rclpy the node's tension subscription may match after the
    # endpoints waited for above (discovery is per endpoint)
    eventually(lambda: "no tension" not in peer.status().message, 10.0,
               "tension to count as fresh for stale_s = 30 s", spin=peer.ctx,
               action=lambda: peer.send_tension(time.time_ns(), 1.0), every=0.5)
    assert peer.status().message == "no markers for more than 30 s"
    assert peer.level() == 1

    below = node.set("stale_s", 0.0)
    assert not below["successful"] and "stale_s" in below["reason"], below
    refused = node.set("design.E", 1.0e9)
    assert not refused["successful"] and "read-only" in refused["reason"], refused
    assert node.get("stale_s") == 30.0
    assert node.get("design.E") == preset("paper-experiment").E


def test_a_float_list_with_an_integer_entry_is_refused_as_rcl_refuses_it(runtime, spawn,
                                                                         tmp_path):
    """``[0.1, 0, 0.5]`` mixes a double and an integer: rcl refuses such a file, and so does
    this node on either runtime, at start, naming the parameter (``[0.1, 0.0, 0.5]`` loads)."""
    node = spawn("tdcm_ros.runtime.run_node", METRICS, "--params", params_file(tmp_path, {
        "registration": {"source": "parameter", "translation": [0.1, 0, 0.5]}}))
    assert node.wait(timeout=60) == InputError.exit_code
    assert ("parameter registration.translation mixes double and integer items"
            in node.stderr.read().decode())


