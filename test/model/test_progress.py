"""The progress hook of long computations: what sweeps and the accuracy bench report, and that
reporting changes no answer."""

from __future__ import annotations

import numpy as np
import pytest

from tdcm_ros.model import preset, sweep, within
from tdcm_ros.model.design_space import PROGRESS_CHUNK_DESIGNS

MM = 1e-3

Calls = list[tuple[str, int, "int | None"]]


def test_a_reported_sweep_counts_every_design_and_gives_the_same_space() -> None:
    calls: Calls = []
    axes = {"w_n": np.linspace(0.5, 3.0, 15) * MM, "w_d": np.linspace(1.0, 2.0, 15) * MM}
    tensions = [0.0, 10.0, 20.0]
    plain = sweep(preset("fig2-wn-1.9"), axes, tensions, coupling="fixed-pitch")
    reported = sweep(preset("fig2-wn-1.9"), axes, tensions, coupling="fixed-pitch",
                     progress=lambda *call: calls.append(call))
    assert PROGRESS_CHUNK_DESIGNS == 100
    assert calls == [("design sweep", done, 225) for done in (0, 100, 200, 225)]
    for name in ("status", "message", "tip_deflection_m", "tip_angle_rad", "max_bending_strain"):
        np.testing.assert_array_equal(getattr(reported, name), getattr(plain, name), err_msg=name)


def test_a_small_sweep_is_one_batch_reported_at_start_and_end() -> None:
    calls: Calls = []
    sweep(preset("fig3-wd-1.52"), {"w_d": np.linspace(1.0, 2.0, 7) * MM}, [5.0, 15.0],
          progress=lambda *call: calls.append(call))
    assert calls == [("design sweep", 0, 7), ("design sweep", 7, 7)]


def test_within_shifts_a_part_into_its_stage() -> None:
    calls: Calls = []
    part = within(lambda *call: calls.append(call), "fig.png", 10, 25)
    assert part is not None
    part("design sweep", 4, 14)
    assert calls == [("fig.png", 14, 25)]
    assert within(None, "fig.png", 0, 1) is None


def test_the_accuracy_bench_reports_references_then_each_configuration(
        monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("scipy")
    from tdcm_ros.model import accuracy

    chosen = accuracy.configs(quick=True)[:2]
    name, design = next(iter(accuracy.designs(quick=True).items()))
    monkeypatch.setattr(accuracy, "configs", lambda quick=False: chosen)
    monkeypatch.setattr(accuracy, "designs", lambda quick=False: {name: design})
    monkeypatch.setattr(accuracy, "tensions", lambda quick=False: (8.0,))
    calls: Calls = []
    report = accuracy.run_bench(quick=True, progress=lambda *call: calls.append(call))
    stages = list(dict.fromkeys(stage for stage, _, _ in calls))
    assert stages == ["reference solutions", "methods and settings"]
    methods = [(d, t) for s, d, t in calls if s == "methods and settings"]
    assert methods == [(0, 2), (1, 2), (2, 2)]
    assert [r.label for r in report.rows] == [c.label for c in chosen]
