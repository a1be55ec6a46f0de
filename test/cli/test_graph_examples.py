"""Every graph command example the docs give (README shell blocks, ``--help`` epilogs) runs on the
embedded runtime as written, against the README's own graph: ``tdcm up --twin --nodes
model_node,shape_controller`` (README, the shape controller's section), on a private router, with
the lab's motion capture joining it (``mocap_node`` on a simulated scene: the markers the record
and play examples name).

A command that ends by itself (``--once``, ``-1``, ``list``, ``get``, ``service call``, ``hz
--duration``) runs to exit status 0, in this process. One that runs until Ctrl-C (``topic echo``,
``topic pub`` at a rate, ``record``, ``bag play --loop``, the other ``up`` graphs) runs as a
process until it has shown what it is for -- a message echoed, one published, a chunk of a bag
written, the bag playing, the graph's nodes on the wire -- then gets SIGINT and exits 0.

Rewritten, and why: an endpoint an example names (``tcp/ros-pc:7447``) is the test's router; an
absolute ``/tmp/...`` path lies in the test's folder; the TLS pair (a secure ``up`` and a
``topic echo`` from another host) runs with certificates and the shipped config files made as
the README says. Not run here: ``--runtime rclpy`` examples (this is the embedded tier) and
``demo`` (test/demo runs each demo scene, minutes apiece); they are parsed by
test_documented_examples.py, which also runs every offline example."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import pytest

from tdcm_ros.cli.main import build_parser
from test.support.cli import tdcm
from test.support.examples import Example, documented_examples
from test.support.graph import start_router
from test.support.processes import REPO, Lines, child_env, free_port, listening, stop
from test.support.waiting import eventually

pytestmark = pytest.mark.process

EXAMPLES = documented_examples(build_parser())
#: The graph every other example talks to (README, "tdcm up --twin --nodes ...").
GRAPH_ARGV = ["up", "--twin", "--nodes", "model_node,shape_controller"]
#: The lab's motion capture beside it, joining its router: markers for the record/play examples.
MOCAP_ARGV = ["up", "--connect", "ENDPOINT", "--nodes", "mocap_node", "-p", "mocap_node:source:=sim"]
GRAPH_NODES = ("/device_twin", "/tension_driver", "/model_node", "/shape_controller",
               "/mocap_node")
#: The verbs run against the graph, in the order a reader meets them.
AGAINST_GRAPH = {"topic list", "topic echo", "topic pub", "topic hz", "param list", "param get",
                 "param set", "param describe", "param dump", "service list", "service call",
                 "record", "bag play", "foxglove"}


def _runs_here(example: Example) -> bool:
    """On the embedded runtime without TLS files (the TLS pair has a test of its own)."""
    return "rclpy" not in example.argv and not _tls(example)


def _tls(example: Example) -> bool:
    return "TDCM_ZENOH_CONFIG" in example.env or "--zenoh-config" in example.argv


def _unique(examples: list[Example]) -> list[Example]:
    seen: set[tuple[str, ...]] = set()
    kept = []
    for example in examples:
        key = (*sorted(example.env), *example.argv)
        if key not in seen:
            seen.add(key)
            kept.append(example)
    return kept


GRAPH_EXAMPLES = _unique([e for e in EXAMPLES if e.verb in AGAINST_GRAPH and _runs_here(e)])
UP_EXAMPLES = _unique([e for e in EXAMPLES if e.verb == "up" and _runs_here(e)
                       and e.argv != GRAPH_ARGV])


@dataclass(frozen=True)
class Graph:
    """The running graph: its router endpoint, the folder examples run in, their environment."""

    endpoint: str
    folder: Path
    env: dict[str, str]


def _rewritten(example: Example, graph: Graph) -> Example:
    """The example with the test's endpoint for any it names and its ``/tmp`` paths in the
    test's folder."""
    argv = [str(graph.folder / arg.removeprefix("/")) if arg.startswith("/tmp/") else arg
            for arg in example.argv]
    for option in ("--connect", "--endpoint"):
        if option in argv:
            argv[argv.index(option) + 1] = graph.endpoint
    env = {k: (graph.endpoint if k == "TDCM_ZENOH_ENDPOINT" else v)
           for k, v in example.env.items()}
    return replace(example, argv=argv, env=env)


