"""A built node that is slow to stop says where it is, and the launcher waits for it as ROS 2
launch does (SIGINT, SIGTERM 5 s later, SIGKILL 5 s after that). Seen (CI beside a CPU hog,
2026-11-28): model_node, running 1.6 s, took over 5 s to stop after ``tdcm up``'s SIGINT and was
killed with nothing in the log to say where it was, so ``tdcm up`` exited 1."""

from __future__ import annotations

import logging
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from tdcm_ros.runtime.graph import NodeGraph
from tdcm_ros.runtime.run_node import SLOW_STOP_S
from test.support.processes import Lines, child_env, stop
from test.support.waiting import eventually, scaled

pytestmark = pytest.mark.process

#: A child that reports once its handlers are set: SIGINT ignored, SIGTERM exits 0 unless told
#: to ignore it too.
STUBBORN = """
import signal, sys
signal.signal(signal.SIGINT, signal.SIG_IGN)
if sys.argv[1] == "ignore-term":
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
else:
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
print("ready", flush=True)
while True:
    signal.pause()
"""


def test_a_node_still_stopping_after_slow_stop_s_writes_its_threads_stacks(
        router: subprocess.Popen[bytes], zenoh_env: dict[str, str], tmp_path: Path) -> None:
    starting = tmp_path / "starting"
    child = subprocess.Popen(
        [sys.executable, "-m", "tdcm_ros.runtime.run_node",
         "test.runtime.signal_nodes:SlowStopNode", "--runtime", "zenoh"],
        env=child_env(zenoh_env, TDCM_TEST_STARTING=str(starting)),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    err = Lines(child, "stderr")
    try:
        eventually(lambda: err.has("running on zenoh") or child.poll() is not None, 60.0,
                   "the node running", detail=err.tail)
        child.send_signal(signal.SIGINT)
        status = child.wait(scaled(30.0))  # its close takes 5 s
    finally:
        stop(child)
    assert status == 0, err.tail()
    assert err.has(f"Timeout (0:00:0{SLOW_STOP_S:.0f})!"), err.tail()
    assert err.has('signal_nodes.py", line') and err.has("in close"), err.tail()


@pytest.mark.parametrize(("mode", "status", "said"), [
    ("exit-on-term", 0, "still running 0.5 s after SIGINT; sending SIGTERM"),
    ("ignore-term", -signal.SIGKILL, "still running 0.5 s after SIGTERM; killing it")])
def test_the_launcher_escalates_sigint_sigterm_sigkill(
        tmp_path: Path, caplog: pytest.LogCaptureFixture, mode: str, status: int, said: str
        ) -> None:
    graph = NodeGraph(log_dir=tmp_path, grace=0.5)
    try:
        child = graph.start("stubborn", [sys.executable, "-c", STUBBORN, mode])
        log = tmp_path / "stubborn.log"
        eventually(lambda: log.exists() and "ready" in log.read_text(), 30.0, "the child ready")
        with caplog.at_level(logging.WARNING, logger="tdcm.graph"):
            assert graph.stop(child) == status
        assert said in caplog.text
        assert (child in graph.failed()) == (mode == "ignore-term")
    finally:
        graph.close()
