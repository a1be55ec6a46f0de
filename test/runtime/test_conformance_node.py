"""Conformance: real embedded nodes seen by :class:`ros_peer.RosPeer`, a plain zenoh session that
follows only rmw_zenoh_cpp's formats (see ros_peer.py), checked byte for byte.

model_node: its ``NN`` token, ``MP``/``MS`` tokens (chunks, mangling, QoS strings), the data key
of ``/tip_pose``, a tension published by the peer and the tip pose it answers with (attachment:
sequence numbers from 1, GID = XXH3-128 of the publisher's token). tension_driver (no device):
its ``SS`` token, ``~/clear_faults`` called with a CDR request and rmw_zenoh's attachment (the
reply's attachment echoes the sequence number and the client's GID), and ``/rosout``.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from test.runtime.ros_peer import (
    RosPeer,
    Token,
    dds_type,
    gid,
    key_expr,
    qos_chunk,
    type_hash,
)
from test.support.waiting import eventually

pytest.importorskip("zenoh")

MODEL = "tdcm_ros.nodes.model_node:ModelNode"
DRIVER = "tdcm_ros.nodes.tension_driver:TensionDriverNode"
WRENCH, POSE = "geometry_msgs/msg/WrenchStamped", "geometry_msgs/msg/PoseStamped"
TRIGGER, LOG = "std_srvs/srv/Trigger", "rcl_interfaces/msg/Log"


@pytest.fixture
def peer(router: Any, zenoh_env: dict[str, str]) -> Iterator[RosPeer]:
    ros = RosPeer(os.environ["TDCM_ZENOH_ENDPOINT"], domain=0)
    yield ros
    ros.close()


def until(what: str, found: Callable[[], Any], timeout: float = 30.0) -> Any:
    """``found()`` once it gives something truthy (the suite's :func:`eventually`)."""
    return eventually(found, timeout, what)


def tokens_of(peer: RosPeer, node: str, required: list[tuple[str, str]]) -> list[Token]:
    """The tokens of node ``/node`` once it has a node token and the endpoints ``required``
    (``(kind, topic)`` pairs)."""
    def found() -> list[Token] | None:
        mine = [t for t in peer.tokens() if t.node == node]
        have = {(t.kind, t.topic) for t in mine}
        return mine if {("NN", ""), *required} <= have else None

    return until(f"the tokens {required} of /{node}", found)


def expected_token(node_token: Token, entity_id: str, kind: str, topic: str, type_name: str,
                   qos: str) -> str:
    """An endpoint token of the node as rmw_zenoh writes it (root namespace, enclave ``/``)."""
    return (f"@ros2_lv/0/{node_token.zid}/{node_token.nid}/{entity_id}/{kind}/%/%/"
            f"{node_token.node}/{topic.replace('/', '%')}/{dds_type(type_name)}/"
            f"{type_hash(type_name)}/{qos}")


def endpoint(tokens: list[Token], kind: str, topic: str) -> Token:
    [token] = [t for t in tokens if t.kind == kind and t.topic == topic]
    return token


def test_model_node_tokens_data_keys_and_attachments(peer: RosPeer, spawn: Any) -> None:
    node = spawn("tdcm_ros.runtime.run_node", MODEL)
    tips = peer.subscribe("/tip_pose", POSE)
    cases = [("MS", "/tension", WRENCH, qos_chunk(depth=100)),
             ("MP", "/tip_pose", POSE, qos_chunk(depth=10)),
             ("MP", "/tf_static", "tf2_msgs/msg/TFMessage",
              qos_chunk(durability="transient_local", depth=1)),
             ("MP", "/rosout", LOG, qos_chunk(durability="transient_local", depth=1000))]
    tokens = tokens_of(peer, "model_node", [(kind, topic) for kind, topic, _, _ in cases])
    [nn] = [t for t in tokens if t.kind == "NN"]
    assert nn.key == f"@ros2_lv/0/{nn.zid}/{nn.nid}/{nn.nid}/NN/%/%/model_node"
    for kind, topic, type_name, qos in cases:
        token = endpoint(tokens, kind, topic)
        assert token.key == expected_token(nn, token.id, kind, topic, type_name, qos)
    assert len({t.id for t in tokens}) == len(tokens)  # entity ids unique within the session
    assert node.poll() is None

    stamps: list[int] = []

    def send() -> None:
        """Publish a fresh 2 N tension (the node drops inputs older than 0.5 s)."""
        stamps.append(time.time_ns())
        payload = peer.publish("/tension", WRENCH, tension(peer, 2.0, stamps[-1]))
        assert payload[:4] == b"\x00\x01\x00\x00"  # CDR little endian, as rmw_zenoh sends

    samples = until("a tip pose", lambda: tips.samples or send())
    tip_token = endpoint(tokens, "MP", "/tip_pose")
    first = samples[0]
    assert first.key == key_expr(0, "/tip_pose", POSE)
    assert first.key == f"0/tip_pose/geometry_msgs::msg::dds_::PoseStamped_/{type_hash(POSE)}"
    assert first.payload[:4] == b"\x00\x01\x00\x00"
    assert first.attachment is not None and first.attachment.gid == gid(tip_token.key)
    assert abs(first.attachment.timestamp_ns - time.time_ns()) < 30e9
    header = first.message.header
    assert header.stamp.sec * 10**9 + header.stamp.nanosec in stamps  # stamped with our input
    until("a second tip pose", lambda: len(tips.samples) > 1 or send())
    numbers = [s.attachment.sequence_number for s in tips.wait(2) if s.attachment]
    assert numbers == list(range(1, len(numbers) + 1)) and len(numbers) >= 2


def tension(peer: RosPeer, newtons: float, stamp_ns: int) -> Any:
    """A ``WrenchStamped`` tension of ``newtons`` N along z stamped ``stamp_ns``."""
    vector = "geometry_msgs/msg/Vector3"
    return peer.message(WRENCH, header=peer.message(
        "std_msgs/msg/Header", frame_id="tdcm_tendon", stamp=peer.message(
            "builtin_interfaces/msg/Time", sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)),
        wrench=peer.message("geometry_msgs/msg/Wrench",
                            force=peer.message(vector, x=0.0, y=0.0, z=newtons),
                            torque=peer.message(vector, x=0.0, y=0.0, z=0.0)))


def test_driver_service_call_and_rosout(peer: RosPeer, spawn: Any, tmp_path: Path) -> None:
    params = tmp_path / "driver.yaml"
    params.write_text(yaml.safe_dump({"tension_driver": {"ros__parameters": {
        "port": str(tmp_path / "absent")}}}))
    spawn("tdcm_ros.runtime.run_node", DRIVER, "--params", str(params))
    logs = peer.subscribe("/rosout", LOG)
    service = "/tension_driver/clear_faults"
    tokens = tokens_of(peer, "tension_driver", [("SS", service), ("MP", "/rosout")])
    [nn] = [t for t in tokens if t.kind == "NN"]
    server = endpoint(tokens, "SS", service)
    assert server.key == expected_token(nn, server.id, "SS", service, TRIGGER, "::,10:,:,:,,")
    assert dds_type(TRIGGER) == "std_srvs::srv::dds_::Trigger_"

    request = peer.message(f"{TRIGGER}_Request", structure_needs_at_least_one_member=0)
    first = peer.call(service, TRIGGER, request)
    second = peer.call(service, TRIGGER, request)
    # One liveliness query is not enough: peer.tokens() returns what arrived within its 1 s
    # timeout, so under load a reply can be cut short. Poll until the token is seen.
    client = until("the peer's client token", lambda: [
        t for t in peer.tokens() if t.node == RosPeer.NAME and t.kind == "SC"])
    assert [t.topic for t in client] == [service]
    for number, reply in enumerate((first, second), start=1):
        assert reply.key == key_expr(0, service, TRIGGER)
        assert reply.payload[:4] == b"\x00\x01\x00\x00"
        assert reply.response.success is False
        assert reply.response.message.startswith("refused: link disconnected")
        assert reply.attachment.sequence_number == number
        assert reply.attachment.gid == peer.client_gid(service) == gid(client[0].key)

    nan = peer.message("std_msgs/msg/Float64", data=math.nan)
    warned = until("the NaN warning on /rosout", lambda: [
        s for s in logs.samples if "not finite" in s.message.msg] or (
        peer.publish("/tension_setpoint", "std_msgs/msg/Float64", nan) and None))
    record = warned[0]
    rosout = endpoint(tokens, "MP", "/rosout")
    assert record.key == key_expr(0, "/rosout", LOG)
    assert (record.message.level, record.message.name) == (30, "tension_driver")
    assert record.message.msg == "tension_setpoint = nan N is not finite; ignored"
    assert record.attachment is not None and record.attachment.gid == gid(rosout.key)
    assert record.attachment.sequence_number >= 1
