"""Conformance vectors written from rmw_zenoh_cpp's Jazzy sources (release 0.2.9:
``liveliness_utils.cpp`` ``Entity``/``TopicInfo``/``qos_to_keyexpr``, ``qos.cpp``,
``attachment_helpers.cpp``, ``rmw_service_data.cpp``) checked against the package's wire
functions, and the independent reading in ros_peer.py checked against the package's."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.bagio import service_type_hash, type_hash
from tdcm_ros.runtime import wire
from tdcm_ros.runtime.port import QoS
from test.runtime.ros_peer import (
    SERVICES,
    STORE,
    attachment,
    gid,
    parse_attachment,
    parse_token,
    qos_chunk,
)
from test.runtime.ros_peer import key_expr as peer_key
from test.runtime.ros_peer import type_hash as peer_hash

ZID = "8f2b9c0d4e5a61728394a5b6c7d8e9f0"
NODE = wire.NodeIdentity(domain_id=7, zid=ZID, node_id=3, namespace="/robot/arm",
                         name="model_node")
POSE = "geometry_msgs/msg/PoseStamped"
POSE_HASH = "RIHS01_10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8"
TRIGGER_HASH = "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"

# (QoS, the chunk rmw_zenoh writes): empty where equal to its defaults (reliable=1, volatile=2,
# keep-last=1, depth 42, infinite durations, automatic liveliness); values from rmw/types.h.
QOS_VECTORS = [
    (QoS(depth=10), "::,10:,:,:,,"),
    (QoS(depth=42), "::,:,:,:,,"),
    (QoS(depth=1, durability="transient_local"), ":1:,1:,:,:,,"),
    (QoS(depth=5, reliability="best_effort"), "2::,5:,:,:,,"),
    (QoS(depth=1000, durability="transient_local"), ":1:,1000:,:,:,,"),
    (QoS(depth=1, reliability="best_effort", durability="transient_local"), "2:1:,1:,:,:,,"),
]


def test_the_pose_type_hash_is_jazzy_s() -> None:
    assert type_hash(POSE) == peer_hash(POSE) == POSE_HASH


def test_node_token() -> None:
    assert wire.node_token(NODE) == f"@ros2_lv/7/{ZID}/3/3/NN/%/%robot%arm/model_node"


@pytest.mark.parametrize(("qos", "chunk"), QOS_VECTORS)
def test_qos_chunks(qos: QoS, chunk: str) -> None:
    assert wire.qos_chunk(qos) == chunk
    assert qos_chunk(qos.reliability, qos.durability, qos.depth) == chunk


def test_publisher_and_subscription_tokens_and_data_key() -> None:
    topic = "/robot/arm/tip_pose"
    expected = (f"@ros2_lv/7/{ZID}/3/12/MP/%/%robot%arm/model_node/%robot%arm%tip_pose/"
                f"geometry_msgs::msg::dds_::PoseStamped_/{POSE_HASH}/::,10:,:,:,,")
    token = wire.endpoint_token(NODE, 12, wire.PUBLISHER, topic, POSE, POSE_HASH, QoS(depth=10))
    assert token == expected
    subscription = wire.endpoint_token(NODE, 13, wire.SUBSCRIPTION, topic, POSE, POSE_HASH,
                                       QoS(depth=42))
    assert subscription == expected.replace("/12/MP/", "/13/MS/").replace(",10:", ",:")
    key = f"7/robot/arm/tip_pose/geometry_msgs::msg::dds_::PoseStamped_/{POSE_HASH}"
    assert wire.topic_key(7, topic, POSE, POSE_HASH) == peer_key(7, topic, POSE) == key
    parsed, theirs = wire.parse_token(token), parse_token(token)
    assert (parsed.kind, parsed.namespace, parsed.node_name, parsed.topic, parsed.type_name,
            parsed.type_hash, parsed.qos) == ("MP", "/robot/arm", "model_node", topic, POSE,
                                              POSE_HASH, "::,10:,:,:,,")
    assert (theirs.zid, theirs.nid, theirs.id, theirs.enclave, theirs.type) == (
        ZID, "3", "12", "/", "geometry_msgs::msg::dds_::PoseStamped_")


def test_service_server_and_client_tokens_and_key() -> None:
    service = "/robot/arm/model_node/clear_faults"
    trigger = "std_srvs/srv/Trigger"
    assert service_type_hash(trigger) == peer_hash(trigger) == TRIGGER_HASH
    server = wire.endpoint_token(NODE, 20, wire.SERVICE, service, trigger, TRIGGER_HASH,
                                 wire.SERVICE_QOS)
    assert server == (f"@ros2_lv/7/{ZID}/3/20/SS/%/%robot%arm/model_node/"
                      f"%robot%arm%model_node%clear_faults/std_srvs::srv::dds_::Trigger_/"
                      f"{TRIGGER_HASH}/::,10:,:,:,,")
    client = wire.endpoint_token(NODE, 21, wire.CLIENT, service, trigger, TRIGGER_HASH,
                                 wire.SERVICE_QOS)
    assert client == server.replace("/20/SS/", "/21/SC/")
    key = f"7/robot/arm/model_node/clear_faults/std_srvs::srv::dds_::Trigger_/{TRIGGER_HASH}"
    assert wire.topic_key(7, service, trigger, TRIGGER_HASH) == peer_key(7, service, trigger) == key


def test_attachment_bytes() -> None:
    """int64 42, int64 0x0102030405060708 (little endian), then the 16-byte GID as a zenoh-ext
    sequence: its length 16 as one LEB128 byte, then the bytes."""
    source = bytes(range(0xA0, 0xB0))
    expected = bytes.fromhex("2a00000000000000" "0807060504030201" "10"
                             "a0a1a2a3a4a5a6a7a8a9aaabacadaeaf")
    assert wire.encode_attachment(42, 0x0102030405060708, source) == expected
    assert attachment(42, 0x0102030405060708, source) == expected
    decoded = wire.decode_attachment(expected)
    assert (decoded.sequence_number, decoded.source_timestamp_ns, decoded.gid) == (
        42, 0x0102030405060708, source)
    assert parse_attachment(expected).gid == source
    negative = wire.encode_attachment(-1, -2, source)
    assert negative[:16] == b"\xff" * 8 + b"\xfe" + b"\xff" * 7


@given(st.text(min_size=1, max_size=300))
def test_the_gid_matches_an_independent_xxh3_reading(token: str) -> None:
    """The package's GID (an integer to little-endian bytes) equals ros_peer's (the canonical
    big-endian digest split into high64 and low64, stored low then high as rmw_zenoh's
    memcpy of ``XXH128_hash_t`` does)."""
    assert wire.gid_of(token) == gid(token)


@pytest.mark.parametrize("service", sorted(SERVICES))
def test_the_package_s_service_hash_is_the_peer_s_pinned_one(service: str) -> None:
    """bagio's service types (the .srv text of tdcm_ros/bagio/services.py) hash as the
    independent peer's pinned Jazzy hashes (checked against Jazzy's files in the rclpy half)."""
    assert service_type_hash(service) == peer_hash(service)


@pytest.mark.parametrize("service", sorted(SERVICES))
def test_the_peer_s_service_types_round_trip(service: str) -> None:
    for half in ("Request", "Response"):
        name = f"{service}_{half}"
        message = STORE.types[name](**{field: _default(desc) for field, desc in
                                       STORE.fielddefs[name][1]})
        data = bytes(STORE.serialize_cdr(message, name))
        assert bytes(STORE.serialize_cdr(STORE.deserialize_cdr(data, name), name)) == data


def _default(desc: object) -> object:
    kind, detail = desc  # type: ignore[misc]
    if kind == 1:  # a base type
        return {"string": "", "bool": False}.get(detail[0], 0)
    if kind == 2:  # a nested message
        name = detail
        return STORE.types[name](**{f: _default(d) for f, d in STORE.fielddefs[name][1]})
    inner = detail[0]  # a sequence: rosbags keeps numbers in numpy arrays, the rest in lists
    if inner[0] == 1 and inner[1][0] != "string":
        return np.zeros(0, dtype={"bool": np.bool_, "byte": np.uint8, "char": np.uint8}.get(
            inner[1][0], inner[1][0]))
    return []


@pytest.mark.rclpy
@pytest.mark.parametrize("service", sorted(SERVICES))
def test_pinned_service_hashes_and_fields_are_jazzy_s(service: str) -> None:
    """ros_peer's service hashes are those of ROS 2 Jazzy's type descriptions, and its request
    and response fields those of the rosidl classes."""
    import importlib

    package, _, name = service.split("/")
    description = json.loads((_share(package) / "srv" / f"{name}.json").read_text())
    [pinned] = [h["hash_string"] for h in description["type_hashes"]
                if h["type_name"] == service]
    assert SERVICES[service][2] == pinned
    module = importlib.import_module(f"{package}.srv")
    for half in ("Request", "Response"):
        rosidl = getattr(getattr(module, name), half).get_fields_and_field_types()
        ours = [field for field, _ in STORE.fielddefs[f"{service}_{half}"][1]]
        assert ours == list(rosidl) or (ours == ["structure_needs_at_least_one_member"]
                                        and not rosidl)


def _share(package: str) -> Path:
    """Where ``package`` installed its share folder: the ament index, else the Python
    environment's ``share/`` (ROS wheels installed into a virtual environment)."""
    from ament_index_python.packages import (
        PackageNotFoundError,
        get_package_share_directory,
    )

    try:
        return Path(get_package_share_directory(package))
    except PackageNotFoundError:
        return Path(sys.prefix) / "share" / package
