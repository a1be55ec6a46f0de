"""The QoS a bag records per topic (``offered_qos_profiles``), folded into what a player offers,
and the reader's time range."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

from tdcm_ros.bagio import BagError
from tdcm_ros.bagio.qos import parse_profiles, recorded_qos
from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.bagio.writer import BagWriter, OfferedQos

LATCHED = {"history": "keep_last", "depth": 1, "reliability": "reliable",
           "durability": "transient_local"}
SENSOR = {"history": "keep_last", "depth": 5, "reliability": "best_effort",
          "durability": "volatile"}


def test_one_profile_is_kept() -> None:
    assert recorded_qos([LATCHED]) == OfferedQos(1, "reliable", "transient_local")
    assert recorded_qos([SENSOR]) == OfferedQos(5, "best_effort", "volatile")


def test_several_publishers_give_what_every_one_offers() -> None:
    # a best-effort or volatile publisher among them: the weaker policy, the largest depth
    assert recorded_qos([LATCHED, SENSOR]) == OfferedQos(5, "best_effort", "volatile")
    assert recorded_qos([LATCHED, {**LATCHED, "depth": 3}]) == OfferedQos(
        3, "reliable", "transient_local")


def test_no_profile_gives_the_defaults() -> None:
    assert recorded_qos([]) == OfferedQos()
    assert recorded_qos(parse_profiles("")) == OfferedQos()
    assert recorded_qos(parse_profiles("[: not yaml")) == OfferedQos()


def test_older_rosbag2_enum_numbers_and_yaml_text() -> None:
    text = "- history: 1\n  depth: 1\n  reliability: 1\n  durability: 1\n"
    assert recorded_qos(parse_profiles(text)) == OfferedQos(1, "reliable", "transient_local")
    assert recorded_qos(parse_profiles([{"reliability": 2, "durability": 2, "depth": 0}])) == \
        OfferedQos(10, "best_effort", "volatile")


def test_rosbags_qos_tuples() -> None:
    never = QosTime(sec=0, nsec=0)
    qos = Qos(QosHistory.KEEP_LAST, 7, QosReliability.BEST_EFFORT, QosDurability.TRANSIENT_LOCAL,
              never, never, QosLiveliness.AUTOMATIC, never, False)
    assert recorded_qos(parse_profiles([qos])) == OfferedQos(7, "best_effort", "transient_local")


def test_the_reader_gives_each_topics_recorded_qos_and_time_range(tmp_path: Path) -> None:
    writer = BagWriter(tmp_path / "bag")
    writer.add_topic("/tf_static", "tf2_msgs/msg/TFMessage", OfferedQos(1, "reliable",
                                                                       "transient_local"))
    writer.add_topic("/n", "std_msgs/msg/Float64", OfferedQos(100, "best_effort", "volatile"))
    writer.write("/tf_static", 2_000, b"\x00\x01\x00\x00\x00\x00\x00\x00")
    writer.write("/n", 5_000, b"\x00\x01\x00\x00" + bytes(8))
    writer.write("/n", 9_000, b"\x00\x01\x00\x00" + bytes(8))
    writer.close()
    reader = open_bag(tmp_path / "bag")
    assert reader.qos("tf_static") == OfferedQos(1, "reliable", "transient_local")
    assert reader.qos("/n") == OfferedQos(100, "best_effort", "volatile")
    assert reader.time_range_ns == (2_000, 9_000)
    with pytest.raises(BagError, match="no topic '/x'"):
        reader.qos("/x")
