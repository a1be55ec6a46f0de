"""BagWriter -> open_bag round trips, bare MCAP files, ros2-bag-shaped MCAP, bad bags."""

from __future__ import annotations

import shutil
import struct
import uuid
from pathlib import Path

import pytest
import yaml
from mcap.reader import SeekingReader
from mcap.writer import Writer
from rosbags.rosbag2 import Reader as RosbagsReader
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as RosbagsWriter

from tdcm_ros.bagio import BagError, from_dict, serialize, to_dict, type_hash, typestore
from tdcm_ros.bagio.reader import open_bag, require_topic
from tdcm_ros.bagio.writer import BagWriter, OfferedQos

T0 = 1_700_000_000_000_000_000


def _wrench(force_z: float, stamp_ns: int) -> object:
    return from_dict("geometry_msgs/msg/WrenchStamped", {
        "header": {"stamp": {"sec": stamp_ns // 10**9, "nanosec": stamp_ns % 10**9},
                   "frame_id": "tdcm_tendon"},
        "wrench": {"force": {"z": force_z}}})


def _markers(k: int) -> object:
    return from_dict("mocap4r2_msgs/msg/Markers", {
        "header": {"frame_id": "mocap"}, "frame_number": k,
        "markers": [{"marker_name": f"m{j + 1}", "marker_index": j,
                     "translation": {"x": 0.001 * k, "y": 0.01 * j, "z": 0.015 + 0.02 * j}}
                    for j in range(3)]})


def _tf() -> object:
    return from_dict("tf2_msgs/msg/TFMessage", {"transforms": [{
        "header": {"frame_id": "mocap"}, "child_frame_id": "tdcm_base",
        "transform": {"translation": {"x": 0.1}, "rotation": {"w": 1.0}}}]})


def _expected() -> list[tuple[str, int, str, object]]:
    """(topic, log time, type, message) of a small trial, in log-time order."""
    out: list[tuple[str, int, str, object]] = [
        ("/tf_static", T0, "tf2_msgs/msg/TFMessage", _tf())]
    for i in range(200):
        t = T0 + 1_000_000 * (i + 1)
        out.append(("/tension", t, "geometry_msgs/msg/WrenchStamped", _wrench(0.05 * i, t)))
        if i % 10 == 5:
            out.append(("/markers", t + 1, "mocap4r2_msgs/msg/Markers", _markers(i)))
        if i % 50 == 0:
            out.append(("/tension_setpoint", t + 2, "std_msgs/msg/Float64",
                        from_dict("std_msgs/msg/Float64", {"data": i / 10})))
    return out


def _write(path: Path, **options: object) -> list[tuple[str, int, str, object]]:
    expected = _expected()
    with BagWriter(path, **options) as writer:  # type: ignore[arg-type]
        writer.add_topic("/tf_static", "tf2_msgs/msg/TFMessage",
                         OfferedQos(depth=1, durability="transient_local"))
        for topic, stamp, msgtype, message in expected:
            writer.add_topic(topic, msgtype)
            writer.write(topic, stamp, serialize(message, msgtype))
    return expected


def _as_plain(messages: list[tuple[str, int, object]]) -> list[tuple[str, int, object]]:
    return [(topic, stamp, to_dict(message)) for topic, stamp, message in messages]


def test_round_trip_four_types_and_metadata_v9(tmp_path: Path) -> None:
    expected = _write(tmp_path / "trial")
    reader = open_bag(tmp_path / "trial")
    assert reader.warnings == []
    assert reader.topics == {"/tf_static": "tf2_msgs/msg/TFMessage",
                             "/tension": "geometry_msgs/msg/WrenchStamped",
                             "/markers": "mocap4r2_msgs/msg/Markers",
                             "/tension_setpoint": "std_msgs/msg/Float64"}
    got = _as_plain(list(reader.messages()))
    assert got == [(t, s, to_dict(m)) for t, s, _, m in expected]
    assert reader.counts == {"/tf_static": 1, "/tension": 200, "/markers": 20,
                             "/tension_setpoint": 4}
    info = yaml.safe_load((tmp_path / "trial" / "metadata.yaml").read_text())
    info = info["rosbag2_bagfile_information"]
    assert info["version"] == 9
    assert info["storage_identifier"] == "mcap"
    assert info["message_count"] == len(expected)
    assert info["relative_file_paths"] == ["trial_0.mcap"]
    assert info["starting_time"]["nanoseconds_since_epoch"] == T0
    assert info["duration"]["nanoseconds"] == expected[-1][1] - T0
    by_topic = {e["topic_metadata"]["name"]: e for e in info["topics_with_message_count"]}
    tf = by_topic["/tf_static"]["topic_metadata"]
    assert tf["offered_qos_profiles"][0]["durability"] == "transient_local"
    assert tf["offered_qos_profiles"][0]["depth"] == 1
    assert tf["type_description_hash"] == type_hash("tf2_msgs/msg/TFMessage")
    assert by_topic["/markers"]["message_count"] == 20


def test_topic_filter_and_short_names(tmp_path: Path) -> None:
    expected = _write(tmp_path / "trial")
    reader = open_bag(tmp_path / "trial")
    got = _as_plain(list(reader.messages(["tension", "/markers"])))
    assert got == [(t, s, to_dict(m)) for t, s, _, m in expected if t in ("/tension", "/markers")]
    assert require_topic(reader, "markers", ["mocap4r2_msgs/msg/Markers"]) == "/markers"


def test_rosbags_reads_our_bag_with_definitions_and_qos(tmp_path: Path) -> None:
    """An independent rosbag2 reader sees the same topics, counts and QoS."""
    expected = _write(tmp_path / "trial")
    with RosbagsReader(tmp_path / "trial") as bag:
        connections = {c.topic: c for c in bag.connections}
        assert connections["/markers"].msgtype == "mocap4r2_msgs/msg/Markers"
        assert "MSG: mocap4r2_msgs/Marker" in connections["/markers"].msgdef.data
        assert "builtin_interfaces/Time stamp" in connections["/tension"].msgdef.data
        qos = connections["/tf_static"].ext.offered_qos_profiles[0]
        assert qos.durability.name == "TRANSIENT_LOCAL"
        assert sum(1 for _ in bag.messages()) == len(expected)


def test_bare_mcap_file_of_a_bag(tmp_path: Path) -> None:
    expected = _write(tmp_path / "trial")
    bare = tmp_path / "copy.mcap"
    shutil.copy(tmp_path / "trial" / "trial_0.mcap", bare)
    reader = open_bag(bare)
    assert reader.warnings == []
    assert len(list(reader.messages())) == len(expected)


def test_uncompressed_unchunked_mcap_without_summary(tmp_path: Path) -> None:
    """An MCAP without chunks or summary (a minimal writer) is read by a linear scan."""
    path = tmp_path / "plain.mcap"
    with path.open("wb") as stream:
        writer = Writer(stream, use_chunking=False, use_statistics=False,
                        use_summary_offsets=False, repeat_channels=False, repeat_schemas=False)
        writer.start(profile="ros2", library="test")
        definition = typestore().generate_msgdef("std_msgs/msg/Float64", ros_version=2)[0]
        schema = writer.register_schema("std_msgs/msg/Float64", "ros2msg", definition.encode())
        channel = writer.register_channel("/x", "cdr", schema)
        for i in range(5):
            data = serialize(from_dict("std_msgs/msg/Float64", {"data": float(i)}))
            writer.add_message(channel, T0 + i, data, T0 + i)
        writer.finish()
    reader = open_bag(path)
    assert [m.data for _, _, m in reader.messages()] == [0.0, 1.0, 2.0, 3.0, 4.0]


def test_sqlite3_rosbag2_folder(tmp_path: Path) -> None:
    """A sqlite3 (db3) bag written by rosbags is read with its topics in log-time order."""
    expected = _expected()
    with RosbagsWriter(tmp_path / "db", version=9,
                       storage_plugin=StoragePlugin.SQLITE3) as writer:
        connections = {}
        for topic, stamp, msgtype, message in expected:
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=typestore())
            writer.write(connections[topic], stamp, serialize(message, msgtype))
    reader = open_bag(tmp_path / "db")
    assert reader.topics["/markers"] == "mocap4r2_msgs/msg/Markers"
    assert _as_plain(list(reader.messages())) == [(t, s, to_dict(m)) for t, s, _, m in expected]


