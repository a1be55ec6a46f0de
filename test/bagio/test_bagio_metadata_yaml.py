"""A hostile ``metadata.yaml`` is refused by the bounded YAML loader: the bag opens from its
storage files with a warning naming the file and the limit."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from pathlib import Path

from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.bagio.reader import METADATA_FILE, open_bag
from tdcm_ros.bagio.writer import BagWriter

Stopwatch = Callable[[str], AbstractContextManager[None]]


def test_hostile_metadata_is_a_warning_and_the_messages_still_read(
        tmp_path: Path, hostile_yaml: tuple[str, str, str], stopwatch: Stopwatch) -> None:
    name, text, phrase = hostile_yaml
    bag = tmp_path / "trial"
    with BagWriter(bag) as writer:
        writer.add_topic("/tension", "std_msgs/msg/Float64")
        writer.write("/tension", 1, serialize(from_dict("std_msgs/msg/Float64", {"data": 2.0}),
                                               "std_msgs/msg/Float64"))
    (bag / METADATA_FILE).write_text(text)
    with stopwatch(f"open_bag with metadata {name}"):
        reader = open_bag(bag)
    assert any(str(bag / METADATA_FILE) in w and phrase in w for w in reader.warnings), \
        reader.warnings
    assert [topic for topic, _, _ in reader.raw_messages()] == ["/tension"]
