"""model_node's input gating in-process (MemoryPort, manual clock): which tensions it solves and
which it drops and counts, with the age and future limits checked to the ns, and the node
solving on once bad inputs have passed. The same node in its own process: test_model_node.py."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from tdcm_ros.bagio import from_dict
from tdcm_ros.model import preset, solve
from tdcm_ros.nodes.model_node import ModelNode
from tdcm_ros.runtime.memory_port import MemoryPort

MS = 10**6
KEYS = ("dropped_non_finite", "dropped_negative", "dropped_above_max", "dropped_stale",
        "dropped_future", "dropped_unstamped")


def wrench(tension: float, stamp_ns: int) -> Any:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9},
                   "frame_id": "tendon"},
        "wrench": {"force": {"z": tension}}})


def stamp(message: Any) -> int:
    return int(message.header.stamp.sec) * 10**9 + int(message.header.stamp.nanosec)


class Node:
    """model_node on a MemoryPort; :meth:`send` delivers a tension (solved on arrival)."""

    def __init__(self, overrides: dict[str, Any] | None = None) -> None:
        self.port = MemoryPort(overrides, name="model_node")
        self.node = ModelNode(self.port)

    def send(self, tension: float, stamp_ns: int) -> bool:
        """Deliver ``tension`` stamped ``stamp_ns``; True if a tip pose with that stamp came
        (every solve publishes one; the midline is drawn at ``output.visual_rate_hz``)."""
        before = len(self.port.messages("tip_pose"))
        self.port.deliver("tension", wrench(tension, stamp_ns))
        self.port.advance(0.001)
        tips = self.port.messages("tip_pose")[before:]
        assert len(tips) <= 1
        return bool(tips) and stamp(tips[0]) == stamp_ns

    def counts(self) -> dict[str, int]:
        return {k: self.node.counts[k] for k in KEYS}


def test_a_good_tension_is_solved_at_its_stamp_as_the_library_solves_it() -> None:
    n = Node()
    now = n.port.now_ns()
    assert n.send(20.0, now - 3 * MS)
    path = n.port.messages("midline")[-1]
    expected = solve(preset("paper-experiment"), 20.0).tip_position
    p = path.poses[-1].pose.position
    assert np.allclose([p.x, p.y, p.z], expected, atol=1e-12)
    assert path.header.frame_id == "tdcm_base"
    assert n.counts() == dict.fromkeys(KEYS, 0)


def test_each_solve_publishes_the_tendon_as_a_joint_its_stroke_and_tension() -> None:
    n = Node()
    for tension in (6.0, 20.0):
        sent = n.port.now_ns() - 2 * MS
        assert n.send(tension, sent)
        state = n.port.messages("tendon_states")[-1]
        expected = solve(preset("paper-experiment"), tension)
        assert stamp(state) == sent and state.header.frame_id == ""
        assert list(state.name) == ["tendon_1"] and len(state.velocity) == 0
        assert list(state.position) == pytest.approx(expected.tendon_strokes_m.tolist(),
                                                     abs=1e-12)
        assert list(state.effort) == [tension]
    assert len(n.port.messages("tendon_states")) == 2   # one per solve


@pytest.mark.parametrize(("tension", "key"), [
    (float("nan"), "dropped_non_finite"), (float("inf"), "dropped_non_finite"),
    (-3.0, "dropped_negative"), (200.000001, "dropped_above_max"), (1e9, "dropped_above_max")])
def test_a_bad_value_is_dropped_counted_and_named(tension: float, key: str) -> None:
    n = Node()
    assert not n.send(tension, n.port.now_ns())
    assert n.counts() == {k: int(k == key) for k in KEYS}
    assert n.node.last_problem == f"dropped tension {tension!r} N: {key.removeprefix('dropped_')}"
    assert n.send(12.0, n.port.now_ns())  # and solves on


def test_the_limits_themselves_are_valid() -> None:
    n = Node()
    assert n.send(0.0, n.port.now_ns()) and n.send(200.0, n.port.now_ns())
    assert n.counts() == dict.fromkeys(KEYS, 0)


def test_a_tension_exactly_max_age_old_is_solved_one_ns_older_is_stale() -> None:
    n = Node()  # input.max_age_s = 0.5
    assert n.send(8.0, n.port.now_ns() - 500 * MS)
    assert not n.send(8.0, n.port.now_ns() - 500 * MS - 1)
    assert not n.send(8.0, n.port.now_ns() - 10 * 10**9)
    assert n.counts()["dropped_stale"] == 2 and sum(n.counts().values()) == 2


def test_max_age_zero_disables_the_age_check() -> None:
    n = Node({"input.max_age_s": 0.0})
    assert n.send(8.0, n.port.now_ns() - 3600 * 10**9)
    assert n.counts() == dict.fromkeys(KEYS, 0)


def test_a_tension_exactly_max_future_ahead_is_solved_one_ns_further_is_dropped() -> None:
    """Issue 13: a stamp 3 years ahead passed the age check and was solved."""
    n = Node()  # input.max_future_s = 0.5
    assert n.send(8.0, n.port.now_ns() + 500 * MS)
    assert not n.send(8.0, n.port.now_ns() + 500 * MS + 1)
    assert not n.send(30.0, n.port.now_ns() + 3 * 365 * 86400 * 10**9)
    assert n.counts()["dropped_future"] == 2 and sum(n.counts().values()) == 2


def test_a_zero_stamp_is_dropped_as_unstamped_even_with_the_age_check_off() -> None:
    """Issue 13: a zero stamp skipped the age check and was solved."""
    for overrides in ({}, {"input.max_age_s": 0.0}):
        n = Node(overrides)
        assert not n.send(31.0, 0)
        assert n.counts() == {k: int(k == "dropped_unstamped") for k in KEYS}
        assert n.node.last_problem == "dropped tension 31.0 N: unstamped"


def test_the_limits_are_parameters_changed_at_runtime() -> None:
    n = Node()
    assert n.port.store.set({"input.tension_max": 10.0}).successful
    assert not n.send(10.5, n.port.now_ns()) and n.send(10.0, n.port.now_ns())
    assert n.port.store.set({"input.max_age_s": 2.0}).successful
    assert n.send(8.0, n.port.now_ns() - 2 * 10**9)
    assert not n.send(8.0, n.port.now_ns() - 2 * 10**9 - 1)
    assert n.counts() == {k: int(k in ("dropped_above_max", "dropped_stale")) for k in KEYS}


def test_every_drop_then_good_tensions_warn_then_recover_on_diagnostics() -> None:
    n = Node()
    now = n.port.now_ns()
    for tension, stamp_ns in ((float("nan"), now), (-3.0, now), (1e9, now),
                              (8.0, now - 10 * 10**9), (30.0, now + 10**9), (31.0, 0)):
        assert not n.send(tension, stamp_ns)
    assert n.counts() == dict.fromkeys(KEYS, 1)
    assert n.port.messages("midline") == []
    for _ in range(6 * 50):  # good tensions at 50 Hz for 6 diagnostics periods
        assert n.send(12.0, n.port.now_ns())
        n.port.advance(0.019)
    statuses = [a.status[0] for a in n.port.messages("/diagnostics")]
    assert statuses[0].level == 1 and statuses[0].message == "dropped tension 31.0 N: unstamped"
    assert statuses[-1].level == 0 and statuses[-1].message == "ok"
    values = {kv.key: kv.value for kv in statuses[-1].values}
    assert {k: values[k] for k in KEYS} == dict.fromkeys(KEYS, "1")


def test_drops_are_announced_on_the_log_with_the_reason_and_its_parameter(
        caplog: pytest.LogCaptureFixture) -> None:
    """Each kind of drop is logged at WARN the first time, naming why and the parameter that
    decides it; more of the same kind within 5 s (the port's clock) are held back and counted
    in the next line."""
    import logging

    n = Node()
    now = n.port.now_ns()
    with caplog.at_level(logging.WARNING):
        for _ in range(3):
            assert not n.send(20.0, 0)
        assert not n.send(20.0, now - 2 * 10**9)
        assert not n.send(20.0, now + 2 * 10**9)
        assert not n.send(500.0, now)
        n.port.advance(5.0)
        assert not n.send(20.0, 0)
    lines = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert lines[0] == ("dropped tension 20.0 N: header.stamp is 0 (never set): stamp it (tdcm "
                        "topic pub: {header: auto}), or send std_msgs/msg/Float64 with "
                        "input.tension_type")
    assert "stamped 2 s before the node's clock, older than input.max_age_s = 0.5 s" in lines[1]
    assert "--clock and use_sim_time: true" in lines[1]
    assert "stamped 2 s after the node's clock, more than input.max_future_s = 0.5 s" in lines[2]
    assert lines[3] == "dropped tension 500.0 N: above input.tension_max = 200 N"
    assert len(lines) == 5 and lines[4].endswith("(2 more like it in the last 5.0 s)")
    assert n.node.counts["dropped_unstamped"] == 4


def test_a_marker_rounded_past_the_tip_is_the_tip_and_a_refused_bound_is_printed_true() -> None:
    """An 80 mm tube whose notch width makes its length 0.0799999999999... m: a marker at 0.08 m
    (what a user writes) is taken at the tip; one 1 µm past it is refused with the true bound."""
    from tdcm_ros.errors import InputError
    from tdcm_ros.model import preset as design_preset

    base = design_preset("paper-experiment")
    n = Node({"design.w_t": base.w_t * (1 - 1e-12), "markers.arc_lengths": [0.02, base.length]})
    length = n.node.config.design.length
    assert length < base.length
    assert n.send(20.0, n.port.now_ns())
    with pytest.raises(InputError) as error:
        n.node._config({"markers.arc_lengths": [0.02, base.length + 1e-6]})
    assert f"[0, {length!r}] m" in str(error.value)


@pytest.mark.parametrize("rate", [30.0, 0.0])
def test_the_shape_is_drawn_at_the_visual_rate_and_the_tip_every_solve(rate: float) -> None:
    """1 kHz of inputs for 0.2 s: the tip and tendon state of each, the drawn topics at most
    ``output.visual_rate_hz`` by the inputs' stamps (0: each), the first one drawn."""
    n = Node({"output.visual_rate_hz": rate, "input.max_age_s": 0.0})
    first = n.port.now_ns()
    for k in range(200):
        assert n.send(10.0 + 0.01 * k, first + k * MS)
    drawn = [stamp(m) for m in n.port.messages("midline")]
    assert len(n.port.messages("tip_pose")) == len(n.port.messages("tendon_states")) == 200
    if rate == 0.0:
        assert len(drawn) == 200
    else:
        assert drawn[0] == first and np.all(np.diff(drawn) >= 1e9 / rate)
        assert len(drawn) == 6  # 0, 34, 68, 102, 136, 170 ms: every 34th of 1 ms stamps
    for topic in ("midline_poses", "predicted_markers", "body_markers", "joint_states"):
        assert [stamp(m) if hasattr(m, "header") else stamp(m.markers[0])
                for m in n.port.messages(topic)] == drawn, topic
