"""``tdcm topic pub``'s stamping keywords, as ``ros2 topic pub`` has them: a Header given
``auto`` and a Time given ``now`` are stamped with the time of each publish."""

from __future__ import annotations

import pytest

from tdcm_ros.bagio import BagError, from_dict
from tdcm_ros.cli.topic import flow_yaml, with_stamps

NOW = 1_800_000_123_456_789_012


def test_header_auto_is_stamped_now_with_an_empty_frame() -> None:
    values = with_stamps("geometry_msgs/msg/WrenchStamped",
                         {"header": "auto", "wrench": {"force": {"z": 8.0}}}, NOW)
    message = from_dict("geometry_msgs/msg/WrenchStamped", values)
    assert (message.header.stamp.sec, message.header.stamp.nanosec) == (1_800_000_123,
                                                                        456_789_012)
    assert message.header.frame_id == "" and message.wrench.force.z == 8.0


def test_time_now_is_stamped_at_any_depth_and_other_values_are_kept() -> None:
    clock = from_dict("rosgraph_msgs/msg/Clock", with_stamps("rosgraph_msgs/msg/Clock",
                                                             {"clock": "now"}, NOW))
    assert clock.clock.sec == 1_800_000_123
    stamp = {"sec": 5, "nanosec": 6}
    kept = with_stamps("geometry_msgs/msg/PoseStamped", {"header": {"stamp": stamp}}, NOW)
    assert kept == {"header": {"stamp": stamp}}


def test_a_keyword_where_it_means_nothing_is_still_an_error() -> None:
    with pytest.raises(BagError, match="expected a mapping of fields"):
        from_dict("geometry_msgs/msg/Wrench", with_stamps("geometry_msgs/msg/Wrench",
                                                          {"force": "auto"}, NOW))


def test_a_message_prints_as_one_line_of_yaml() -> None:
    assert flow_yaml({"header": {"stamp": {"sec": 1, "nanosec": 2}, "frame_id": ""},
                      "data": [1.5, 2.0]}) == (
        "{header: {stamp: {sec: 1, nanosec: 2}, frame_id: ''}, data: [1.5, 2.0]}")
