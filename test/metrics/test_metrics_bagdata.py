"""Hazards in evaluated bags: occluded markers (NaN, exactly zero), duplicated messages, a corrupt
chunk (evaluate and ``bag info`` warn the same) and implausible stamps; reading in batches gives
the messages decoded one by one, whatever the batch size; the tension and the markers are read in
one pass, their errors in the order reading them in turn gave."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import SeekingReader

from tdcm_ros.bagio import BagError, deserialize, serialize
from tdcm_ros.bagio.reader import BagReader, open_bag
from tdcm_ros.bagio.writer import BagWriter
from tdcm_ros.cli.main import main
from tdcm_ros.metrics import bagdata
from tdcm_ros.metrics.bagdata import BagSource, load_bag
from tdcm_ros.metrics.errors import MetricsError
from tdcm_ros.metrics.synthetic_bag import write_recording
from test.metrics.metrics_samples import TRUE_E, small_recording

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


LABELS = ("m1", "m2", "m3")


def _same_source(a: BagSource, b: BagSource) -> None:
    np.testing.assert_array_equal(a.tension.stamps_s, b.tension.stamps_s)
    np.testing.assert_array_equal(a.tension.tension_n, b.tension.tension_n)
    np.testing.assert_array_equal(a.markers.stamps_s, b.markers.stamps_s)
    np.testing.assert_array_equal(a.markers.positions, b.markers.positions)
    assert a.warnings == b.warnings and a.occluded == b.occluded


@pytest.mark.parametrize("batch", [1, 7])
def test_any_batch_size_and_understated_counts_read_the_same_bag(
        clean: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, batch: int) -> None:
    twice = _rewrite(clean, tmp_path / "twice", lambda _t, s, d: [(s, d), (s, d)])
    whole = [load_bag(path, labels=LABELS) for path in (clean, twice)]
    assert bagdata.BATCH > open_bag(twice).counts["/tension"]  # one batch per topic above

    def understated(path: Path) -> BagReader:  # the arrays start at 1 row and must grow
        reader = open_bag(path)
        reader.counts = dict.fromkeys(reader.counts, 1)
        return reader

    monkeypatch.setattr(bagdata, "BATCH", batch)
    monkeypatch.setattr(bagdata, "open_bag", understated)
    for path, reference in zip((clean, twice), whole, strict=True):
        _same_source(load_bag(path, labels=LABELS), reference)
    assert any("/tension: " in w and "duplicated messages" in w for w in whole[1].warnings)


def test_the_series_are_the_messages_decoded_one_by_one(tmp_path: Path) -> None:
    path = write_recording(small_recording(seed=4, occlusion=0.2), tmp_path / "occluded")
    reader = open_bag(path)
    tension = [(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec, m.wrench.force.z)
               for _, _, m in reader.messages(["/tension"])]
    frames = [(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec,
               {k.marker_name: (k.translation.x, k.translation.y, k.translation.z)
                for k in m.markers}) for _, _, m in reader.messages(["/markers"])]
    expected = np.full((len(frames), len(LABELS), 3), np.nan)
    for n, (_, seen) in enumerate(frames):
        for i, label in enumerate(LABELS):
            expected[n, i] = seen.get(label, np.nan)
    source = load_bag(path, labels=LABELS)
    np.testing.assert_array_equal(source.tension.stamps_s,
                                  np.array([s for s, _ in tension], dtype=np.int64) * 1e-9)
    np.testing.assert_array_equal(source.tension.tension_n, [f for _, f in tension])
    np.testing.assert_array_equal(source.markers.stamps_s,
                                  np.array([s for s, _ in frames], dtype=np.int64) * 1e-9)
    np.testing.assert_array_equal(source.markers.positions, expected)
    assert np.isnan(expected).any() and not source.warnings


@pytest.mark.parametrize("nonzero_at", [None, "first", "last"])
def test_log_times_replace_header_stamps_only_when_every_one_is_zero(
        clean: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, nonzero_at: str | None
        ) -> None:
    count = open_bag(clean).counts["/tension"]
    at = {None: -1, "first": 0, "last": count - 1}[nonzero_at]
    sec = 1_700_000_100
    path = _rewrite(clean, tmp_path / "zero", _with_tension_sec(lambda n: sec if n == at else 0))
    monkeypatch.setattr(bagdata, "BATCH", 5)  # the one non-zero stamp in the first or last batch
    source = load_bag(path, labels=LABELS)
    zero_warning = "/tension: header stamps are all zero; using the bag's log times"
    if nonzero_at:
        assert zero_warning not in source.warnings
        np.testing.assert_array_equal(source.tension.stamps_s, [sec])
    else:
        assert zero_warning in source.warnings and source.tension.stamps_s.size == count
        logs = [stamp for _, stamp, _ in open_bag(path).raw_messages(["/tension"])]
        np.testing.assert_array_equal(source.tension.stamps_s,
                                      np.array(logs, dtype=np.int64) * 1e-9)


def test_a_float64_tension_topic_is_read_as_model_node_takes_it(clean: Path,
                                                                 tmp_path: Path) -> None:
    """The same bag with /tension as std_msgs/msg/Float64 (no header): the same tensions, each
    stamped by its log time, and a warning that says so (refused before)."""
    from tdcm_ros.bagio import from_dict

    reader = open_bag(clean)
    path = tmp_path / "float"
    logs = []
    with BagWriter(path) as writer:
        for topic, msgtype in reader.topics.items():
            writer.add_topic(topic, "std_msgs/msg/Float64" if topic == "/tension" else msgtype)
        for topic, stamp, data in reader.raw_messages():
            if topic == "/tension":
                force = deserialize(data, "geometry_msgs/msg/WrenchStamped").wrench.force.z
                data = serialize(from_dict("std_msgs/msg/Float64", {"data": force}),
                                 "std_msgs/msg/Float64")
                logs.append(stamp)
            writer.write(topic, stamp, data)
    wrench, floats = load_bag(clean, labels=LABELS), load_bag(path, labels=LABELS)
    order = np.argsort(np.asarray(logs), kind="stable")
    by_log = np.array([deserialize(d, "geometry_msgs/msg/WrenchStamped").wrench.force.z
                       for t, _, d in reader.raw_messages(["/tension"])])[order]
    np.testing.assert_array_equal(floats.tension.tension_n, by_log)
    np.testing.assert_array_equal(floats.tension.stamps_s,
                                  np.sort(np.asarray(logs, dtype=np.int64)) * 1e-9)
    assert sorted(floats.tension.tension_n) == sorted(wrench.tension.tension_n)
    assert "/tension: std_msgs/msg/Float64 has no header; stamped by the bag's log times" in \
        floats.warnings


def test_a_missing_tension_topic_names_the_option_that_sets_it(clean: Path) -> None:
    with pytest.raises(BagError, match=r"no topic '/force'.*evaluate --tension-topic"):
        load_bag(clean, labels=LABELS, tension_topic="/force")


def test_the_tension_and_the_markers_are_read_in_one_pass(
        clean: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every chunk holds both: one pass decompresses and reads each once, not once per topic."""
    asked = _record_reads(monkeypatch)
    load_bag(clean, labels=LABELS)
    assert asked == [("blocks", ["/markers", "/tension"])]


