"""The package's layering rules (docs/architecture.md), checked on the source, and the checker
itself on small fake packages that break one rule each."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import tdcm_ros
from test.layering import Rules, violations

SOURCE = Path(tdcm_ros.__file__).parent
HEAVY = frozenset({"scipy", "matplotlib", "zenoh", "rclpy", "mcap", "rosbags", "numba"})

LAYERS = (  # from the ground up; units in one layer do not import each other
    frozenset({"__init__", "errors"}),
    frozenset({"spec", "yamlio", "resources", "plot_backend"}),
    frozenset({"model"}),
    frozenset({"device", "mocap", "bagio", "figures", "plotting"}),
    frozenset({"metrics", "scenes", "control"}),
    frozenset({"runtime"}),
    frozenset({"nodes", "recording"}),
    frozenset({"demo"}),
    frozenset({"cli"}),
    frozenset({"__main__"}),
)
ROS_FREE = frozenset().union(*LAYERS[:5])  # everything below runtime
ENTRY_POINTS = frozenset(f"tdcm_ros.{name}" for name in (  # besides scripts (python -m)
    "model.accuracy", "model.baselines",  # scipy
    "bagio.reader", "bagio.writer",  # mcap
    "metrics.api", "metrics.calibration", "metrics.synthetic", "metrics.synthetic_bag",  # bags
    "runtime.zenoh_runtime", "runtime.zenoh_config", "runtime.zenoh_query",  # transports
    "runtime.rclpy_runtime",
    "runtime.param_client", "runtime.param_services",  # rcl_interfaces messages (rosbags)
    "runtime.lifecycle",  # lifecycle_msgs messages (rosbags)
    "runtime.wire", "device.constants",  # used as namespaces: wire.parse_token, c.TRIP_MN
))
BUDGETS = {unit: frozenset() for layer in LAYERS for unit in layer} | {
    "metrics": frozenset({"scipy"}), "scenes": frozenset({"scipy"}),
    "control": frozenset({"scipy"}),
    "bagio": frozenset({"rosbags"}), "recording": frozenset({"rosbags", "mcap"}),
    "demo": frozenset({"scipy", "rosbags", "mcap"}),
}
RULES = Rules(package="tdcm_ros", layers=LAYERS, entry_points=ENTRY_POINTS, ros_free=ROS_FREE,
              face_budgets=BUDGETS, heavy=HEAVY)


def test_the_package_keeps_its_layering_rules() -> None:
    assert violations(RULES, SOURCE) == []


@pytest.mark.parametrize("face", ["tdcm_ros.model", "tdcm_ros.cli", "tdcm_ros.errors"])
def test_faces_on_the_solve_path_load_no_heavy_library(face: str) -> None:
    probe = (f"import sys, {face}; print(' '.join(sorted({{m.split('.')[0] for m in sys.modules}}"
             f" & set({sorted(HEAVY)!r}))))")
    loaded = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                            check=True, cwd=SOURCE.parent).stdout.split()
    assert loaded == []


# A fake package: ground `errors`, `low` (a face and a heavy entry point) below `high`.
FAKE = {
    "__init__.py": "",
    "errors.py": "class Oops(Exception):\n    pass\n",
    "low/__init__.py": "from fake.low.core import thing\n\n__all__ = ['thing']\n",
    "low/core.py": "from fake.errors import Oops\n\n\ndef thing():\n    raise Oops\n",
    "low/heavy.py": "import scipy\n",
    "high/__init__.py": "",
    "high/use.py": "from fake.low import thing\nfrom fake.low.heavy import scipy\n",
}
FAKE_RULES = Rules(
    package="fake",
    layers=(frozenset({"__init__", "errors"}), frozenset({"low"}), frozenset({"high"})),
    entry_points=frozenset({"fake.low.heavy"}), ros_free=frozenset({"errors", "low"}),
    face_budgets={"__init__": frozenset(), "errors": frozenset(), "low": frozenset(),
                  "high": frozenset()},
    heavy=frozenset({"scipy", "rclpy"}))


def fake_package(tmp_path: Path, changes: dict[str, str]) -> Path:
    root = tmp_path / "fake"
    for name, text in (FAKE | changes).items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(textwrap.dedent(text), encoding="utf-8")
    return root


def test_the_fake_package_is_clean(tmp_path: Path) -> None:
    assert violations(FAKE_RULES, fake_package(tmp_path, {})) == []


BREACHES = {
    "upward import": ({"low/core.py": "def f():\n    from fake.high import use\n"},
                      "fake.low.core:2 imports fake.high.use: 'high' is above 'low'"),
    "cycle through the checker's imports": (
        {"low/a.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from fake.low import b\n",
         "low/b.py": "from fake.low import a\n"},
        "import cycle among: fake.low.a, fake.low.b"),
    "reach past a face": ({"high/use.py": "from fake.low.core import thing\n"},
                          "fake.high.use:1 reaches past the face of 'low' into fake.low.core"),
    "own face": ({"low/core.py": "from fake.low import thing\n"},
                 "fake.low.core:1 imports its own unit's face fake.low"),
    "ROS in the core": ({"low/core.py": "def spin():\n    import rclpy\n"},
                        "fake.low.core:2 imports rclpy in the ROS-free unit 'low'"),
    "heavy face": ({"low/__init__.py": "from fake.low import heavy\n"},
                   "importing fake.low pulls scipy (over its budget)"),
    "unplaced unit": ({"extra.py": ""}, "unit 'extra' is in no layer"),
    "face imports a script": (
        {"low/__init__.py": "from fake.low.tool import run\n",
         "low/tool.py": "def run():\n    pass\n\n\nif __name__ == '__main__':\n    run()\n"},
        "importing fake.low imports the script fake.low.tool"),
    "sibling import": ({"errors.py": "import fake\n"}, "'__init__' is beside 'errors'"),
}


@pytest.mark.parametrize("case", sorted(BREACHES))
def test_each_breach_is_reported(tmp_path: Path, case: str) -> None:
    changes, expected = BREACHES[case]
    found = violations(FAKE_RULES, fake_package(tmp_path, changes))
    assert any(expected in line for line in found), found