def _reading_cdr(sec: int, nanosec: int, value: float, text: str, ident: int) -> bytes:
    """CDR (little endian) of the Reading type below, packed by hand."""
    body = struct.pack("<iI", sec, nanosec) + struct.pack("<d", value)
    raw = text.encode() + b"\0"
    body += struct.pack("<I", len(raw)) + raw
    return b"\x00\x01\x00\x00" + body + struct.pack("<B", ident)


def test_ros2_bag_shaped_mcap_with_a_type_we_do_not_know(tmp_path: Path) -> None:
    """Profile ros2, ros2msg schema with a nested package type, CDR payloads, QoS metadata."""
    package = f"lab_{uuid.uuid4().hex[:8]}_msgs"
    msgtype = f"{package}/msg/Reading"
    assert msgtype not in typestore().types
    definition = (
        "builtin_interfaces/Time stamp\nfloat64 value\nLabel label\n"
        "================================================================================\n"
        f"MSG: {package}/Label\nstring text\nuint8 id\n"
        "================================================================================\n"
        "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n")
    qos = yaml.safe_dump([{"history": "keep_last", "depth": 10, "reliability": "reliable",
                           "durability": "volatile"}])
    path = tmp_path / "from_ros2.mcap"
    with path.open("wb") as stream:
        writer = Writer(stream, chunk_size=256)
        writer.start(profile="ros2", library="rosbag2 (test)")
        schema = writer.register_schema(msgtype, "ros2msg", definition.encode())
        channel = writer.register_channel("/sensor/reading", "cdr", schema,
                                          {"offered_qos_profiles": qos})
        for i in range(30):
            writer.add_message(channel, T0 + 10 * i, _reading_cdr(7, i, 0.5 * i, f"r{i}", i),
                               T0 + 10 * i, sequence=i)
        writer.finish()
    reader = open_bag(path)
    assert reader.topics == {"/sensor/reading": msgtype}
    got = list(reader.messages())
    assert [stamp for _, stamp, _ in got] == [T0 + 10 * i for i in range(30)]
    last = got[-1][2]
    assert (last.stamp.sec, last.stamp.nanosec, last.value) == (7, 29, 14.5)
    assert (last.label.text, last.label.id) == ("r29", 29)


