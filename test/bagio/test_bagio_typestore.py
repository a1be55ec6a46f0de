"""The message model: Jazzy typestore + msg_defs, RIHS01 hashes, CDR identical to rosbags."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from tdcm_ros.bagio import (
    BagError,
    deserialize,
    from_dict,
    msg_class,
    normalize_type_name,
    serialize,
    to_dict,
    type_hash,
)

MSG_DEFS = Path(__file__).resolve().parents[2] / "msg_defs"
# rmw_zenoh docs/design.md, "Topic and Service name mapping to Zenoh key expressions":
# 0/chatter/std_msgs::msg::dds_::String_/RIHS01_df668c74...1a18
STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
# rosidl_generator_c output of a Jazzy build of mocap4r2_msgs (marker__description.c,
# mocap4r2_msgs__msg__Marker__get_type_hash), bytes 0c ad b1 4b ... b9 43.
MOCAP_MARKER_HASH = "RIHS01_0cadb14b00eb93dfd5d1b774f04f13efc0c2e08a3bee1abbaef9f67f6b10b943"


def test_string_hash_matches_rmw_zenoh_docs() -> None:
    assert type_hash("std_msgs/msg/String") == STRING_HASH


def test_mocap4r2_marker_registered_with_upstream_hash() -> None:
    assert type_hash("mocap4r2_msgs/msg/Marker") == MOCAP_MARKER_HASH
    markers = msg_class("mocap4r2_msgs/msg/Markers")
    assert markers.__msgtype__ == "mocap4r2_msgs/msg/Markers"


def test_short_type_names_are_normalised() -> None:
    assert normalize_type_name("geometry_msgs/WrenchStamped") == "geometry_msgs/msg/WrenchStamped"
    with pytest.raises(BagError, match="unknown message type"):
        normalize_type_name("nope_msgs/msg/Nothing")


@pytest.mark.parametrize(("type_name", "fields"), [
    ("geometry_msgs/msg/WrenchStamped",
     {"header": {"stamp": {"sec": 3, "nanosec": 7}, "frame_id": "tdcm_base"},
      "wrench": {"force": {"z": 20.0}}}),
    ("nav_msgs/msg/Path", {"header": {"frame_id": "tdcm_base"},
                           "poses": [{"pose": {"position": {"x": 0.01 * i}}} for i in range(5)]}),
    ("mocap4r2_msgs/msg/Markers",
     {"frame_number": 42, "markers": [{"id_type": 2, "marker_index": 1, "marker_name": "m1",
                                       "translation": {"x": 0.1, "y": -0.2, "z": 0.3}}]}),
    ("sensor_msgs/msg/Image", {"height": 1, "width": 3, "data": [1, 2, 3]}),
    ("visualization_msgs/msg/MarkerArray", {"markers": [{"ns": "body", "id": 1}]}),
])
def test_cdr_round_trip_identical_to_rosbags(type_name: str, fields: dict) -> None:
    message = from_dict(type_name, fields)
    data = serialize(message)
    reference = get_typestore(Stores.ROS2_JAZZY)
    for path in MSG_DEFS.glob("*/msg/*.msg"):
        reference.register(get_types_from_msg(path.read_text(), f"{path.parts[-3]}/msg/{path.stem}"))
    assert data == bytes(reference.serialize_cdr(message, type_name))
    back = deserialize(data, type_name)
    assert serialize(back) == data
    assert to_dict(back) == to_dict(message)


def test_from_dict_fills_defaults_and_rejects_unknown_fields() -> None:
    message = from_dict("geometry_msgs/msg/WrenchStamped", {"wrench": {"force": {"z": 1}}})
    assert message.wrench.force.z == 1.0 and message.header.frame_id == ""
    image = from_dict("sensor_msgs/msg/Image", {"data": [1, 2]})
    assert image.data.dtype == np.uint8
    with pytest.raises(BagError, match="unknown field"):
        from_dict("std_msgs/msg/String", {"text": "x"})
    with pytest.raises(BagError, match="not a valid float64"):
        from_dict("std_msgs/msg/Float64", {"data": "abc"})


def test_deserialize_garbage_raises_bag_error() -> None:
    with pytest.raises(BagError, match="cannot deserialise"):
        deserialize(b"\x00\x01\x00\x00\x01", "geometry_msgs/msg/WrenchStamped")


def test_bytes_past_the_message_are_refused_unless_not_exact() -> None:
    """rclpy's serialize_message (rmw_fastrtps) pads past the message; only that path is lenient."""
    data = serialize(from_dict("std_msgs/msg/String", {"data": "hi"})) + b"\x60\x06\x0a\x75\xf9\x7f"
    with pytest.raises(BagError, match="size mismatch"):
        deserialize(data, "std_msgs/msg/String")
    assert deserialize(data, "std_msgs/msg/String", exact=False).data == "hi"
    with pytest.raises(BagError):
        deserialize(data[:9], "std_msgs/msg/String", exact=False)


def test_prepare_codec_builds_the_codec_of_a_type_and_its_fields_before_first_use() -> None:
    """rosbags generates a type's CDR code on first use (about 20 ms a type); prepare_codec does
    it at once, so a node's callback thread never pays it (a driver loop stalled by it misses the
    device's watchdog on a loaded machine)."""
    from tdcm_ros.bagio import prepare_codec, typestore

    name = "diagnostic_msgs/msg/DiagnosticArray"
    typestore().cache.pop(name, None)
    prepare_codec(name)
    assert {name, "diagnostic_msgs/msg/DiagnosticStatus", "diagnostic_msgs/msg/KeyValue",
            "std_msgs/msg/Header"} <= set(typestore().cache)
