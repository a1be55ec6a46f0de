"""``tdcm solve --plot``'s figure explains itself (inspected as matplotlib objects)."""

from __future__ import annotations

import pytest

from tdcm_ros.model import preset, solve
from tdcm_ros.plotting import solution_figure

plt = pytest.importorskip("matplotlib.pyplot")


def test_solution_figure_has_legends_and_units() -> None:
    fig = solution_figure(plt, solve(preset("paper-experiment"), 12.0))
    try:
        shape, curvature = fig.axes
        assert [t.get_text() for t in shape.get_legend().get_texts()] == [
            "body, as cut", "midline", "notch centres", "unloaded (T = 0 N)"]
        assert [t.get_text() for t in curvature.get_legend().get_texts()] == [
            "curvature κ(s)", "notches"]
        assert (shape.get_xlabel(), shape.get_ylabel()) == ("x in tdcm_base (mm)",
                                                           "z in tdcm_base (mm)")
        assert curvature.get_xlabel() == "arc length s from the base (mm)"
        assert curvature.get_ylabel() == "curvature κ (1/m)"
        assert shape.get_title() == "body at T = 12 N"
    finally:
        plt.close(fig)
