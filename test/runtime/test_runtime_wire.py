"""rmw_zenoh wire conventions: keys, liveliness tokens, QoS chunk, attachment layout.

Expected strings are the published examples of ros2/rmw_zenoh ``docs/design.md`` (Jazzy
branch): sections "Topic and Service name mapping to Zenoh key expressions" and "Graph Cache".
"""

from __future__ import annotations

import pytest

from tdcm_ros.bagio import type_hash
from tdcm_ros.runtime.errors import RuntimePortError
from tdcm_ros.runtime.port import QoS
from tdcm_ros.runtime.wire import (
    NodeIdentity,
    dds_type_name,
    decode_attachment,
    encode_attachment,
    endpoint_token,
    gid_of,
    node_token,
    parse_token,
    qos_chunk,
    ros_type_name,
    topic_key,
)

HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"


def test_type_chunk() -> None:
    assert dds_type_name("std_msgs/msg/String") == "std_msgs::msg::dds_::String_"
    assert ros_type_name("geometry_msgs::msg::dds_::WrenchStamped_") == (
        "geometry_msgs/msg/WrenchStamped")


@pytest.mark.parametrize(("topic", "expected"), [
    ("/chatter", f"0/chatter/std_msgs::msg::dds_::String_/{HASH}"),
    ("/robot1/chatter", f"0/robot1/chatter/std_msgs::msg::dds_::String_/{HASH}"),
])
def test_topic_keys_match_design_md(topic: str, expected: str) -> None:
    assert topic_key(0, topic, "std_msgs/msg/String", type_hash("std_msgs/msg/String")) == expected


def test_node_token_matches_design_md() -> None:
    listener = NodeIdentity(2, "aac3178e146ba6f1fc6e6a4085e77f21", 0, "/", "listener")
    assert node_token(listener) == "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"


def test_endpoint_tokens_match_design_md() -> None:
    listener = NodeIdentity(2, "aac3178e146ba6f1fc6e6a4085e77f21", 0, "/", "listener")
    talker = NodeIdentity(2, "8b20917502ee955ac4476e0266340d5c", 0, "/", "talker")
    assert endpoint_token(listener, 10, "MS", "/chatter", "std_msgs/msg/String", HASH,
                          QoS(depth=10)) == (
        "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/"
        f"std_msgs::msg::dds_::String_/{HASH}/::,10:,:,:,,")
    assert endpoint_token(talker, 10, "MP", "/chatter", "std_msgs/msg/String", HASH,
                          QoS(depth=7)) == (
        "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/"
        f"std_msgs::msg::dds_::String_/{HASH}/::,7:,:,:,,")


def test_qos_chunk_non_defaults_use_rmw_enums() -> None:
    # rmw/types.h: BEST_EFFORT = 2, TRANSIENT_LOCAL = 1; rmw_zenoh default depth 42 is empty
    assert qos_chunk(QoS(depth=5, reliability="best_effort", durability="transient_local")) == (
        "2:1:,5:,:,:,,")
    assert qos_chunk(QoS(depth=42)) == "::,:,:,:,,"


def test_parse_token_round_trip_with_namespace() -> None:
    node = NodeIdentity(0, "abc", 3, "/robot1", "model")
    token = endpoint_token(node, 4, "MP", "/robot1/midline", "nav_msgs/msg/Path",
                           type_hash("nav_msgs/msg/Path"), QoS())
    assert "/%robot1/model/%robot1%midline/nav_msgs::msg::dds_::Path_/" in token
    info = parse_token(token)
    assert (info.kind, info.topic, info.type_name, info.node_fqn) == (
        "MP", "/robot1/midline", "nav_msgs/msg/Path", "/robot1/model")
    with pytest.raises(RuntimePortError):
        parse_token("@ros2_lv/0/abc")


def test_attachment_layout_is_zenoh_ext_serialisation() -> None:
    zenoh_ext = pytest.importorskip("zenoh.ext", reason="eclipse-zenoh not installed")
    gid = bytes(range(16))
    ours = encode_attachment(7, 1_700_000_000_123_456_789, gid)
    theirs = zenoh_ext.z_serialize(
        (zenoh_ext.Int64(7), zenoh_ext.Int64(1_700_000_000_123_456_789), gid)).to_bytes()
    assert ours == theirs and len(ours) == 33
    decoded = decode_attachment(ours)
    assert (decoded.sequence_number, decoded.source_timestamp_ns, decoded.gid) == (
        7, 1_700_000_000_123_456_789, gid)
    with pytest.raises(RuntimePortError):
        decode_attachment(b"\x00" * 12)


# GIDs printed by rmw_zenoh's own hash (rmw_zenoh_cpp 0.2.9, src/detail/simplified_xxhash3.cpp,
# compiled with test/runtime/conformance/gid_vectors.cpp: low64 then high64, as Entity copies them).
RMW_ZENOH_GIDS = {
    "": "7f498d4624c30160d8984701d306aa99",
    "a": "1f4e961eb632c6e63468f15a70af6fa9",
    "@ros2_lv/0/aaaabbbbccccddddeeeeffff00001111/0/11/MP/%/%/model_node/%tdcm%tip_path/"
    "nav_msgs::msg::dds_::Path_/RIHS01_1234/::,7:,:,:,,": "d182e6b2a3b91e7f1624334a3b15e62d",
    "@ros2_lv/42/0123456789abcdef0123456789abcdef/3/4/SS/%/%tdcm/tension_driver/"
    "%tension_driver%start_schedule/std_srvs::srv::dds_::Trigger_/RIHS01_abcd/::,10:,:,:,,":
        "d57bcc0a6e786a6462efe0073f610d73",
}


@pytest.mark.parametrize("token", sorted(RMW_ZENOH_GIDS))
def test_gid_is_rmw_zenohs_xxh3_of_the_token(token: str) -> None:
    assert gid_of(token).hex() == RMW_ZENOH_GIDS[token]
