"""Every command example the docs give (the shell blocks of the README and the docs site, each
``--help`` epilog's ``examples:``) is one tdcm takes: each parses, and each that needs no running
graph runs to exit status 0 from a folder holding the files it names. The full benchmarks are parsed only
(minutes of timed solves; their ``--quick`` forms run); the graph's examples run in
test_graph_examples.py (all but the ``--runtime rclpy`` ones and the demos, which test/demo runs
in shortened forms)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tdcm_ros.cli.main import build_parser
from test.support.cli import tdcm
from test.support.examples import REPO, Example, documented_examples

#: Subcommands that need nothing but files: run here.
OFFLINE = {"solve", "inverse", "design", "urdf", "figures", "bench", "evaluate", "calibrate",
           "scene list", "scene validate", "scene explain", "scene effects", "bag info",
           "param specs"}
#: Subcommands that talk to a graph (or start one): run by the graph examples' test.
GRAPH = {"up", "demo", "record", "bag play", "foxglove", "topic list", "topic echo", "topic pub", "topic hz",
         "param list", "param get", "param set", "param describe", "param dump", "service list",
         "service call"}
EXAMPLES = documented_examples(build_parser())
#: Examples that are benchmarks, minutes of timed solves (``bench/`` measures, tests do not):
#: parsed here, not run; their ``--quick`` forms run.
BENCHMARKS = {("bench", "accuracy", "--markdown", "--plot", "accuracy_pareto.png"),
              ("bench", "accuracy", "--json", "-q")}
#: Candidates a design example that leaves ``--samples`` at its default (100,000: 10-20 s of
#: solves) samples here: the example runs as written otherwise (the search's size is the
#: design tests' subject, test/model/test_design_space.py and test/cli/test_design_cli.py).
DESIGN_SAMPLES = "4096"


def _id(example: Example) -> str:
    return f"{example.where}: {' '.join(example.argv)}"


def test_the_docs_have_examples_of_every_kind() -> None:
    """The collector finds the README's, the docs pages' and the epilogs' examples (a broken
    one finds none)."""
    wheres = {e.where.split(":")[0] for e in EXAMPLES}
    assert "README.md" in wheres and "doc/reference/cli.md" in wheres  # cli.md: the epilogs'
    assert any(where.startswith("doc/tutorials/") for where in wheres)
    assert {e.verb for e in EXAMPLES} >= {"solve", "evaluate", "topic pub", "param set", "up"}


@pytest.mark.parametrize("example", EXAMPLES, ids=_id)
def test_every_example_parses_and_is_of_a_known_kind(example: Example) -> None:
    assert example.verb in OFFLINE | GRAPH, f"classify {example.verb!r} in OFFLINE or GRAPH"
    try:
        build_parser(example.argv).parse_args(example.argv)
    except SystemExit as exit_:
        pytest.fail(f"{_id(example)} does not parse (exit {exit_.code})")


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding every file the offline examples name, as a checkout does: the sample
    bag (also as ``run.mcap``, ``trial1``, ``trial2``), ``config/``, ``bench/``, a scene file, a
    bag from another lab, bags of the antagonistic pair (``pair_run``: one JointState;
    ``pair_topics``: a WrenchStamped topic per tendon, ``/flexor`` and ``/extensor``), a bag of
    the friction scene where its demo writes it (``friction_demo/bag``) and the model
    calibrated on it (``model.yaml``)."""
    from tdcm_ros.metrics.api import calibrate_paths
    from tdcm_ros.metrics.synthetic import simulate
    from tdcm_ros.metrics.synthetic_bag import write_recording
    from tdcm_ros.model import MarkerLayout
    from tdcm_ros.scenes import load_scene
    from test.cli.test_foreign_bags_cli import DESIGN, LEVELS, VICON, write_foreign_bag
    from test.metrics.metrics_samples import pair_recording
    from test.metrics.test_friction_calibration import UP_DOWN
    from test.support.scene_recording import scene_recording

    folder = tmp_path_factory.mktemp("examples")
    sample = REPO / "bags" / "paper_experiment"
    (folder / "bags").symlink_to(REPO / "bags")
    (folder / "config").symlink_to(REPO / "config")
    (folder / "doc").mkdir()  # figures write to doc/figures, as from a checkout
    for name in ("trial1", "trial2"):
        shutil.copytree(sample, folder / name)
    shutil.copy(sample / "paper_experiment_0.mcap", folder / "run.mcap")
    shutil.copy(REPO / "config" / "scenes" / "paper_experiment.yaml", folder / "my_bench.yaml")
    lab = simulate(DESIGN, layout=MarkerLayout(labels=VICON, radial_offset=0.0), levels=LEVELS,
                   hold_s=2.0, trials=1, tension_hz=200.0, mocap_hz=50.0, seed=8)
    write_foreign_bag(lab, folder / "lab_bag")
    pair = pair_recording(trials=1, tension_noise_n=0.03, marker_noise_m=5e-5, lag_s=0.1)
    write_recording(pair, folder / "pair_run")
    write_recording(pair, folder / "pair_topics",
                    tendon_topics={"flexor": "/flexor", "extensor": "/extensor"})
    friction = scene_recording(load_scene("friction_hysteresis"), UP_DOWN, trials=3)
    write_recording(friction, folder / "friction_demo" / "bag")
    fit = calibrate_paths([folder / "friction_demo" / "bag"], ("E", "mu"))
    (folder / "model.yaml").write_text(fit.model.text(), encoding="utf-8")
    return folder


def test_only_the_full_benchmarks_are_left_unrun() -> None:
    full = {tuple(e.argv) for e in EXAMPLES if e.verb == "bench" and "--quick" not in e.argv}
    assert full == BENCHMARKS


def _distinct(examples: list[Example]) -> list[Example]:
    """Each command once (the first place it is shown): the same line in two help texts runs once."""
    seen: dict[tuple[tuple[str, ...], tuple[tuple[str, str], ...]], Example] = {}
    for example in examples:
        seen.setdefault((tuple(example.argv), tuple(sorted(example.env.items()))), example)
    return list(seen.values())


@pytest.mark.parametrize("example", _distinct([e for e in EXAMPLES if e.verb in OFFLINE
                                               and tuple(e.argv) not in BENCHMARKS]), ids=_id)
def test_every_offline_example_runs(example: Example, workdir: Path,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    for name, value in example.env.items():
        monkeypatch.setenv(name, value)
    argv = list(example.argv)
    if example.verb == "design" and "--problem" in argv:
        if "--workers" not in argv:  # no process pool inside a test worker
            argv += ["--workers", "1"]
    elif example.verb == "design" and "--samples" not in argv:
        argv += ["--samples", DESIGN_SAMPLES]
    done = tdcm(*argv, cwd=workdir)
    assert done.returncode == 0, f"{_id(example)}: exit {done.returncode}\n{done.stderr[-2000:]}"