def _record_reads(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, list[str]]]:
    """The (method, topics) of each ``raw_blocks`` and ``raw_messages`` call from now on (the
    /tf_static read aside)."""
    asked: list[tuple[str, list[str]]] = []
    for name, method in (("blocks", "raw_blocks"), ("messages", "raw_messages")):
        original = getattr(BagReader, method)

        def recording(self: BagReader, topics: list[str] | None = None, *args: object,
                      _name: str = name, _original: Callable = original
                      ) -> object:
            if topics != ["/tf_static"]:
                asked.append((_name, sorted(topics or [])))
            return _original(self, topics, *args)

        monkeypatch.setattr(BagReader, method, recording)
    return asked


def _broken_markers(topic: str, stamp: int, data: bytes) -> list[tuple[int, bytes]]:
    return [(stamp, data[:12] if topic == "/markers" else data)]


def test_a_topic_error_comes_where_reading_the_topics_in_turn_raised_it(
        clean: Path, tmp_path: Path) -> None:
    """Read in one pass, the tension's errors still come before the markers' (the markers'
    decoding error is kept until the tension is done), and a missing markers topic is said
    once the tension is read."""
    broken = _rewrite(clean, tmp_path / "broken", _broken_markers)
    with pytest.raises(BagError, match="cannot deserialise 12 bytes as mocap4r2_msgs"):
        load_bag(broken, labels=LABELS)
    both = _rewrite(broken, tmp_path / "both", _with_tension_sec(lambda _n: 2**31 - 1))
    with pytest.raises(MetricsError, match="/tension: all .* stamps are implausible"):
        load_bag(both, labels=LABELS)
    absurd = _rewrite(clean, tmp_path / "absurd", _with_tension_sec(lambda _n: 2**31 - 1))
    with pytest.raises(MetricsError, match="/tension: all .* stamps are implausible"):
        load_bag(absurd, labels=LABELS, markers_topic="/nosuch")
    with pytest.raises(BagError, match="no topic '/nosuch'"):
        load_bag(clean, labels=LABELS, markers_topic="/nosuch")


def test_stamps_become_seconds_in_their_own_buffer_exactly_as_a_product() -> None:
    """Block by block over the ns buffer: the same floats as ``stamps_ns * 1e-9``."""
    stamps_ns = np.random.default_rng(0).integers(1, 2**62, size=3 * bagdata._SECONDS_BLOCK + 7)
    expected = stamps_ns * 1e-9
    buffer = stamps_ns.copy()
    seconds = bagdata._seconds(buffer)
    assert seconds.dtype == np.float64 and np.shares_memory(seconds, buffer)
    assert seconds.tobytes() == expected.tobytes()


def test_a_shared_stamp_with_another_payload_is_no_duplicate(
        clean: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each /tension message followed by an exact copy and by one with another force under the
    same stamp: the copies are dropped, the others kept. Only the messages whose stamp is shared
    are hashed, in a second read; a bag without shared stamps is read once."""

    def copy_and_other(topic: str, stamp: int, data: bytes) -> list[tuple[int, bytes]]:
        if topic != "/tension":
            return [(stamp, data)]
        msg = deserialize(data, "geometry_msgs/msg/WrenchStamped")
        msg.wrench.force.z += 1.0
        other = serialize(msg, "geometry_msgs/msg/WrenchStamped")
        return [(stamp, data), (stamp, data), (stamp, other)]

    path = _rewrite(clean, tmp_path / "shared", copy_and_other)
    count = open_bag(clean).counts["/tension"]
    reads = _record_reads(monkeypatch)
    source = load_bag(path, labels=LABELS)
    assert source.tension.stamps_s.size == 2 * count
    assert f"/tension: {count} duplicated messages (same stamp and payload as an earlier one) " \
        "left out" in source.warnings
    both = ["/markers", "/tension"]
    assert reads == [("blocks", both), ("messages", both)]  # the pass, the hashes of /tension
    reads.clear()
    load_bag(clean, labels=LABELS)
    assert reads == [("blocks", both)]
