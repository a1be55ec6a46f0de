"""``tdcm evaluate`` / ``tdcm calibrate`` on bags of the antagonistic pair, as a user runs them:
the two tension layouts (one JointState topic; a WrenchStamped topic per tendon, its samples
stamped apart) give the same table, and each way of naming the tensions wrongly is one line
naming the parameter, the value and what is allowed, with exit status 2."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from tdcm_ros.bagio import deserialize, serialize
from tdcm_ros.bagio.reader import open_bag
from tdcm_ros.bagio.writer import BagWriter
from tdcm_ros.metrics.series import TensionSeries
from tdcm_ros.metrics.synthetic_bag import write_recording
from test.metrics.metrics_samples import PAIR_BODY, pair_recording
from test.support.cli import tdcm

WRENCH = "geometry_msgs/msg/WrenchStamped"
PAIR = ("--design", PAIR_BODY)


def topics(*values: str) -> tuple[str, ...]:
    """``--tension-topic VALUE`` for each value."""
    return tuple(arg for value in values for arg in ("--tension-topic", value))


PER_TENDON = topics("flexor=/flexor", "extensor=/extensor")
#: ns: the extensor's load cell samples 1.5 ms after the flexor's (the samples are 4 ms apart)
STAGGER_NS = 1_500_000


def stagger(source: Path, target: Path, topic: str, shift_ns: int) -> Path:
    """Copy the bag ``source`` to ``target`` with ``topic``'s (WrenchStamped) header stamps and
    log times ``shift_ns`` later."""
    reader = open_bag(source)
    messages = []
    for name, log_ns, data in reader.raw_messages():
        if name == topic:
            msg = deserialize(data, WRENCH)
            stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec + shift_ns
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, 10**9)
            data, log_ns = serialize(msg, WRENCH), log_ns + shift_ns
        messages.append((log_ns, name, data))
    with BagWriter(target) as writer:
        for name, msgtype in reader.topics.items():
            writer.add_topic(name, msgtype)
        for log_ns, name, data in sorted(messages, key=lambda m: m[0]):
            writer.write(name, log_ns, data)
    return target


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The noise-free pair as one JointState (``joint``), as a WrenchStamped topic per tendon
    stamped apart (``split``), and as a JointState whose efforts name the extensor otherwise
    (``renamed``)."""
    folder = tmp_path_factory.mktemp("pair")
    rec = pair_recording()
    renamed = replace(rec, tension=TensionSeries(rec.tension.stamps_s, rec.tension.tension_n,
                                                 ("flexor", "antagonist")))
    per_tendon = {"flexor": "/flexor", "extensor": "/extensor"}
    return {"joint": write_recording(rec, folder / "joint"),
            "split": stagger(write_recording(rec, folder / "together", tendon_topics=per_tendon),
                             folder / "split", "/extensor", STAGGER_NS),
            "renamed": write_recording(renamed, folder / "renamed")}


def test_both_layouts_give_the_same_table(bags: dict[str, Path]) -> None:
    joint = tdcm("evaluate", str(bags["joint"]), *PAIR)
    split = tdcm("evaluate", str(bags["split"]), *PAIR, *PER_TENDON)
    assert joint.returncode == split.returncode == 0, joint.stderr + split.stderr
    assert split.stdout == joint.stdout.replace(str(bags["joint"]), str(bags["split"]))
    assert "flexor N extensor N" in joint.stdout and "warning" not in joint.stdout
    docs = [json.loads(tdcm("evaluate", str(bags[name]), *PAIR, *args, "--json").stdout)
            for name, args in (("joint", ()), ("split", PER_TENDON))]
    for doc in docs:
        del doc["details"]["sources"]
    assert docs[0] == docs[1]
    assert docs[0]["steps"][1]["tensions_n"] == {"flexor": 8.0, "extensor": 0.0}
    assert docs[0]["rmse_m"] < 1e-9  # the model's own markers: see test_metrics_tendons


