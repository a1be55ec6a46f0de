"""The vectorised WrenchStamped decoder gives what the typestore decodes, for a batch of one
layout (one view of all payloads) and for mixed lengths and byte orders (grouped)."""

from __future__ import annotations

import numpy as np
import pytest

from tdcm_ros.bagio import deserialize, from_dict, serialize, typestore
from tdcm_ros.metrics.cdr import wrench_force_z

TYPE = "geometry_msgs/msg/WrenchStamped"


def wrench(i: int, frame: str, little: bool = True) -> bytes:
    message = from_dict(TYPE, {"header": {"stamp": {"sec": 1_700_000_000 + i, "nanosec": 7 * i},
                                          "frame_id": frame},
                               "wrench": {"force": {"x": 1.0, "z": 0.25 * i - 3.0}}})
    return serialize(message, TYPE) if little else bytes(
        typestore().serialize_cdr(message, TYPE, little_endian=False))


def expected(payloads: list[bytes]) -> tuple[list[int], list[float]]:
    messages = [deserialize(p, TYPE) for p in payloads]
    return ([m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec for m in messages],
            [m.wrench.force.z for m in messages])


@pytest.mark.parametrize("payloads", [
    [wrench(i, "load_cell") for i in range(50)],
    [wrench(i, "f" * (i % 5), little=i % 7 != 3) for i in range(50)],
], ids=["one layout", "mixed lengths and byte orders"])
def test_wrench_decoding_matches_the_typestore(payloads: list[bytes]) -> None:
    stamps, force = wrench_force_z(payloads)
    want_stamps, want_force = expected(payloads)
    assert stamps.tolist() == want_stamps
    np.testing.assert_array_equal(force, want_force)