def test_type_without_definition_is_named(tmp_path: Path) -> None:
    path = tmp_path / "nodef.mcap"
    with path.open("wb") as stream:
        writer = Writer(stream)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema("nowhere_msgs/msg/Thing", "ros2msg", b"")
        channel = writer.register_channel("/thing", "cdr", schema)
        writer.add_message(channel, T0, b"\x00\x01\x00\x00\x01\x02", T0)
        writer.finish()
    reader = open_bag(path)
    assert any("nowhere_msgs/msg/Thing" in w for w in reader.warnings)
    with pytest.raises(BagError, match="nowhere_msgs/msg/Thing"):
        list(reader.messages(["/thing"]))


def test_killed_writer_keeps_flushed_chunks(tmp_path: Path) -> None:
    """No close(): no metadata.yaml, no footer; every flushed message is read, none after."""
    writer = BagWriter(tmp_path / "killed", flush_period_s=3600.0)
    writer.add_topic("/x", "std_msgs/msg/Float64")
    for i in range(500):
        writer.write("/x", T0 + i, serialize(from_dict("std_msgs/msg/Float64", {"data": i})))
    writer.flush()
    for i in range(500, 510):  # still in the chunk in progress when the process dies
        writer.write("/x", T0 + i, serialize(from_dict("std_msgs/msg/Float64", {"data": i})))
    shutil.copytree(tmp_path / "killed", tmp_path / "snapshot")
    reader = open_bag(tmp_path / "snapshot")
    assert [m.data for _, _, m in reader.messages()] == [float(i) for i in range(500)]
    assert any("no metadata.yaml" in w for w in reader.warnings)
    assert any("500 messages" in w for w in reader.warnings)


