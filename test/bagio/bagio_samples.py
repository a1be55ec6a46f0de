"""Small bags shared by the bag reader's damage tests (uniquely named so imports never collide)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from mcap.writer import Writer

from tdcm_ros.bagio import from_dict, serialize, to_dict, typestore
from tdcm_ros.bagio.writer import BagWriter

T0 = 1_700_000_000_000_000_000  #: ns, log time of the first message
Message = tuple[str, int, str, object]
COMPRESSIONS = ("zstd", "lz4", "none")


def sample_messages(count: int, marker_every: int) -> list[Message]:
    """``count`` tensions 1 µs apart and a Markers message every ``marker_every`` of them."""
    out: list[Message] = []
    for i in range(count):
        out.append(("/tension", T0 + 1000 * i, "geometry_msgs/msg/WrenchStamped",
                    from_dict("geometry_msgs/msg/WrenchStamped",
                              {"header": {"frame_id": f"f{i}"}, "wrench": {"force": {"z": i}}})))
        if i % marker_every == 0:
            out.append(("/markers", T0 + 1000 * i + 1, "mocap4r2_msgs/msg/Markers",
                        from_dict("mocap4r2_msgs/msg/Markers", {"frame_number": i, "markers": [
                            {"marker_name": "m3", "translation": {"z": 0.001 * i}}]})))
    return out


def chunked_bags(messages: list[Message], folder: Path
                 ) -> dict[str, tuple[bytes, list[tuple[str, int, object]]]]:
    """Per compression: the bytes of a bag of ``messages`` in 1 KiB chunks, and the messages as
    (topic, log time, dict)."""
    out = {}
    for compression in COMPRESSIONS:
        path = folder / compression
        with BagWriter(path, chunk_size=1024, compression=compression) as writer:
            for topic, stamp, msgtype, message in messages:
                writer.add_topic(topic, msgtype)
                writer.write(topic, stamp, serialize(message, msgtype))
        out[compression] = ((path / f"{compression}_0.mcap").read_bytes(),
                            [(t, s, to_dict(m)) for t, s, _, m in messages])
    return out


def write_mcap(path: Path, messages: list[Message], **writer_options: Any) -> Path:
    """``messages`` as a ros2-profile MCAP at ``path`` written by the mcap library's own
    ``Writer`` with ``writer_options`` (layouts the package's writer never makes)."""
    with path.open("wb") as stream:
        writer = Writer(stream, **writer_options)
        writer.start(profile="ros2", library="test")
        channels: dict[str, int] = {}
        for topic, stamp, msgtype, message in messages:
            if topic not in channels:
                definition = typestore().generate_msgdef(msgtype, ros_version=2)[0]
                schema = writer.register_schema(msgtype, "ros2msg", definition.encode())
                channels[topic] = writer.register_channel(topic, "cdr", schema)
            writer.add_message(channels[topic], stamp, serialize(message, msgtype), stamp)
        writer.finish()
    return path


def messages_by_topic(messages: Iterable[tuple[str, int, bytes]]
                      ) -> dict[str, list[tuple[int, bytes]]]:
    """``BagReader.raw_messages`` output as (log time, payload) per topic, in order."""
    out: dict[str, list[tuple[int, bytes]]] = {}
    for topic, stamp, data in messages:
        out.setdefault(topic, []).append((stamp, data))
    return out


def blocks_by_topic(blocks: Iterable[tuple[str, np.ndarray, Sequence[bytes]]]
                    ) -> dict[str, list[tuple[int, bytes]]]:
    """``BagReader.raw_blocks`` output the same way."""
    out: dict[str, list[tuple[int, bytes]]] = {}
    for topic, stamps, payloads in blocks:
        assert stamps.dtype == np.int64 and len(stamps) == len(payloads)
        out.setdefault(topic, []).extend(zip(stamps.tolist(), payloads, strict=True))
    return out
