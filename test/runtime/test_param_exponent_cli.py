"""``tdcm param set NODE NAME 1.0e9``: a float written with an exponent (no dot, or no sign) is a
float, not YAML 1.1's string, on both runtimes (the CLI in its own process)."""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Callable

TALKER = "tdcm_ros.nodes.talker:Talker"
Spawn = Callable[..., subprocess.Popen[bytes]]


def tdcm_param(env: dict[str, str], *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "tdcm_ros.cli.main", "param", *argv],
                          env=env, capture_output=True, text=True, timeout=60, check=False)


def test_param_set_accepts_exponent_floats(runtime: str, graph_env: dict[str, str],
                                           spawn: Spawn) -> None:
    spawn("tdcm_ros.runtime.run_node", TALKER)
    deadline = time.monotonic() + 30
    while (listing := tdcm_param(graph_env, "list", "talker")).returncode != 0:
        assert time.monotonic() < deadline, listing.stderr
    for text, value in (("2e-1", "0.2"), ("2.5e-1", "0.25"), ("1E0", "1.0")):
        done = tdcm_param(graph_env, "set", "talker", "period", text)
        assert done.returncode == 0, f"{text}: {done.stderr}"
        assert tdcm_param(graph_env, "get", "talker", "period").stdout.strip() == value
