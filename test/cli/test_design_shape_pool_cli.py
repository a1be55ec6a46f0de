"""``tdcm design --problem`` with its default process pool (``--workers -1``: every core), as a
user runs it: the answer is the one a single process finds (DE's deferred updating)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from test.support.cli import tdcm
from test.support.examples import REPO
from test.support.processes import child_env

pytestmark = pytest.mark.process

CURVE = str(REPO / "config" / "design" / "constant_curvature.yaml")


def test_the_process_pool_finds_what_one_process_finds() -> None:
    pooled = subprocess.run([sys.executable, "-m", "tdcm_ros", "design", "--problem", CURVE,
                             "--workers", "2", "--json", "-q"], check=False,
                            capture_output=True, text=True, env=child_env(), cwd=REPO,
                            timeout=600)
    assert pooled.returncode == 0, pooled.stderr
    alone = tdcm("design", "--problem", CURVE, "--workers", "1", "--json", "-q")
    assert alone.returncode == 0, alone.stderr
    found, reference = json.loads(pooled.stdout), json.loads(alone.stdout)
    assert found["met"] and found["generations"] == reference["generations"]
    assert np.array_equal(list(found["variables"].values()),
                          list(reference["variables"].values()))
