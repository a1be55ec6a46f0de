"""The vectorised WrenchStamped and Markers decoders give what the per-message decoders give:
for a batch of one layout (one view of all payloads) and for mixed lengths, layouts and byte
orders (grouped)."""

from __future__ import annotations

import numpy as np
import pytest

from tdcm_ros.bagio import deserialize, from_dict, serialize, typestore
from tdcm_ros.metrics.cdr import markers_frame, markers_groups, wrench_force_z

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


MARKERS = "mocap4r2_msgs/msg/Markers"


def markers(i: int, names: list[str], little: bool = True) -> bytes:
    message = from_dict(MARKERS, {
        "header": {"stamp": {"sec": 1_700_000_000, "nanosec": 1000 * i}, "frame_id": "mocap"},
        "frame_number": i, "markers": [
            {"marker_name": name, "marker_index": k,
             "translation": {"x": 0.001 * i, "y": -0.5 * k, "z": float(i + k)}}
            for k, name in enumerate(names)]})
    return serialize(message, MARKERS) if little else bytes(
        typestore().serialize_cdr(message, MARKERS, little_endian=False))


def test_markers_groups_decode_each_payload_as_markers_frame() -> None:
    layouts = [["m1", "m2", "m3"], ["m2", "m1", "m3"], ["m1", "m3"], ["m1", "m1", "x9"], []]
    payloads = [markers(i, layouts[i % len(layouts)], little=i % 11 != 4) for i in range(60)]
    decoded: dict[int, tuple[int, str, list[str], list[list[float]]]] = {}
    sizes = []
    for at, stamps, frame, names, xyz in markers_groups(payloads):
        sizes.append(len(at))
        for row, i in enumerate(at.tolist()):
            decoded[i] = (int(stamps[row]), frame, names, xyz[row].tolist())
    want = {i: (s, f, n, [list(p) for p in x])
            for i, (s, f, n, x) in enumerate(map(markers_frame, payloads))}
    assert decoded == want
    assert max(sizes) > 1  # payloads of one layout were decoded together
