"""Ctrl-C stops a ``tdcm`` command that runs until Ctrl-C even when it was started with SIGINT
ignored: a background job of a non-interactive shell (``cmd &`` in a script) inherits that, and
Python then leaves SIGINT ignored. Seen as ``tdcm topic echo`` and ``topic pub --rate`` running on
10 s after SIGINT under a CI runner started in the background."""

from __future__ import annotations

import shlex
import subprocess
import sys

import pytest

from test.support.processes import Lines, child_env, stop
from test.support.waiting import eventually

pytestmark = pytest.mark.process


@pytest.mark.parametrize("argv", [
    ("topic", "pub", "chatter", "std_msgs/msg/String", "{data: hi}", "--rate", "20"),
    ("topic", "echo", "chatter", "std_msgs/msg/String"),
])
def test_a_command_started_with_sigint_ignored_still_stops_on_ctrl_c(
        argv: tuple[str, ...], router: subprocess.Popen[bytes],
        zenoh_env: dict[str, str]) -> None:
    # a shell that ignores SIGINT, then becomes the command (which inherits the disposition)
    command = " ".join(shlex.quote(a) for a in (sys.executable, "-m", "tdcm_ros", *argv))
    child = subprocess.Popen(["sh", "-c", f"trap '' INT; exec {command}"],
                             env=child_env(zenoh_env), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE)
    out, err = Lines(child), Lines(child, "stderr")
    try:
        # running: pub says it began its loop, echo that nothing publishes the topic yet
        eventually(lambda: out.has("beginning loop") or err.has("still waiting")
                   or child.poll() is not None, 30.0, f"tdcm {' '.join(argv)} running",
                   detail=lambda: out.tail() + err.tail())
        assert child.poll() is None, out.tail() + err.tail()
    finally:
        status = stop(child)  # killed if SIGINT does not stop it: nothing is left running
    assert status == 130