def test_calibrate_reads_both_layouts_alike(bags: dict[str, Path]) -> None:
    joint = tdcm("calibrate", str(bags["joint"]), *PAIR, "--set", "E=1.5e9", "--json")
    split = tdcm("calibrate", str(bags["split"]), *PAIR, *PER_TENDON, "--set", "E=1.5e9",
                 "--json")
    assert joint.returncode == split.returncode == 0, joint.stderr + split.stderr
    fits = [json.loads(done.stdout)["parameters"]["E"] for done in (joint, split)]
    assert fits[0] == fits[1]
    assert fits[0]["value"] == pytest.approx(1.85e9, rel=1e-6)  # the body file's, the truth


#: case -> (bag, arguments, what the one-line error says)
BAD_INPUT: dict[str, tuple[str, tuple[str, ...], tuple[str, ...]]] = {
    "a NAME not in the body file": ("split", topics("flexor=/flexor", "thumb=/extensor"), (
        ("--tension-topic 'thumb=/extensor': 'thumb' is not a tendon of the body; allowed: its "
         "tendon names flexor, extensor"),)),
    "a tendon without a topic": ("split", topics("flexor=/flexor"), (
        "--tension-topic: no topic for tendon(s) extensor",
        "allowed: NAME=TOPIC for every tendon (flexor, extensor)")),
    "a tendon given twice": ("split", topics("flexor=/flexor", "extensor=/extensor",
                                             "flexor=/extensor"), (
        "tendon flexor is given a topic twice (/flexor and /extensor)",)),
    "one topic for two tendons": ("split", topics("flexor=/flexor", "extensor=/flexor"), (
        "one topic for several tendons",)),
    "a plain topic among NAME=TOPIC": ("split", topics("/flexor", "extensor=/extensor"), (
        "'/flexor' is a plain TOPIC among NAME=TOPIC",)),
    "a JointState missing a tendon": ("renamed", (), (
        ("--tension-topic /tension (sensor_msgs/msg/JointState) has no effort for tendon(s) "
         "extensor in 5500 messages; its joints with efforts: antagonist (5500 messages), "
         "flexor (5500 messages); allowed: an effort (N) for each tendon of the body "
         "(--design), by its name (flexor, extensor)"),)),
    "one WrenchStamped for two tendons": ("split", topics("/flexor"), (
        ("--tension-topic /flexor is a geometry_msgs/msg/WrenchStamped: one tension, but the "
         "body has 2 tendons (flexor, extensor); allowed: a sensor_msgs/msg/JointState topic "
         "with an effort per tendon, or NAME=TOPIC for each tendon"),)),
    "a JointState as one tendon's topic": ("joint", topics("flexor=tension", "extensor=markers"), (
        ("topic /tension has type sensor_msgs/msg/JointState; expected "
         "geometry_msgs/msg/WrenchStamped or std_msgs/msg/Float64 (the tension topic of tendon "
         "flexor: --tension-topic flexor=tension)"),)),
    "topics never within align.tolerance_s": ("split", (*PER_TENDON, "--set",
                                                        "align.tolerance_s=0.001"), (
        ("no sample of /flexor has a sample of every other tendon's topic (/extensor) within "
         "align.tolerance_s = 0.001 s"), "(--set align.tolerance_s=SECONDS)")),
}


@pytest.mark.parametrize("command", ["evaluate", "calibrate"])
@pytest.mark.parametrize("case", sorted(BAD_INPUT))
def test_bad_tension_input_is_one_line_and_exit_2(bags: dict[str, Path], command: str,
                                                  case: str) -> None:
    bag, args, expected = BAD_INPUT[case]
    done = tdcm(command, str(bags[bag]), *PAIR, *args)
    assert done.returncode == 2, done.stderr
    err = done.stderr.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err and done.stdout == ""
    assert err.startswith(f"tdcm {command}: ")
    for text in expected:
        assert text in err


def test_the_paper_body_on_a_pair_bag_names_its_tendon(bags: dict[str, Path]) -> None:
    """Without ``--design`` the model is the paper's one tendon, ``tendon_1``: the pair's
    JointState has no effort for it."""
    done = tdcm("evaluate", str(bags["joint"]), "--json")
    assert done.returncode == 2
    error = json.loads(done.stdout)["error"]
    assert error["kind"] == "input"
    assert "has no effort for tendon(s) tendon_1" in error["message"]
    assert "its joints with efforts: extensor (5500 messages), flexor (5500 messages)" in \
        error["message"]
