"""Transient-local endpoints of the embedded runtime behave as rmw_zenoh's (Jazzy 0.2.9,
``rmw_publisher_data.cpp`` / ``rmw_subscription_data.cpp``), seen from a plain zenoh session
that uses zenoh-ext's advanced publisher/subscriber protocol as rmw_zenoh does: a reliable
transient-local publisher is detectable, caches ``depth`` samples for late joiners and sends
sporadic heartbeats carrying its last sequence number; a transient-local subscription is
detectable and asks for history and heartbeat recovery. Not exercised: an actual lost sample
being recovered (zenoh gives no way to drop one sample on a loopback link)."""

from __future__ import annotations

import json
import struct
import time
from typing import Any

import pytest

from tdcm_ros.bagio import from_dict, serialize, type_hash
from tdcm_ros.runtime import wire
from tdcm_ros.runtime.port import QoS
from test.support.waiting import eventually

zenoh = pytest.importorskip("zenoh", reason="eclipse-zenoh not installed")
pytest.importorskip("zenoh.ext", reason="eclipse-zenoh without zenoh.ext")

STRING = "std_msgs/msg/String"
LATCHED = QoS(depth=3, durability="transient_local")


def _plain_session() -> Any:
    """A zenoh client of the test's router (``TDCM_ZENOH_ENDPOINT``), as a ROS peer would be."""
    import os

    config = zenoh.Config()
    config.insert_json5("mode", json.dumps("client"))
    config.insert_json5("connect/endpoints", json.dumps([os.environ["TDCM_ZENOH_ENDPOINT"]]))
    return zenoh.open(config)


def _key(port_topic: str) -> str:
    from tdcm_ros.runtime import wire

    return wire.topic_key(0, port_topic, STRING, type_hash(STRING))


def test_a_reliable_latched_publisher_is_detectable_caches_and_sends_heartbeats(
        context: Any) -> None:
    session = _plain_session()
    try:
        key = _key("/config")
        heartbeats: list[tuple[str, bytes]] = []
        listener = session.declare_subscriber(
            f"{key}/@adv/pub/**", lambda s: heartbeats.append((str(s.key_expr),
                                                                s.payload.to_bytes())))
        publisher = context.create_port("latched").create_publisher("config", STRING, LATCHED)
        for text in ("v1", "v2", "v3", "v4"):
            publisher.publish(from_dict(STRING, {"data": text}))
        eventually(lambda: bool(heartbeats), 5.0, "a heartbeat")
        name, payload = heartbeats[-1]
        assert struct.unpack("<I", payload) == (3,)  # sequence numbers of the 4 samples: 0..3
        tokens = [str(r.ok.key_expr) for r in
                  session.liveliness().get(f"{key}/@adv/pub/**", timeout=5.0) if r.ok]
        assert tokens == [name]  # the heartbeat comes from the detectable publisher's id
        got: list[bytes] = []
        late = zenoh.ext.declare_advanced_subscriber(
            session, key, lambda s: got.append(s.payload.to_bytes()),
            history=zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=3),
            recovery=zenoh.ext.RecoveryConfig(heartbeat=True))
        eventually(lambda: len(got) == 3, 10.0, "the cached samples")
        assert [bytes(b)[-3:-1] for b in got] == [b"v2", b"v3", b"v4"]  # depth 3, oldest dropped
        late.undeclare()
        listener.undeclare()
    finally:
        session.close()


def test_a_best_effort_latched_publisher_sends_no_heartbeat(context: Any) -> None:
    """Beside it a reliable latched publisher, declared and published after it, whose second
    heartbeat (a heartbeat period after its first, so after a tick of the best-effort one's
    period too, had it one) is heard before the best-effort one is checked."""
    session = _plain_session()
    try:
        loose_key, firm_key = _key("/loose"), _key("/firm")
        heartbeats: dict[str, list[bytes]] = {loose_key: [], firm_key: []}
        listeners = [session.declare_subscriber(
            f"{key}/@adv/pub/**", lambda s, key=key: heartbeats[key].append(s.payload.to_bytes()))
            for key in heartbeats]
        port = context.create_port("latched")
        loose = port.create_publisher("loose", STRING, QoS(depth=1, reliability="best_effort",
                                                            durability="transient_local"))
        firm = port.create_publisher("firm", STRING, LATCHED)
        loose.publish(from_dict(STRING, {"data": "x"}))
        firm.publish(from_dict(STRING, {"data": "a"}))
        eventually(lambda: heartbeats[firm_key], 10.0, "the reliable publisher's heartbeat")
        firm.publish(from_dict(STRING, {"data": "b"}))
        eventually(lambda: len(heartbeats[firm_key]) >= 2, 10.0,
                   "the reliable publisher's next heartbeat")
        assert struct.unpack("<I", heartbeats[firm_key][-1]) == (1,)  # its second sample
        assert heartbeats[loose_key] == []
        tokens = [str(r.ok.key_expr) for r in
                  session.liveliness().get(f"{loose_key}/@adv/pub/**", timeout=5.0) if r.ok]
        assert len(tokens) == 1  # still detectable, with its cache
        for listener in listeners:
            listener.undeclare()
    finally:
        session.close()


def test_a_latched_subscription_is_detectable_and_hears_a_late_publisher(
        context: Any) -> None:
    """A plain advanced publisher with rmw_zenoh's options, declared after the subscription,
    publishes once; the subscription (detectable, through its token) receives the sample."""
    session = _plain_session()
    try:
        key = _key("/state")
        got: list[str] = []
        context.create_port("reader").create_subscription(
            "state", STRING, lambda m: got.append(m.data), LATCHED)
        eventually(lambda: any(r.ok for r in session.liveliness().get(
            f"{key}/@adv/sub/**", timeout=2.0)), 10.0, "the subscription's detection token")
        publisher = zenoh.ext.declare_advanced_publisher(
            session, key, cache=zenoh.ext.CacheConfig(3),
            sample_miss_detection=zenoh.ext.MissDetectionConfig(sporadic_heartbeat=0.5),
            publisher_detection=True)
        # with rmw_zenoh's attachment, as every rmw_zenoh publisher sends it (a subscription
        # refuses a sample without one)
        publisher.put(serialize(from_dict(STRING, {"data": "seen"}), STRING),
                      attachment=wire.encode_attachment(1, time.time_ns(), bytes(wire.GID_SIZE)))
        eventually(lambda: got, 10.0, "the late publisher's sample", spin=context)
        assert got == ["seen"]
        publisher.undeclare()
    finally:
        session.close()
