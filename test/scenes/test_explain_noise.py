"""``tdcm scene explain``: a cost measured as a difference of two timings is never printed as a
negative number; one not above the measured timing noise says so, with the noise."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tdcm_ros.scenes.explain import (
    CLOCK_RESOLUTION_S,
    EffectReport,
    format_cost,
    timed_difference,
)

REPO = Path(__file__).resolve().parents[2]
TIMES = st.floats(0.0, 1e-2)
#: a cost cell of the text table: "12.3 us", "0.041 ± 0.021 us" or "< 0.21 us (below ...)"
COST_CELL = re.compile(r"(?:< )?\d[\d.e+-]* (?:± \d[\d.e+-]* )?us(?: \(below the timing noise\))?")


def test_a_faster_run_with_the_effect_is_below_the_noise_not_a_negative_cost() -> None:
    cost, noise = timed_difference(with_s=1.0e-6, without_s=1.1e-6, repeat_s=1.02e-6)
    assert cost == 0.0 and noise == pytest.approx(0.1e-6)
    row = EffectReport("load_cell", "actuation", cost, "twin step (1 ms)", 0.0, "", noise)
    assert format_cost(row) == "< 0.1 us (below the timing noise)"


def test_a_cost_above_the_noise_is_shown_with_it() -> None:
    cost, noise = timed_difference(with_s=250e-6, without_s=10e-6, repeat_s=258e-6)
    row = EffectReport("tendon_friction", "mechanics", cost, "solve", 0.0, "", noise)
    assert (cost, noise) == (pytest.approx(240e-6), pytest.approx(8e-6))
    assert format_cost(row) == "240.0 ± 8.0 us" and not row.below_noise


@given(TIMES, TIMES, TIMES)
def test_cost_and_noise_are_never_negative(with_s: float, without_s: float,
                                            repeat_s: float) -> None:
    cost, noise = timed_difference(with_s, without_s, repeat_s)
    assert cost >= 0.0 and noise >= max(CLOCK_RESOLUTION_S, abs(repeat_s - with_s))
    assert cost == with_s - without_s or (cost == 0.0 and 0.0 < without_s - with_s <= noise)
    text = format_cost(EffectReport("e", "actuation", cost, "step", None, "", noise))
    assert COST_CELL.fullmatch(text) and "-" not in text.replace("e-", "")


def test_explain_prints_timed_costs_with_their_noise(tmp_path: Path) -> None:
    scene = tmp_path / "timed.yaml"
    scene.write_text("schedule: {levels: [0, 10], hold_s: 1.0}\n"
                     "effects:\n  gravity: {}\n  tendon_compliance: {}\n  load_cell: {}\n")

    def explain(*extra: str) -> str:
        done = subprocess.run([sys.executable, "-m", "tdcm_ros", "scene", "explain", str(scene),
                               "--repeats", "2", "--samples", "20", *extra], cwd=REPO,
                              capture_output=True, text=True, timeout=120, check=False)
        assert done.returncode == 0, done.stderr
        return done.stdout

    rows = {row["name"]: row for row in json.loads(explain("--json"))["rows"]}
    assert set(rows) == {"gravity", "tendon_compliance", "load_cell"}
    for row in rows.values():
        assert row["cost_s"] >= 0.0 and row["noise_s"] >= CLOCK_RESOLUTION_S
    table = explain().splitlines()[2:]
    assert len(table) == 3
    for line in table:
        cell = re.split(r"\s{2,}", line)[2]
        assert COST_CELL.fullmatch(cell), line