def _wait_for_nodes(endpoint: str, nodes: tuple[str, ...], what: str, child: subprocess.Popen[bytes],
                    detail: Callable[[], str]) -> None:
    """Wait until every node of ``nodes`` has an endpoint on the graph at ``endpoint``; fails
    at once if ``child`` (what starts them) exits."""
    from tdcm_ros.runtime.zenoh_runtime import GraphWatch, ZenohContext, open_session

    context = ZenohContext(open_session(router_endpoint=endpoint))
    watch = GraphWatch(context)
    try:
        def seen() -> bool:
            assert child.poll() is None, f"{what}: exited {child.returncode}\n{detail()}"
            found = set().union(*watch.nodes(("MP", "MS", "SS")).values())
            return all(node in found for node in nodes)

        eventually(seen, 60.0, f"{what}: nodes {nodes}", detail=detail)
    finally:
        watch.close()
        context.close()


def _folder(path: Path) -> Path:
    """``path`` made a folder as a checkout is for the examples: ``bags/``, ``config/``, and
    ``tmp/`` for their ``/tmp`` paths."""
    (path / "bags").symlink_to(REPO / "bags")
    (path / "config").symlink_to(REPO / "config")
    (path / "tmp").mkdir()
    return path


def _env(endpoint: str) -> dict[str, str]:
    """The examples' environment: the embedded runtime at ``endpoint``, no TLS config."""
    env = child_env(TDCM_ZENOH_ENDPOINT=endpoint, TDCM_RUNTIME="zenoh", ROS_DOMAIN_ID="0")
    env.pop("TDCM_ZENOH_CONFIG", None)
    return env


