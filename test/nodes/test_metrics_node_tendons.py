"""metrics_node on a body with several tendons (the antagonistic pair): JointState tensions by
tendon name and Markers frames on an in-memory port with a simulated clock, against the offline
evaluation of the same samples."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.errors import InputError
from tdcm_ros.metrics.evaluation import evaluate_series
from tdcm_ros.metrics.options import options_from_sets
from tdcm_ros.metrics.synthetic import Recording
from tdcm_ros.nodes.metrics_node import MetricsNode
from tdcm_ros.runtime.memory_port import MemoryPort
from test.metrics.metrics_samples import PAIR_BODY, pair_recording

JOINT_STATE = "sensor_msgs/msg/JointState"
TENDONS = ("flexor", "extensor")
#: m. The noise-free recording's markers are the model's own at the tension vector of the
#: frame's stamp; the node's model there is a lattice point's solve (the levels are multiples of
#: 0.1 N): what is left is float rounding of the mocap round trip (measured: < 1e-16 m).
ROUNDING_M = 1e-12


def pair_port(overrides: dict[str, Any] | None = None) -> MemoryPort:
    """An in-memory port of metrics_node on the pair's body file, JointState tensions, the
    registration from ``/tf_static``, clock at 0."""
    return MemoryPort({"design.file": PAIR_BODY, "input.tension_type": JOINT_STATE,
                       "registration.source": "tf_static", **(overrides or {})},
                      name="metrics_node", start_ns=0)


def _hdr(stamp_s: float, frame: str = "") -> dict[str, Any]:
    ns = round(stamp_s * 1e9)
    return {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": frame}


def efforts(stamp_s: float, names: tuple[str, ...], values: list[float]) -> Any:
    """A JointState of tendon efforts (N) by name, stamped ``stamp_s`` (s)."""
    return from_dict(JOINT_STATE, {"header": _hdr(stamp_s), "name": list(names),
                                   "position": [], "velocity": [], "effort": values})


def send_registration(port: MemoryPort, rec: Recording) -> None:
    port.deliver("/tf_static", from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
        "header": _hdr(0.0, "mocap"), "child_frame_id": "tdcm_base",
        "transform": {"translation": dict(zip("xyz", rec.registration.translation, strict=True)),
                      "rotation": dict(zip("xyzw", rec.registration.quaternion,
                                           strict=True))}}]}))


def feed(port: MemoryPort, node: MetricsNode, rec: Recording, every_s: float = 0.5) -> None:
    """Deliver the recording in stamp order (tension as JointState efforts, extensor first to
    show the match is by name), running the update timer every ``every_s`` (s)."""
    tension, markers = rec.tension, rec.markers
    fi, next_update = 0, every_s
    for t, row in zip(tension.stamps_s, tension.tension_n.tolist(), strict=True):
        port.clock_ns = round(t * 1e9)
        port.deliver("tension", efforts(t, TENDONS[::-1], row[::-1]))
        while fi < markers.stamps_s.size and markers.stamps_s[fi] <= t:
            port.deliver("markers", from_dict("mocap4r2_msgs/msg/Markers", {
                "header": _hdr(markers.stamps_s[fi], "mocap"), "frame_number": fi,
                "markers": [{"marker_name": label, "marker_index": i,
                             "translation": dict(zip("xyz", r, strict=True))}
                            for i, (label, r) in enumerate(zip(
                                markers.labels, markers.positions[fi].tolist(), strict=True))
                            if not np.isnan(r[0])]}))
            fi += 1
        if t >= next_update:
            node.update()
            next_update += every_s


@pytest.fixture(scope="module")
def fed() -> tuple[MemoryPort, MetricsNode, Recording]:
    """The node after the noise-free pair recording (2 trials of 5 holds)."""
    rec = pair_recording()
    port = pair_port()
    node = MetricsNode(port)
    send_registration(port, rec)
    feed(port, node, rec)
    return port, node, rec


def test_the_running_table_and_steps_are_the_offline_evaluation(
        fed: tuple[MemoryPort, MetricsNode, Recording]) -> None:
    port, _, rec = fed
    options = options_from_sets([f"design.preset={PAIR_BODY}"])
    offline = evaluate_series(rec.tension, rec.markers, options,
                              registration=rec.registration).to_json()
    live = json.loads(port.published["metrics/table"][-1].data)
    # the stream ends inside the final (0, 0) hold, which never finishes: the offline steps but
    # that last unloading one (the same keys and values, numbers to float rounding), and the
    # same Table I (over the loading steps)
    steps, expected = live.pop("steps"), offline.pop("steps")[:-1]
    assert [tuple(s["tensions_n"].values()) for s in steps[:5]] == [
        (0.0, 0.0), (8.0, 0.0), (16.0, 0.0), (8.0, 8.0), (0.0, 12.0)]
    assert len(steps) == len(expected) == 10
    for got, want in zip(steps, expected, strict=True):
        assert got.keys() == want.keys()
        for key, value in want.items():
            exact = not isinstance(value, float)  # trial, phase, frames, tensions_n, ...
            assert got[key] == (value if exact else pytest.approx(value, abs=1e-12)), key
    for key in ("mape_pct", "rmse_m", "mae_m", "shape_error_m", "deflection_mean_m", "n_trials",
                "n_steps"):
        assert live[key] == pytest.approx(offline[key], abs=1e-12), key
    assert live["n_steps"] == 10 and live["n_trials"] == 2  # every hold loads (a tendon rises)


def test_the_per_frame_tip_error_is_zero_without_noise(
        fed: tuple[MemoryPort, MetricsNode, Recording]) -> None:
    port, node, rec = fed
    tips = port.published["metrics/tip_error"]
    assert len(tips) == rec.markers.stamps_s.size  # every frame scored
    sizes = [np.linalg.norm([m.vector.x, m.vector.y, m.vector.z]) for m in tips]
    assert max(sizes) < ROUNDING_M
    assert node.counts["tension"] == rec.tension.stamps_s.size
    assert not {"tension_missing_tendon", "tension_non_finite",
                "frames_without_error"} & set(node.counts)


def test_a_joint_state_without_every_tendon_is_counted_and_dropped() -> None:
    port = pair_port()
    node = MetricsNode(port)
    port.deliver("tension", efforts(1.0, ("flexor",), [8.0]))
    port.deliver("tension", efforts(1.1, ("flexor", "extensor"), [8.0]))  # no effort for one
    port.deliver("tension", efforts(1.2, TENDONS, [8.0, float("nan")]))
    port.deliver("tension", efforts(1.3, ("roll", *TENDONS), [0.0, 8.0, 2.0]))
    assert node.counts["tension_missing_tendon"] == 2
    assert node.counts["tension_non_finite"] == 1
    assert node.counts["tension"] == 1
    assert node.running.tension_at(1.3) == (8.0, 2.0)
    assert node.running.tension_at(1.2) is None
    node.diagnostics.publish()
    values = {kv.key: kv.value for kv in port.published["/diagnostics"][-1].status[0].values}
    assert (values["tension_missing_tendon"], values["tension_non_finite"]) == ("2", "1")


def test_several_tendons_with_a_wrench_tension_type_stop_the_start() -> None:
    with pytest.raises(InputError, match=r"input\.tension_type = geometry_msgs/msg/WrenchStamped"
                       r" carries one tension, but the body has 2 tendons \(flexor, extensor\); "
                       r"allowed: sensor_msgs/msg/JointState") as caught:
        MetricsNode(pair_port({"input.tension_type": "geometry_msgs/msg/WrenchStamped"}))
    assert (caught.value.parameter, caught.value.value) == \
        ("input.tension_type", "geometry_msgs/msg/WrenchStamped")
    with pytest.raises(InputError, match="input.tension_type"):
        MetricsNode(pair_port({"input.tension_type": "std_msgs/msg/Float64"}))
