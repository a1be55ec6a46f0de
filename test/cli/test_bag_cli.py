"""``tdcm bag``: ``info`` shows duration, start and end as ``ros2 bag info`` does; ``play`` warns
when nodes on wall time will drop what it plays (a bag recorded more than 0.5 s ago, played
without ``--clock``)."""

from __future__ import annotations

from pathlib import Path

from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.bagio.writer import BagWriter
from tdcm_ros.cli.bag import stale_stamps_warning
from test.support.cli import tdcm

NOW = 1_800_000_000_000_000_000


def test_an_old_bag_without_clock_warns_with_the_cure() -> None:
    warning = stale_stamps_warning(NOW - 3600 * 10**9, NOW, clock=False)
    assert warning.startswith("WARNING: the bag's messages are stamped 3600 s ago")
    assert "input.max_age_s" in warning and "--clock" in warning and "--use-sim-time" in warning


def test_with_clock_or_a_fresh_bag_nothing_is_said() -> None:
    assert stale_stamps_warning(NOW - 3600 * 10**9, NOW, clock=True) == ""
    assert stale_stamps_warning(NOW - 4 * 10**8, NOW, clock=False) == ""


def test_info_shows_duration_start_and_end(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    with BagWriter(bag) as writer:
        writer.add_topic("/tick", "std_msgs/msg/UInt32")
        for n, stamp_ns in enumerate((1_500_000_000, 2_000_000_000, 4_250_000_001)):
            writer.write("/tick", stamp_ns, bytes(serialize(
                from_dict("std_msgs/msg/UInt32", {"data": n}), "std_msgs/msg/UInt32")))
    result = tdcm("bag", "info", str(bag))
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[1:5] == ["duration: 2.750 s",
                          "start: 1970-01-01T00:00:01.500000Z (1.500000000)",
                          "end: 1970-01-01T00:00:04.250000Z (4.250000001)",
                          "messages: 3"]
