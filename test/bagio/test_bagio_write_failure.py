"""A write that fails (here the file-size limit, ``RLIMIT_FSIZE``: the same ``OSError`` path as a
full disk or quota) ends the bag cleanly: the MCAP file is cut back to its last whole chunk, it
reads back as exactly the messages the writer says it kept, ``metadata.yaml`` is written for
them, and every later message is counted as lost. The limit applies to a child process only."""

from __future__ import annotations

import json
import resource
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.bagio.writer import RESERVE_BYTES, RESERVE_NAME

REPO = Path(__file__).resolve().parents[2]
LIMIT = RESERVE_BYTES + 40_000  # bytes: room for the reserve, then the MCAP file runs out
WRITER = """
import json, sys
from tdcm_ros.bagio import from_dict, serialize
from tdcm_ros.bagio.writer import BagWriter

writer = BagWriter(sys.argv[1], chunk_size=4096, compression="none")
writer.add_topic("/tick", "std_msgs/msg/UInt32")
given = 0
while not writer.failure and given < 1_000_000:
    data = serialize(from_dict("std_msgs/msg/UInt32", {"data": given}), "std_msgs/msg/UInt32")
    writer.write("/tick", 1_000_000_000 + given * 1000, bytes(data))
    given += 1
for late in range(5):  # after the failure: counted, not written
    writer.write("/tick", 2_000_000_000 + late, b"")
writer.close()
print(json.dumps({"failure": writer.failure, "lost": writer.lost, "given": given + 5,
                  "kept": writer.counts.get("/tick", 0)}))
"""


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))


@pytest.fixture
def failed_bag(tmp_path: Path) -> tuple[Path, dict[str, Any]]:
    bag = tmp_path / "bag"
    child = subprocess.run([sys.executable, "-c", WRITER, str(bag)], cwd=REPO, check=True,
                           capture_output=True, text=True, timeout=120, preexec_fn=_limited)
    return bag, json.loads(child.stdout)


def test_the_bag_keeps_a_readable_prefix_with_its_metadata(
        failed_bag: tuple[Path, dict[str, Any]]) -> None:
    bag, result = failed_bag
    assert "File too large" in str(result["failure"]) and "failed after" in str(result["failure"])
    kept, lost, given = result["kept"], result["lost"], result["given"]
    assert kept > 0 and lost >= 5 and kept + lost == given
    values = [int(m.data) for _, _, m in open_bag(bag).messages(["/tick"])]
    assert values == list(range(kept))
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["message_count"] == kept
    assert meta["topics_with_message_count"][0]["message_count"] == kept
    assert meta["duration"]["nanoseconds"] == (kept - 1) * 1000
    assert not (bag / RESERVE_NAME).exists()
    assert (bag / f"{bag.name}_0.mcap").stat().st_size < LIMIT