def test_writer_refuses_to_overwrite(tmp_path: Path) -> None:
    (tmp_path / "taken").mkdir()
    with pytest.raises(BagError, match="refusing to overwrite"):
        BagWriter(tmp_path / "taken")


def test_writer_rejects_unknown_topic_and_type_change(tmp_path: Path) -> None:
    with BagWriter(tmp_path / "bag") as writer:
        writer.add_topic("x", "std_msgs/msg/Float64")
        with pytest.raises(BagError, match="add_topic"):
            writer.write("/y", T0, b"")
        with pytest.raises(BagError, match="already in the bag"):
            writer.add_topic("/x", "std_msgs/msg/String")
        writer.write("x", T0, serialize(from_dict("std_msgs/msg/Float64", {"data": 1.0})))


@pytest.mark.parametrize(("make", "match"), [
    (lambda p: p / "absent", "no such bag"),
    (lambda p: (p / "folder").mkdir() or p / "folder", "not a bag"),
    (lambda p: (p / "notes.txt").write_text("hello") and p / "notes.txt", "not a bag"),
    (lambda p: (p / "x.mcap").write_bytes(b"\x89MCAP0\r\n\x01\x05") and p / "x.mcap",
     "no message can be recovered"),
])
def test_bad_paths(tmp_path: Path, make: object, match: str) -> None:
    with pytest.raises(BagError, match=match):
        open_bag(make(tmp_path))  # type: ignore[operator]


def test_empty_bag(tmp_path: Path) -> None:
    with BagWriter(tmp_path / "empty") as writer:
        writer.add_topic("/tension", "geometry_msgs/msg/WrenchStamped")
    with pytest.raises(BagError, match=r"empty bag.*/tension"):
        open_bag(tmp_path / "empty")


def test_require_topic_errors(tmp_path: Path) -> None:
    _write(tmp_path / "trial")
    reader = open_bag(tmp_path / "trial")
    with pytest.raises(BagError, match=r"no topic 'poses'; topics: /markers \[mocap4r2"):
        require_topic(reader, "poses")
    with pytest.raises(BagError, match="has type std_msgs/msg/Float64; expected geometry"):
        require_topic(reader, "tension_setpoint", ["geometry_msgs/msg/WrenchStamped"])


@pytest.mark.parametrize("compression", ["none", "zstd"])
def test_a_corrupt_chunk_is_skipped_with_a_warning_given_at_open(
        tmp_path: Path, compression: str) -> None:
    expected = _write(tmp_path / "trial", compression=compression, chunk_size=2048)
    source = tmp_path / "trial" / "trial_0.mcap"
    with source.open("rb") as stream:
        chunk = SeekingReader(stream).get_summary().chunk_indexes[1]  # type: ignore[union-attr]
    data = bytearray(source.read_bytes())
    inside = chunk.chunk_start_offset + chunk.chunk_length - 40  # in the chunk's (compressed) data
    data[inside] ^= 0x10
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data))
    reader = open_bag(bad)
    (warning,) = [w for w in reader.warnings if "corrupt chunk" in w]
    assert f"at byte {chunk.chunk_start_offset} skipped" in warning and "bad.mcap" in warning
    lost = [e for e in expected
            if chunk.message_start_time <= e[1] <= chunk.message_end_time]
    assert f"{len(lost)} messages" in warning
    kept = [(t, s, to_dict(m)) for t, s, _, m in expected if (t, s, _, m) not in lost]
    assert _as_plain(list(reader.messages())) == kept
    assert reader.message_count == len(kept)