@pytest.fixture
def elsewhere(tmp_path: Path) -> Graph:
    """A folder and environment of their own, no graph running: for examples that start one."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    return Graph(endpoint, _folder(tmp_path), _env(endpoint))


@pytest.fixture(scope="module")
def graph(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Graph]:
    """The README's graph on a private router, run from a folder holding ``bags/``."""
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    folder = _folder(tmp_path_factory.mktemp("graph_examples"))
    env = _env(endpoint)
    up = subprocess.Popen([sys.executable, "-m", "tdcm_ros", *GRAPH_ARGV], env=env, cwd=folder,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    err = Lines(up, "stderr")
    mocap: subprocess.Popen[bytes] | None = None
    try:
        eventually(lambda: listening(port), 30.0, "the graph's router",
                   detail=lambda: err.tail())
        mocap = subprocess.Popen(
            [sys.executable, "-m", "tdcm_ros", *[endpoint if a == "ENDPOINT" else a
                                                 for a in MOCAP_ARGV]],
            env=env, cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        mocap_out = Lines(mocap)
        _wait_for_nodes(endpoint, GRAPH_NODES, "the README's graph", up,
                        lambda: err.tail() + mocap_out.tail())
        yield Graph(endpoint, folder, env)
    finally:
        statuses = {"mocap": stop(mocap, timeout=20.0) if mocap is not None else 0,
                    "graph": stop(up, timeout=20.0)}
        assert set(statuses.values()) == {0}, f"tdcm up exited {statuses}:\n{err.tail(40)}"


@pytest.fixture(scope="module")
def bag_stamped(graph: Graph) -> Iterator[Callable[[int, int], bool]]:
    """``seen(until_ns, after_ns)``: whether a peer on the graph got a ``/tension`` message
    stamped by ``until_ns`` (a bag's last time) and received after ``after_ns`` (ns since the
    epoch): a played bag's message, not one of the driver's live ones, stamped as they arrive."""
    from tdcm_ros.runtime.zenoh_runtime import ZenohContext, open_session

    context = ZenohContext(open_session(router_endpoint=graph.endpoint))
    port = context.create_port("_graph_examples_peer")
    received: list[tuple[int, int]] = []  # (stamp ns, received ns)

    def take(message: object) -> None:
        stamp = message.header.stamp  # type: ignore[attr-defined]
        received.append((stamp.sec * 10**9 + stamp.nanosec, time.time_ns()))

    port.create_subscription("/tension", "geometry_msgs/msg/WrenchStamped", take)

    def seen(until_ns: int, after_ns: int) -> bool:
        context.spin_for(0.02)  # the subscription's callbacks run on this thread
        return any(stamp <= until_ns and at > after_ns for stamp, at in received)

    yield seen
    context.close()


def _evidence(example: Example, folder: Path, bag_stamped: Callable[[int, int], bool]
              ) -> Callable[[Lines], bool] | None:
    """What a command that runs until Ctrl-C shows once it works (``None``: it ends by itself).
    ``out`` is the command's stdout."""
    argv, started_ns = example.argv, time.time_ns()
    if example.verb == "topic echo" and "--once" not in argv:
        return lambda out: out.has("---")
    if example.verb == "topic pub" and not {"-1", "--once"} & set(argv):
        return lambda out: out.has("publishing #2")
    if example.verb == "foxglove":
        return lambda out: out.has("serving")
    if example.verb == "bag play":
        from tdcm_ros.bagio.reader import open_bag

        bag_end_ns = open_bag(folder / example.argv[2]).time_range_ns[1]
        return lambda out: bag_stamped(bag_end_ns, started_ns)
    if example.verb == "record":
        bag = folder / next(a for a in argv[1:] if not a.startswith("-"))
        sizes: list[int] = []

        def grew(out: Lines) -> bool:
            if not out.has("recording to"):
                return False
            size = sum(p.stat().st_size for p in bag.glob("*.mcap"))
            sizes.append(size)
            return size > sizes[0]

        return grew
    return None


#: One graph, its examples in order (a bag recorded, then played): one xdist worker runs them.
@pytest.mark.xdist_group("graph_examples")
@pytest.mark.parametrize("example", GRAPH_EXAMPLES, ids=lambda e: f"{e.where}: {' '.join(e.argv)}")
def test_every_graph_example_runs_against_the_readmes_graph(
        example: Example, graph: Graph, bag_stamped: Callable[[int, int], bool],
        monkeypatch: pytest.MonkeyPatch) -> None:
    example = _rewritten(example, graph)
    env = {**graph.env, **example.env}
    evidence = _evidence(example, graph.folder, bag_stamped)
    what = f"{example.where}: tdcm {' '.join(example.argv)}"
    if evidence is None:
        for name, value in env.items():
            monkeypatch.setenv(name, value)
        done = tdcm(*example.argv, cwd=graph.folder)
        assert done.returncode == 0, f"{what}: exit {done.returncode}\n{done.stdout[-1500:]}\n" \
                                     f"{done.stderr[-1500:]}"
        shown = {"topic echo": "---", "topic hz": "average rate", "topic list": "/tip_pose",
                 "param get": "paper-experiment", "service list": "/tension_driver/"}
        assert shown.get(example.verb, "") in done.stdout, f"{what}:\n{done.stdout[-1500:]}"
        return
    child = subprocess.Popen([sys.executable, "-m", "tdcm_ros", *example.argv], env=env,
                             cwd=graph.folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out, err = Lines(child), Lines(child, "stderr")
    try:
        eventually(lambda: evidence(out) or child.poll() is not None, 60.0,
                   f"{what} to show it works", detail=lambda: out.tail() + err.tail())
        assert child.poll() is None, f"{what} exited {child.returncode} before Ctrl-C:\n" \
                                     f"{out.tail()}{err.tail()}"
    finally:
        status = stop(child)
    assert status in (0, 130), f"{what}: exit {status} after Ctrl-C\n{out.tail()}{err.tail()}"


@pytest.mark.parametrize("example", UP_EXAMPLES, ids=lambda e: f"{e.where}: {' '.join(e.argv)}")
def test_every_other_up_example_brings_its_graph_up_and_stops_on_ctrl_c(
        example: Example, elsewhere: Graph) -> None:
    """Each other ``tdcm up`` example on a router of its own until its nodes are on the wire,
    then Ctrl-C: one that starts its router, or, with ``--connect``, one this test starts for
    it (the example joins a router that runs elsewhere)."""
    from tdcm_ros.cli.up import plan

    endpoint = elsewhere.endpoint
    example = _rewritten(example, elsewhere)
    env = {**elsewhere.env, **example.env}
    nodes, _, _ = plan(build_parser(example.argv).parse_args(example.argv), os.getpid())
    started: list[subprocess.Popen[bytes]] = []
    if "--connect" in example.argv:
        router, router_err = start_router(int(endpoint.rsplit(":", 1)[1]), env)
        started.append(router)
        assert router.poll() is None, f"the router to join exited:\n{router_err.tail()}"
    child = subprocess.Popen([sys.executable, "-m", "tdcm_ros", *example.argv], env=env,
                             cwd=elsewhere.folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    err = Lines(child, "stderr")
    what = f"{example.where}: tdcm {' '.join(example.argv)}"
    try:
        _wait_for_nodes(endpoint, tuple(f"/{n}" for n in nodes), what, child, err.tail)
    finally:
        status = stop(child, timeout=20.0)
        for process in started:
            stop(process)
    assert status == 0, f"{what}: exit {status}\n{err.tail(30)}"


def test_the_tls_examples_bring_up_a_secure_graph_that_a_configured_peer_reads(
        elsewhere: Graph) -> None:
    """README: ``tdcm up --endpoint tls/bench-pc:7447 --router-config router.json5 --zenoh-config
    peer.json5 --twin`` on the bench PC, then ``TDCM_ZENOH_ENDPOINT=... TDCM_ZENOH_CONFIG=peer.json5
    tdcm topic echo tip_pose`` from another host: bench-pc is 127.0.0.1 here, the certificates
    and the two files are made as the README's section does (test_zenoh_security's helpers)."""
    from test.runtime.test_zenoh_security import PASSWORDS, make_certificates, render

    up_example, echo_example = (next(e for e in EXAMPLES if _tls(e) and e.verb == verb)
                                for verb in ("up", "topic echo"))
    make_certificates(elsewhere.folder)
    (elsewhere.folder / "users.txt").write_text("".join(f"{u}:{p}\n" for u, p in PASSWORDS.items()))
    render("router.json5", elsewhere.folder, "router.json5")
    render("peer.json5", elsewhere.folder, "peer.json5")
    port = free_port()
    endpoint = f"tls/127.0.0.1:{port}"
    up_example, echo_example = (_rewritten(e, Graph(endpoint, elsewhere.folder, elsewhere.env))
                                for e in (up_example, echo_example))
    env = {k: v for k, v in elsewhere.env.items() if k != "TDCM_ZENOH_ENDPOINT"}
    up = subprocess.Popen([sys.executable, "-m", "tdcm_ros", *up_example.argv], env=env,
                          cwd=elsewhere.folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    up_err = Lines(up, "stderr")
    # the other host's command comes once the bench is up (else: "no zenoh router", exit 1)
    eventually(lambda: listening(port) or up.poll() is not None, 30.0, "the TLS router",
               detail=up_err.tail)
    echo = subprocess.Popen([sys.executable, "-m", "tdcm_ros", *echo_example.argv],
                            env={**env, **echo_example.env}, cwd=elsewhere.folder,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out, err = Lines(echo), Lines(echo, "stderr")
    try:
        eventually(lambda: out.has("---") or echo.poll() is not None or up.poll() is not None,
                   90.0, "tip_pose echoed over TLS",
                   detail=lambda: out.tail() + err.tail() + up_err.tail())
        assert out.has("---"), f"exited: echo {echo.poll()}, up {up.poll()}\n{err.tail()}" \
                               f"{up_err.tail()}"
    finally:
        statuses = (stop(echo), stop(up, timeout=20.0))
    assert statuses[0] in (0, 130) and statuses[1] == 0, f"{statuses}\n{up_err.tail(30)}"
