"""Hazards in evaluated bags: occluded markers (NaN, exactly zero), duplicated messages, a corrupt
chunk (evaluate and ``bag info`` warn the same) and implausible stamps."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import SeekingReader
from metrics_samples import TRUE_E, small_recording

from tdcm_ros.bagio import deserialize, serialize
from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.bagio.writer import BagWriter
from tdcm_ros.cli.main import main
from tdcm_ros.metrics.synthetic_bag import write_recording

Change = Callable[[str, int, bytes], list[tuple[int, bytes]]]


@pytest.fixture(scope="module")
def clean(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_recording(small_recording(seed=3), tmp_path_factory.mktemp("hazards") / "clean")


def _evaluate(capsys: pytest.CaptureFixture[str], path: Path) -> tuple[int, dict]:
    code = main(["evaluate", str(path), "--json", "--set", f"E={TRUE_E}"])
    return code, json.loads(capsys.readouterr().out)


def _rewrite(source: Path, target: Path, change: Change) -> Path:
    """Copy the bag ``source`` to ``target``, each message through ``change(topic, log time,
    payload)`` -> [(log time, payload), ...]."""
    reader = open_bag(source)
    with BagWriter(target) as writer:
        for topic, msgtype in reader.topics.items():
            writer.add_topic(topic, msgtype)
        for topic, stamp, data in reader.raw_messages():
            for log_ns, payload in change(topic, stamp, data):
                writer.write(topic, log_ns, payload)
    return target


def _with_tension_sec(seconds: Callable[[int], int | None]) -> Change:
    """A change setting the header stamp of the n-th /tension message to ``seconds(n)`` s."""
    count = [0]

    def change(topic: str, stamp: int, data: bytes) -> list[tuple[int, bytes]]:
        if topic != "/tension":
            return [(stamp, data)]
        count[0] += 1
        sec = seconds(count[0] - 1)
        if sec is None:
            return [(stamp, data)]
        msg = deserialize(data, "geometry_msgs/msg/WrenchStamped")
        msg.header.stamp.sec, msg.header.stamp.nanosec = sec, 0
        return [(stamp, serialize(msg, "geometry_msgs/msg/WrenchStamped"))]
    return change


def test_zero_and_nan_markers_are_occluded_counted_and_not_used(
        clean: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = small_recording(seed=3)
    positions = rec.markers.positions
    positions[::3, 2] = 0.0  # the tip marker reported at the origin: occluded in the live stream
    positions[1::7, 0, 1] = np.nan  # a NaN coordinate
    zeros, nans = len(positions[::3]), len(positions[1::7])
    path = write_recording(rec, tmp_path / "occluded")
    code, doc = _evaluate(capsys, path)
    assert code == 0
    assert doc["details"]["occluded_markers"] == {"m1": nans, "m2": 0, "m3": zeros}
    assert any(f"{zeros + nans} occluded marker positions" in w
               for w in doc["details"]["warnings"])
    _, reference = _evaluate(capsys, clean)
    assert doc["n_steps"] == reference["n_steps"]
    assert doc["mape_pct"] < 0.5 and doc["rmse_m"] < 2e-5  # the zeros never entered a mean
    assert main(["evaluate", str(path), "--set", f"E={TRUE_E}"]) == 0
    assert f"occluded marker positions left out (NaN or exactly 0): m1 {nans}, m2 0, m3 {zeros}" \
        in capsys.readouterr().out


def test_duplicated_messages_are_dropped_and_counted(
        clean: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    twice = _rewrite(clean, tmp_path / "twice", lambda _t, s, d: [(s, d), (s, d)])
    _, reference = _evaluate(capsys, clean)
    code, doc = _evaluate(capsys, twice)
    assert code == 0
    assert doc["n_steps"] == reference["n_steps"]
    assert doc["rmse_m"] == pytest.approx(reference["rmse_m"], rel=1e-9)
    reader = open_bag(clean)
    for topic in ("/tension", "/markers"):
        assert any(f"{topic}: {reader.counts[topic]} duplicated messages" in w
                   for w in doc["details"]["warnings"])


def test_a_corrupt_chunk_is_skipped_and_bag_info_says_the_same(
        clean: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    mcap = next(clean.glob("*.mcap"))
    with mcap.open("rb") as stream:
        chunks = SeekingReader(stream).get_summary().chunk_indexes  # type: ignore[union-attr]
    chunk = chunks[len(chunks) // 2]
    data = bytearray(mcap.read_bytes())
    data[chunk.chunk_start_offset + chunk.chunk_length - 50] ^= 0x01  # in the compressed data
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data))
    code, doc = _evaluate(capsys, bad)
    assert code == 0 and doc["n_steps"] > 0
    (warning,) = [w for w in doc["details"]["warnings"] if "corrupt chunk" in w]
    assert f"corrupt chunk at byte {chunk.chunk_start_offset} skipped" in warning
    assert main(["bag", "info", str(bad)]) == 0
    info = capsys.readouterr().out
    assert f"warning: {warning.removeprefix(f'{bad}: ')}" in info


def test_some_implausible_stamps_are_left_out_with_their_own_warning(
        clean: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    odd = {10: 2**31 - 1, 20: 0, 30: 2**31 - 1, 40: -5}
    path = _rewrite(clean, tmp_path / "odd", _with_tension_sec(odd.get))
    _, reference = _evaluate(capsys, clean)
    code, doc = _evaluate(capsys, path)
    assert code == 0 and doc["n_steps"] == reference["n_steps"]
    assert any("/tension: 4 messages with implausible stamps left out (e.g. 2.14748365e+09 s"
               in w for w in doc["details"]["warnings"])


@pytest.mark.parametrize("sec", [-2**31, 2**31 - 1])
def test_all_implausible_stamps_are_an_error_naming_them(
        clean: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], sec: int) -> None:
    path = _rewrite(clean, tmp_path / "absurd", _with_tension_sec(lambda _n: sec))
    assert main(["evaluate", str(path)]) == 2
    err = capsys.readouterr().err
    count = open_bag(clean).counts["/tension"]
    assert f"/tension: all {count} stamps are implausible (e.g. {float(sec):.9g} s)" in err
    assert "no tension hold" not in err and len(err.strip().splitlines()) == 1
