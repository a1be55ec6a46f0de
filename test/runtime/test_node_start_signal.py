"""A node stops at once on SIGINT or SIGTERM while it is still being built. Seen: ``tdcm up``
stopped 2 s after starting, model_node still loading its kernels on a loaded machine took the
signal as a stop request for a loop it had not entered, built on for 5 s, and the launcher killed
it ("ignored SIGINT for 5.0 s"), so ``tdcm up`` exited 1. Seen again once the build was
interrupted at once: a library model_node's build calls ran the handler and dropped its
``KeyboardInterrupt``, and the node built on and spun until killed. And again (CI, 2026-11-28):
an importlib weakref callback dropped it ("Exception ignored in ... KeyboardInterrupt") and the
rest of model_node's build outlasted the launcher's 5 s."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest

from test.support.processes import Lines, child_env, stop
from test.support.waiting import eventually, scaled

pytestmark = pytest.mark.process


def building_node(zenoh_env: dict[str, str], tmp_path: Path, node: str = "SlowStartNode"
                  ) -> tuple[subprocess.Popen[bytes], Lines]:
    """A process of ``node`` (of signal_nodes), returned once it is in its 60 s constructor;
    its stderr."""
    starting = tmp_path / "starting"
    child = subprocess.Popen(
        [sys.executable, "-m", "tdcm_ros.runtime.run_node",
         f"test.runtime.signal_nodes:{node}", "--runtime", "zenoh"],
        env=child_env(zenoh_env, TDCM_TEST_STARTING=str(starting)),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    err = Lines(child, "stderr")
    eventually(lambda: starting.exists() or child.poll() is not None, 60.0,
               "the node's constructor", detail=err.tail)
    return child, err


@pytest.mark.parametrize("node", ["SlowStartNode", "SwallowingStartNode",
                                  "SwallowingSlowNode"])
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_node_is_built_stops_it_at_once(
        signum: signal.Signals, node: str, router: subprocess.Popen[bytes],
        zenoh_env: dict[str, str], tmp_path: Path) -> None:
    """Also when the build drops the signal's error and returns (the node does not spin on)
    or builds on (it leaves STUCK_BUILD_S after the signal, before a launcher's 5 s kill)."""
    child, err = building_node(zenoh_env, tmp_path, node)
    child.send_signal(signum)
    try:
        status = child.wait(scaled(5.0))  # the constructor would take 60 s more
    finally:
        stop(child)
    assert status == 130
    assert err.has(f"{signum.name} while starting; " + (
        "the build did not stop within 2 s: exiting" if node == "SwallowingSlowNode" else
        "stopped")), err.tail()


def test_a_second_signal_on_the_way_out_does_not_hold_the_node(
        router: subprocess.Popen[bytes], zenoh_env: dict[str, str], tmp_path: Path) -> None:
    """Ctrl-C twice in a row while the node is built: it still leaves, 130."""
    child, err = building_node(zenoh_env, tmp_path)
    child.send_signal(signal.SIGINT)
    child.send_signal(signal.SIGINT)
    assert stop(child, timeout=5.0) == 130, err.tail()
