"""``tdcm evaluate`` imports only what it uses (issue 34): evaluating a bag loads neither the
calibration (scipy.optimize's fit, a t quantile) nor scipy.stats, matplotlib or numba, nor the
URDF writer's XML quoting (xml.sax pulls urllib.request and ssl)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import tdcm_ros

ROOT = Path(tdcm_ros.__file__).parents[1]
BAG = ROOT / "bags" / "paper_experiment"
NOT_ON_THE_PATH = ("scipy.stats", "tdcm_ros.metrics.calibration", "matplotlib", "numba",
                   "xml.sax", "urllib.request", "ssl")
PROBE = f"""
import contextlib, io, json, sys
from tdcm_ros.cli.main import main
with contextlib.redirect_stdout(io.StringIO()) as out:
    code = main(["evaluate", {str(BAG)!r}, "--json"])
loaded = sorted(m for m in sys.modules if m.startswith({NOT_ON_THE_PATH!r}))
print(json.dumps({{"code": code, "steps": json.loads(out.getvalue())["n_steps"],
                   "loaded": loaded}}))
"""


def test_evaluating_a_bag_loads_no_calibration_nor_scipy_stats() -> None:
    result = json.loads(subprocess.run([sys.executable, "-c", PROBE], capture_output=True,
                                       text=True, check=True, cwd=ROOT).stdout)
    assert result["code"] == 0 and result["steps"] > 0
    assert result["loaded"] == []
