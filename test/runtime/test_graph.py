"""How :class:`NodeGraph` starts a child: its own process group, the launcher's session."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from tdcm_ros.runtime.graph import NodeGraph
from test.support.waiting import eventually

#: A child that reports its session, process group and what its stdin is, then waits for SIGINT
#: (its own handler, as every node installs: a child of a background job inherits SIGINT ignored).
REPORT = """
import os, signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
sys.stdout.write(f"{os.getsid(0)} {os.getpgid(0)} {os.path.realpath('/proc/self/fd/0')}\\n")
sys.stdout.flush()
try:
    signal.pause()
except KeyboardInterrupt:
    sys.exit(0)
"""


@pytest.mark.process
def test_a_child_has_its_own_process_group_in_the_launchers_session(tmp_path: Path) -> None:
    """Ctrl-C at a terminal reaches the launcher only (the child is not in the foreground process
    group); the child shares the launcher's session, so where the kernel shares CPU time between
    sessions first (autogroup) a light node is not a group of its own, starved beside a busy one
    (the driver's heartbeat waited 0.6 s for a CPU that way)."""
    graph = NodeGraph(log_dir=tmp_path)
    try:
        child = graph.start("reporter", [sys.executable, "-c", REPORT])
        log = tmp_path / "reporter.log"
        line = eventually(lambda: log.read_text().strip() if log.exists() else "", 10.0,
                          "the child's report")
        session, group, stdin = line.split()
        assert int(session) == os.getsid(0)
        assert int(group) == child.process.pid != os.getpgid(0)
        assert stdin == "/dev/null"
        assert graph.stop(child) == 0  # SIGINT from the launcher
    finally:
        graph.close()
